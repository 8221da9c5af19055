// Drawing a type's objects as its render command says (core/draw.h): points, sprites or
// streaks, straight from the run-time's draw columns (rt::DrawColumns: bound where they
// live in GL, else uploaded column by column — never a per-point structure).
//
//   point   a round, soft-rimmed dot `size` pixels across at the reference distance
//   sprite  a camera-facing square `size` world units across, turned by `rotation`, its
//           shape computed in the fragment shader (@shape: soft, disc, ring, star, smoke;
//           `frame` picks the smoke's noise) or an image (@texture, a PNG; a flip-book
//           of columns × rows frames, `frame` picking one), tinted by the colour
//   streak  a band `size` world units wide from `position` to `end`, round-capped, with a
//           hot core
//   trail   a ribbon through the position and the points behind it, `size` world units
//           wide at its head, narrowing and fading to nothing at its tail; a streak's
//           cross-section
//
// Blending is the type's (@blend; the viewer's B switch for types that name none): added,
// or alpha-blended over what is behind, back to front (the rows sorted by depth each
// frame: on the GPU where the columns are there, depth_sort.h; else on the host).
#pragma once

#include <epoxy/gl.h>

#include <filesystem>
#include <glm/glm.hpp>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/draw.h"
#include "depth_sort.h"
#include "rt/memory.h"
#include "rt/system.h"

namespace psys::viewer {

// A point's `size` is its diameter in pixels seen from this distance (on a 720-pixel-high
// view; scaled with the view's height).
constexpr float kReferenceDistance = 20;

struct DrawStyle {
    core::DrawKind kind = core::DrawKind::Point;
    core::Shape shape = core::Shape::Soft;
    core::Blend blend = core::Blend::Add;
    std::string texture;  // a sprite's image (@texture), in place of the shape; empty: none
    int columns = 1, rows = 1;  // its flip-book's frames: `frame` picks one (row by row, from the top left)
    bool softGround = false;    // sprites and streaks fade where they cross the ground (y = 0), shown
};

class ParticleRenderer {
public:
    ParticleRenderer();
    ~ParticleRenderer();
    ParticleRenderer(const ParticleRenderer&) = delete;
    ParticleRenderer& operator=(const ParticleRenderer&) = delete;
    void draw(const rt::DrawColumns& columns, const rt::Memory& memory, const DrawStyle& style, const glm::mat4& view,
              const glm::mat4& projection, float viewportHeight);
    // How many rows the last draw sorted back to front (0: not sorted).
    size_t sortedRows() const { return sorted_; }
    // Why a texture could not be loaded (its type is drawn with its shape instead), once
    // per file; empty when every texture loaded.
    std::string takeProblems();

private:
    static constexpr int kColumns = 1 + rt::DrawColumns::kValues;  // visible, then the values in render order
    bool bind(const rt::DrawColumns& c, const rt::Memory& memory, const DrawStyle& style, const glm::mat4& view);
    void packTrail(const rt::DrawColumns& c, const rt::Memory& memory, bool onGpu);
    GLuint texture(const std::string& path);  // loaded once, again when it changes (0: it could not be)
    std::unique_ptr<DepthSort> sorter_;
    struct Texture {
        GLuint gl = 0;
        std::filesystem::file_time_type modified;
    };
    std::map<std::string, Texture> textures_;
    std::string problems_;
    GLuint points_ = 0, quads_ = 0, trails_ = 0, vao_ = 0, buffers_[kColumns] = {};
    GLuint behind_ = 0;  // a trail's points behind its heads, row by row
    size_t behindCapacity_ = 0;
    size_t capacity_[kColumns] = {};
    std::vector<float> staging_, trailColumn_;
    std::vector<uint32_t> order_;
    std::vector<float> depth_;
    size_t sorted_ = 0;
};

}  // namespace psys::viewer
