// HDR drawing and glow: the scene is drawn into a half-float target, so additive light may
// add up past 1 instead of clipping to white; its bright part is blurred over a chain of
// ever smaller targets and added back (a bloom), and the sum is tone mapped into the
// surface: identical below 0.8, then the brightest channel compressed towards 1 and the
// others with it, so a hot orange spark stays orange where clipping each channel would
// have turned it yellow or white. With the glow off, the
// light is clipped at 1 instead (what an 8-bit target shows: colours exactly as given).
#pragma once

#include <epoxy/gl.h>

#include <array>

namespace psys::viewer {

struct GlowSettings {
    bool on = true;          // the bloom and the tone mapping (the panel's switch, L; --no-glow)
    float strength = 0.6f;   // how much of the blurred light is added back
    float threshold = 0.9f;  // the brightness the glow starts from (a soft knee below it)
};

class Glow {
public:
    Glow();
    ~Glow();
    Glow(const Glow&) = delete;
    Glow& operator=(const Glow&) = delete;

    // Binds the HDR target, `width` × `height` (made or resized here), to draw the scene into.
    void begin(int width, int height);
    // Draws the scene's light (and its glow, where on) into the framebuffer bound now,
    // tone mapped; leaves the viewport the surface's.
    void finish(GLuint target, const GlowSettings& settings);

private:
    static constexpr int kLevels = 5;
    void resize(int width, int height);
    void release();
    GLuint downsample_ = 0, upsample_ = 0, composite_ = 0, empty_ = 0;
    GLuint sceneFbo_ = 0, sceneColour_ = 0, sceneDepth_ = 0;
    std::array<GLuint, kLevels> levelFbo_{}, levelColour_{};
    std::array<int, kLevels> levelWidth_{}, levelHeight_{};
    int width_ = 0, height_ = 0;
};

}  // namespace psys::viewer
