#include "glow.h"

#include <algorithm>

#include "render.h"

namespace psys::viewer {

namespace {

// A triangle that covers the viewport, from the vertex index alone.
const char* kFullScreen = R"(#version 450 core
out vec2 uv;
void main() {
    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    uv = p;
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)";

// Half the size: the average of four bilinear taps (a 4×4 box); on the first level only
// the light above the threshold, with a soft knee, passes.
const char* kDownsample = R"(#version 450 core
in vec2 uv;
uniform sampler2D source;
uniform vec2 texel;       // the source's texel size
uniform int first;
uniform float threshold;
out vec4 fragment;
void main() {
    vec3 c = (texture(source, uv + texel * vec2(-1, -1)).rgb + texture(source, uv + texel * vec2(1, -1)).rgb +
              texture(source, uv + texel * vec2(-1, 1)).rgb + texture(source, uv + texel * vec2(1, 1)).rgb) * 0.25;
    if (first == 1) {
        float bright = max(c.r, max(c.g, c.b));
        float knee = 0.5 * threshold;
        float soft = clamp(bright - threshold + knee, 0.0, 2.0 * knee);
        soft = soft * soft / (4.0 * knee + 1e-5);
        c *= max(soft, bright - threshold) / max(bright, 1e-5);
    }
    fragment = vec4(c, 1.0);
}
)";

// Twice the size: a 3×3 tent over the smaller level, added onto the larger one.
const char* kUpsample = R"(#version 450 core
in vec2 uv;
uniform sampler2D source;
uniform vec2 texel;
out vec4 fragment;
void main() {
    vec3 c = texture(source, uv).rgb * 4.0;
    c += (texture(source, uv + texel * vec2(1, 0)).rgb + texture(source, uv + texel * vec2(-1, 0)).rgb +
          texture(source, uv + texel * vec2(0, 1)).rgb + texture(source, uv + texel * vec2(0, -1)).rgb) * 2.0;
    c += texture(source, uv + texel * vec2(1, 1)).rgb + texture(source, uv + texel * vec2(-1, 1)).rgb +
         texture(source, uv + texel * vec2(1, -1)).rgb + texture(source, uv + texel * vec2(-1, -1)).rgb;
    fragment = vec4(c / 16.0, 1.0);
}
)";

// The scene plus its glow, tone mapped: unchanged up to 0.8, then compressed towards 1 (a
// colour of 1 shows as 0.93), hue kept; without the glow, clipped at 1 (the look of an
// 8-bit target).
const char* kComposite = R"(#version 450 core
in vec2 uv;
uniform sampler2D scene;
uniform sampler2D glow;
uniform float strength;
uniform int toneMapped;
out vec4 fragment;
// The brightest channel m is mapped (unchanged up to 0.8, then towards 1) and the colour
// scaled with it: its hue is kept where clipping each channel would turn it yellow or white.
vec3 toneMap(vec3 c) {
    const float k = 0.8;
    float m = max(c.r, max(c.g, c.b));
    if (m <= k) return c;
    float mapped = k + (1.0 - k) * (1.0 - exp(-(m - k) / (1.0 - k)));
    return c * (mapped / m);
}
void main() {
    vec3 c = texture(scene, uv).rgb + strength * texture(glow, uv).rgb;
    fragment = vec4(toneMapped == 1 ? toneMap(max(c, 0.0)) : clamp(c, 0.0, 1.0), 1.0);
}
)";

GLuint colourTexture(int width, int height) {
    GLuint t = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &t);
    glTextureStorage2D(t, 1, GL_RGBA16F, width, height);
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(t, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(t, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return t;
}

void fullScreen(GLuint program, GLuint empty) {
    glUseProgram(program);
    glBindVertexArray(empty);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
}

}  // namespace

Glow::Glow() {
    downsample_ = linkProgram(kFullScreen, kDownsample);
    upsample_ = linkProgram(kFullScreen, kUpsample);
    composite_ = linkProgram(kFullScreen, kComposite);
    glCreateVertexArrays(1, &empty_);
}

Glow::~Glow() {
    release();
    glDeleteVertexArrays(1, &empty_);
    glDeleteProgram(downsample_);
    glDeleteProgram(upsample_);
    glDeleteProgram(composite_);
}

void Glow::release() {
    if (!sceneFbo_) return;
    glDeleteFramebuffers(1, &sceneFbo_);
    glDeleteTextures(1, &sceneColour_);
    glDeleteRenderbuffers(1, &sceneDepth_);
    glDeleteFramebuffers(kLevels, levelFbo_.data());
    glDeleteTextures(kLevels, levelColour_.data());
    sceneFbo_ = 0;
}

void Glow::resize(int width, int height) {
    if (width == width_ && height == height_ && sceneFbo_) return;
    release();
    width_ = width;
    height_ = height;
    sceneColour_ = colourTexture(width, height);
    glCreateRenderbuffers(1, &sceneDepth_);
    glNamedRenderbufferStorage(sceneDepth_, GL_DEPTH_COMPONENT24, width, height);
    glCreateFramebuffers(1, &sceneFbo_);
    glNamedFramebufferTexture(sceneFbo_, GL_COLOR_ATTACHMENT0, sceneColour_, 0);
    glNamedFramebufferRenderbuffer(sceneFbo_, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, sceneDepth_);
    glCreateFramebuffers(kLevels, levelFbo_.data());
    for (int l = 0; l < kLevels; ++l) {
        levelWidth_[l] = std::max(1, width >> (l + 1));
        levelHeight_[l] = std::max(1, height >> (l + 1));
        levelColour_[l] = colourTexture(levelWidth_[l], levelHeight_[l]);
        glNamedFramebufferTexture(levelFbo_[l], GL_COLOR_ATTACHMENT0, levelColour_[l], 0);
    }
}

void Glow::begin(int width, int height) {
    resize(std::max(width, 1), std::max(height, 1));
    glBindFramebuffer(GL_FRAMEBUFFER, sceneFbo_);
    glViewport(0, 0, width_, height_);
}

void Glow::finish(GLuint target, const GlowSettings& settings) {
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    if (settings.on) {
        // Down the chain: each level half the one above, the first only the bright light.
        glUseProgram(downsample_);
        for (int l = 0; l < kLevels; ++l) {
            GLuint source = l == 0 ? sceneColour_ : levelColour_[l - 1];
            int sw = l == 0 ? width_ : levelWidth_[l - 1], sh = l == 0 ? height_ : levelHeight_[l - 1];
            glBindFramebuffer(GL_FRAMEBUFFER, levelFbo_[l]);
            glViewport(0, 0, levelWidth_[l], levelHeight_[l]);
            glBindTextureUnit(0, source);
            glUniform1i(glGetUniformLocation(downsample_, "source"), 0);
            glUniform2f(glGetUniformLocation(downsample_, "texel"), 1.0f / static_cast<float>(sw), 1.0f / static_cast<float>(sh));
            glUniform1i(glGetUniformLocation(downsample_, "first"), l == 0 ? 1 : 0);
            glUniform1f(glGetUniformLocation(downsample_, "threshold"), settings.threshold);
            fullScreen(downsample_, empty_);
        }
        // Back up: each level's blur added onto the one above it.
        glUseProgram(upsample_);
        glEnable(GL_BLEND);
        glBlendFunc(GL_ONE, GL_ONE);
        for (int l = kLevels - 1; l > 0; --l) {
            glBindFramebuffer(GL_FRAMEBUFFER, levelFbo_[l - 1]);
            glViewport(0, 0, levelWidth_[l - 1], levelHeight_[l - 1]);
            glBindTextureUnit(0, levelColour_[l]);
            glUniform1i(glGetUniformLocation(upsample_, "source"), 0);
            glUniform2f(glGetUniformLocation(upsample_, "texel"), 1.0f / static_cast<float>(levelWidth_[l]),
                        1.0f / static_cast<float>(levelHeight_[l]));
            fullScreen(upsample_, empty_);
        }
        glDisable(GL_BLEND);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, target);
    glViewport(0, 0, width_, height_);
    glUseProgram(composite_);
    glBindTextureUnit(0, sceneColour_);
    glBindTextureUnit(1, levelColour_[0]);
    glUniform1i(glGetUniformLocation(composite_, "scene"), 0);
    glUniform1i(glGetUniformLocation(composite_, "glow"), 1);
    glUniform1f(glGetUniformLocation(composite_, "strength"), settings.on ? settings.strength : 0.0f);
    glUniform1i(glGetUniformLocation(composite_, "toneMapped"), settings.on ? 1 : 0);
    fullScreen(composite_, empty_);
    glBindTextureUnit(0, 0);
    glBindTextureUnit(1, 0);
}

}  // namespace psys::viewer
