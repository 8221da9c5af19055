#include "particles.h"

#include <algorithm>
#include <filesystem>
#include <numeric>
#include <utility>

#include <fmt/format.h>
#include <stb_image.h>

#include <glm/gtc/type_ptr.hpp>

#include "codegen_glsl/glsl_shaders.h"
#include "render.h"

namespace psys::viewer {

namespace {

// The attributes, one float each, in render-column order (rt::ColumnLayout): location i is
// column i.
const char* kAttributes = R"(
layout(location = 0) in float visible;
layout(location = 1) in float x;
layout(location = 2) in float y;
layout(location = 3) in float z;
layout(location = 4) in float r;
layout(location = 5) in float g;
layout(location = 6) in float b;
layout(location = 7) in float a;
layout(location = 8) in float size;
layout(location = 9) in float rotation;
layout(location = 10) in float frame;
layout(location = 11) in float ex;
layout(location = 12) in float ey;
layout(location = 13) in float ez;
)";

const char* kPointVertex = R"(
uniform mat4 view;
uniform mat4 projection;
uniform float reference;  // pixels per unit of size at depth 1
out vec4 colour;
void main() {
    if (visible == 0.0) {  // not drawn: outside the clip volume, no pixels
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        gl_PointSize = 0.0;
        colour = vec4(0.0);
        return;
    }
    vec4 eye = view * vec4(x, y, z, 1.0);
    gl_Position = projection * eye;
    gl_PointSize = clamp(size * reference / max(-eye.z, 1e-3), 1.0, 256.0);
    colour = vec4(r, g, b, a);
}
)";

// Sprites and streaks: six vertices (two triangles) per row, the row an instance.
const char* kQuadVertex = R"(
uniform mat4 view;
uniform mat4 projection;
uniform int kind;  // 1: sprite, 2: streak
out vec4 colour;
out vec2 uv;        // the square's corner coordinates, −1 … 1
out float seed;     // a sprite's frame
out float halfLength;  // a streak's half length, in half widths
out float ground;      // the height above the ground plane (y = 0), in half widths
uniform mat4 viewInverse;
const vec2 corners[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, -1), vec2(1, 1), vec2(-1, 1));
void main() {
    vec2 c = corners[gl_VertexID % 6];
    uv = c;
    seed = frame;
    halfLength = 0.0;
    colour = vec4(r, g, b, a);
    if (visible == 0.0) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        return;
    }
    float halfWidth = 0.5 * size;
    if (kind == 1) {
        vec4 eye = view * vec4(x, y, z, 1.0);
        float s = sin(rotation), k = cos(rotation);
        eye.xy += vec2(k * c.x - s * c.y, s * c.x + k * c.y) * halfWidth;
        gl_Position = projection * eye;
        ground = (viewInverse * eye).y / max(halfWidth, 1e-6);
        return;
    }
    // A streak: along the segment in the eye's space, across it in the view plane,
    // extended by half a width at each end for its round caps.
    vec3 p0 = (view * vec4(x, y, z, 1.0)).xyz, p1 = (view * vec4(ex, ey, ez, 1.0)).xyz;
    vec3 d = p1 - p0;
    float len = length(d);
    vec3 dir = len > 1e-6 ? d / len : vec3(0.0, 1.0, 0.0);
    vec3 side = cross(dir, normalize(-(p0 + p1) * 0.5 + vec3(0.0, 0.0, 1e-6)));
    float sideLength = length(side);
    side = sideLength > 1e-6 ? side / sideLength : vec3(1.0, 0.0, 0.0);
    vec3 p = (c.x < 0.0 ? p0 - dir * halfWidth : p1 + dir * halfWidth) + side * c.y * halfWidth;
    halfLength = halfWidth > 0.0 ? 0.5 * len / halfWidth : 0.0;
    gl_Position = projection * vec4(p, 1.0);
    ground = (viewInverse * vec4(p, 1.0)).y / max(halfWidth, 1e-6);
}
)";

// A trail: a ribbon through its head and the points behind it (packed row by row in the
// `behind` buffer, in the order the instances are drawn), two triangles a segment, the
// row an instance. Each point's corners lie across the curve's direction there (from its
// neighbours), so segments meet without a gap or an overlap; the ribbon narrows and fades
// from its head to nothing at its tail. Its cross-section is a streak's (the fragment
// shader's kind 2, with no length).
const char* kTrailVertex = R"(
uniform mat4 view;
uniform mat4 projection;
uniform mat4 viewInverse;
uniform int points;  // the head and points - 1 behind
layout(std430, binding = 0) readonly buffer Behind { float behind[]; };
out vec4 colour;
out vec2 uv;
out float seed;
out float halfLength;
out float ground;
const vec2 corners[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, -1), vec2(1, 1), vec2(-1, 1));
vec3 at(int i) {  // point i of the instance's trail (0: its head), in the eye's space
    if (i == 0) return (view * vec4(x, y, z, 1.0)).xyz;
    int first = (gl_InstanceID * (points - 1) + i - 1) * 3;
    return (view * vec4(behind[first], behind[first + 1], behind[first + 2], 1.0)).xyz;
}
void main() {
    vec2 c = corners[gl_VertexID % 6];
    int i = gl_VertexID / 6 + (c.x < 0.0 ? 0 : 1);
    float along = float(i) / float(points - 1);  // 0 at the head, 1 at the tail
    uv = vec2(0.0, c.y);
    seed = 0.0;
    halfLength = 0.0;
    colour = vec4(r, g, b, a * (1.0 - along));
    if (visible == 0.0) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        return;
    }
    vec3 p = at(i);
    vec3 direction = at(max(i - 1, 0)) - at(min(i + 1, points - 1));
    vec3 side = cross(direction, normalize(-p + vec3(0.0, 0.0, 1e-6)));
    float sideLength = length(side);
    side = sideLength > 1e-9 ? side / sideLength : vec3(1.0, 0.0, 0.0);
    float halfWidth = 0.5 * size;
    vec3 corner = p + side * c.y * halfWidth * (1.0 - along);
    gl_Position = projection * vec4(corner, 1.0);
    ground = (viewInverse * vec4(corner, 1.0)).y / max(halfWidth, 1e-6);
}
)";

const char* kQuadFragment = R"(#version 450 core
in vec4 colour;
in vec2 uv;
in float seed;
in float halfLength;
in float ground;
uniform int softGround;  // 1: fade where the square crosses the ground plane
uniform int kind;   // 1: sprite, 2: streak
uniform int shape;  // core::Shape: soft, disc, ring, star, smoke
uniform int textured;    // 1: the image's texel, tinted, in place of the shape
uniform ivec2 tiles;     // the flip-book's columns and rows
uniform sampler2D image;
out vec4 fragment;

float hash(vec2 p) { return fract(sin(dot(p, vec2(127.1, 311.7))) * 43758.5453); }
float noise(vec2 p) {
    vec2 i = floor(p), f = fract(p);
    vec2 u = f * f * (3.0 - 2.0 * f);
    return mix(mix(hash(i), hash(i + vec2(1, 0)), u.x), mix(hash(i + vec2(0, 1)), hash(i + vec2(1, 1)), u.x), u.y);
}
float fbm(vec2 p) {
    float sum = 0.0, amplitude = 0.5;
    for (int octave = 0; octave < 4; ++octave) {
        sum += amplitude * noise(p);
        p *= 2.03;
        amplitude *= 0.5;
    }
    return sum;
}

// How much of the colour a fragment of the square shows, 0 … 1, and how hot (> 1 in a
// flare's or a streak's core: it glows).
vec2 coverage() {
    if (kind == 2) {  // a capsule: the distance to the segment, in half widths
        float along = uv.x * (halfLength + 1.0);
        float d = length(vec2(max(abs(along) - halfLength, 0.0), uv.y));
        return vec2(1.0 - smoothstep(0.35, 1.0, d), 1.0 + 1.5 * (1.0 - smoothstep(0.0, 0.45, d)));
    }
    float radius = length(uv);
    if (radius > 1.0) return vec2(0.0);
    if (shape == 0) return vec2(pow(1.0 - radius * radius, 2.0), 1.0);            // soft
    if (shape == 1) return vec2(1.0 - smoothstep(0.88, 1.0, radius), 1.0);       // disc
    if (shape == 2) return vec2(1.0 - smoothstep(0.05, 0.2, abs(radius - 0.75)), 1.0);  // ring
    if (shape == 3) {                                                               // star
        float core = exp(-radius * radius * 14.0);
        float rays = exp(-abs(uv.x) * 18.0) * (1.0 - abs(uv.y)) + exp(-abs(uv.y) * 18.0) * (1.0 - abs(uv.x));
        float glow = (1.0 - radius) * 0.25;
        return vec2(clamp(core + rays + glow, 0.0, 1.0), 1.0 + 2.0 * core);
    }
    float puff = fbm(uv * 2.2 + vec2(seed * 7.31, seed * 3.17));                   // smoke
    return vec2(smoothstep(0.25, 0.75, puff) * (1.0 - smoothstep(0.35, 1.0, radius)), 1.0);
}

// The flip-book's frame `seed` (row by row from the top left, wrapping), at the square's
// point uv; the image's first row is its top.
vec4 texel() {
    int frames = tiles.x * tiles.y;
    int i = int(mod(floor(seed), float(frames)));
    vec2 local = uv * 0.5 + 0.5;
    vec2 at = vec2((float(i % tiles.x) + local.x) / float(tiles.x), (float(i / tiles.x) + 1.0 - local.y) / float(tiles.y));
    return texture(image, at);
}

void main() {
    // Soft against the ground: within half a width of the plane, fading to nothing at it,
    // so a sprite resting on the ground shows no hard cut where it passes through.
    float soft = softGround == 1 ? smoothstep(0.0, 1.0, abs(ground)) : 1.0;
    if (kind == 1 && textured == 1) {
        vec4 t = texel();
        if (t.a * soft <= 0.002) discard;
        fragment = vec4(colour.rgb * t.rgb, colour.a * t.a * soft);
        return;
    }
    vec2 c = coverage();
    if (c.x * soft <= 0.002) discard;
    fragment = vec4(colour.rgb * c.y, colour.a * c.x * soft);
}
)";

std::string withAttributes(const char* body) { return std::string("#version 450 core\n") + kAttributes + body; }

}  // namespace

ParticleRenderer::ParticleRenderer() {
    points_ = linkProgram(withAttributes(kPointVertex).c_str(), codegen_glsl::drawFragmentShader().c_str());
    quads_ = linkProgram(withAttributes(kQuadVertex).c_str(), kQuadFragment);
    trails_ = linkProgram(withAttributes(kTrailVertex).c_str(), kQuadFragment);
    sorter_ = std::make_unique<DepthSort>();
    glCreateBuffers(1, &behind_);
    glCreateVertexArrays(1, &vao_);
    glCreateBuffers(kColumns, buffers_);
    for (GLuint i = 0; i < kColumns; ++i) {
        glVertexArrayVertexBuffer(vao_, i, buffers_[i], 0, sizeof(float));
        glVertexArrayAttribFormat(vao_, i, 1, GL_FLOAT, GL_FALSE, 0);
        glVertexArrayAttribBinding(vao_, i, i);
        glEnableVertexArrayAttrib(vao_, i);
    }
}

ParticleRenderer::~ParticleRenderer() {
    for (auto& [path, t] : textures_)
        if (t.gl) glDeleteTextures(1, &t.gl);
    glDeleteBuffers(kColumns, buffers_);
    glDeleteBuffers(1, &behind_);
    glDeleteProgram(trails_);
    glDeleteVertexArrays(1, &vao_);
    glDeleteProgram(points_);
    glDeleteProgram(quads_);
}

// Loaded again when the file changes on disk (its modification time), so an image being
// painted shows as it is saved, as the program does.
GLuint ParticleRenderer::texture(const std::string& path) {
    std::error_code error;
    auto modified = std::filesystem::last_write_time(path, error);
    if (auto it = textures_.find(path); it != textures_.end()) {
        if (error || modified == it->second.modified) return it->second.gl;
        if (it->second.gl) glDeleteTextures(1, &it->second.gl);
        textures_.erase(it);
    }
    int width = 0, height = 0, channels = 0;
    unsigned char* pixels = stbi_load(path.c_str(), &width, &height, &channels, 4);
    GLuint t = 0;
    if (!pixels) {
        problems_ += fmt::format("cannot load the texture {}: {}; drawn with its shape\n", path, stbi_failure_reason());
    } else {
        glCreateTextures(GL_TEXTURE_2D, 1, &t);
        glTextureStorage2D(t, 1, GL_RGBA8, width, height);
        glTextureSubImage2D(t, 0, 0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, pixels);
        // Linear within a frame; clamped, so a frame's edge does not take its neighbour's.
        glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTextureParameteri(t, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTextureParameteri(t, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        stbi_image_free(pixels);
    }
    textures_[path] = {t, error ? std::filesystem::file_time_type{} : modified};
    return t;
}

std::string ParticleRenderer::takeProblems() { return std::exchange(problems_, {}); }

// Binds every column as an attribute: a GL buffer where the backend computes in GL, else
// uploaded from the host. An alpha-blended sprite or streak type goes back to front: on
// the GPU where its columns are there (DepthSort: nothing read back), else sorted on the
// host and uploaded in that order.
bool ParticleRenderer::bind(const rt::DrawColumns& c, const rt::Memory& memory, const DrawStyle& style,
                            const glm::mat4& view) {
    std::array<rt::Buffer, kColumns> columns;
    columns[0] = c.visible;
    const auto values = c.values();
    std::copy(values.begin(), values.end(), columns.begin() + 1);
    std::array<GLuint, kColumns> gl{};
    bool allOnGpu = true;
    for (size_t i = 0; i < columns.size(); ++i)
        if (columns[i].valid()) {
            gl[i] = memory.glBuffer(columns[i]);
            allOnGpu &= gl[i] != 0;
        }
    for (rt::Buffer b : c.trail) allOnGpu &= !b.valid() || memory.glBuffer(b) != 0;
    sorted_ = 0;
    order_.clear();
    bool sort = style.blend == core::Blend::Alpha && style.kind != core::DrawKind::Point && c.rows > 1;
    if (sort && allOnGpu) {
        sorter_->order(gl[0], {gl[1], gl[2], gl[3]}, {c.constant[0], c.constant[1], c.constant[2]}, c.rows, view);
        sorted_ = c.rows;
    } else if (sort) {
        const float* p[3];
        for (int i = 0; i < 3; ++i)
            p[i] = columns[static_cast<size_t>(i + 1)].valid() ? static_cast<const float*>(memory.view(columns[static_cast<size_t>(i + 1)]))
                                                                : nullptr;
        depth_.resize(c.rows);
        for (size_t row = 0; row < c.rows; ++row) {
            glm::vec4 at{p[0] ? p[0][row] : c.constant[0], p[1] ? p[1][row] : c.constant[1], p[2] ? p[2][row] : c.constant[2], 1};
            depth_[row] = (view * at).z;  // more negative: farther
        }
        order_.resize(c.rows);
        std::iota(order_.begin(), order_.end(), 0u);
        std::stable_sort(order_.begin(), order_.end(), [&](uint32_t a, uint32_t b) { return depth_[a] < depth_[b]; });
        sorted_ = c.rows;
    }
    auto bytes = static_cast<GLsizeiptr>(c.rows * sizeof(float));
    for (int i = 0; i < kColumns; ++i) {
        auto column = columns[static_cast<size_t>(i)];
        auto attribute = static_cast<GLuint>(i);
        // A component every row draws alike has no column: a constant attribute.
        if (!column.valid()) {
            glDisableVertexArrayAttrib(vao_, attribute);
            glVertexAttrib1f(attribute, i == 0 ? 1.0f : c.constant[static_cast<size_t>(i - 1)]);
            continue;
        }
        glEnableVertexArrayAttrib(vao_, attribute);
        if (GLuint buffer = gl[static_cast<size_t>(i)]; buffer && !sorted_) {
            glVertexArrayVertexBuffer(vao_, attribute, buffer, 0, sizeof(float));
            continue;
        }
        glVertexArrayVertexBuffer(vao_, attribute, buffers_[i], 0, sizeof(float));
        if (c.rows > capacity_[i]) {
            glNamedBufferData(buffers_[i], bytes, nullptr, GL_STREAM_DRAW);
            capacity_[i] = c.rows;
        }
        if (sorted_ && allOnGpu) {
            sorter_->gather(gl[static_cast<size_t>(i)], buffers_[i], c.rows);
            continue;
        }
        const auto* data = static_cast<const float*>(memory.view(column));
        if (!data || !order_.empty()) {
            staging_.resize(c.rows);
            if (!data) memory.read(column, 0, c.rows, staging_.data());
            else
                for (size_t row = 0; row < c.rows; ++row) staging_[row] = data[order_[row]];
            data = staging_.data();
        }
        glNamedBufferSubData(buffers_[i], 0, bytes, data);
    }
    if (style.kind == core::DrawKind::Trail) packTrail(c, memory, allOnGpu);
    return true;
}

// A trail's points behind its head, packed row by row (x y z of each point, nearest
// first) into one buffer the trail shader reads, in the order the rows are drawn: by
// the GPU's gathers where the columns are there, else on the host.
void ParticleRenderer::packTrail(const rt::DrawColumns& c, const rt::Memory& memory, bool onGpu) {
    const size_t stride = c.trail.size();
    auto bytes = static_cast<GLsizeiptr>(std::max<size_t>(c.rows * stride, 1) * sizeof(float));
    if (static_cast<size_t>(bytes) > behindCapacity_) {
        glNamedBufferData(behind_, bytes, nullptr, GL_STREAM_DRAW);
        behindCapacity_ = static_cast<size_t>(bytes);
    }
    if (onGpu) {
        for (size_t k = 0; k < stride; ++k)
            sorter_->gather(c.trail[k].valid() ? memory.glBuffer(c.trail[k]) : 0, behind_, c.rows, sorted_ != 0, stride,
                            k, c.trailConstant[k]);
        return;
    }
    staging_.resize(c.rows * stride);
    std::vector<float>& column = trailColumn_;
    column.resize(c.rows);
    for (size_t k = 0; k < stride; ++k) {
        if (c.trail[k].valid()) memory.read(c.trail[k], 0, c.rows, column.data());
        else std::fill(column.begin(), column.end(), c.trailConstant[k]);
        for (size_t row = 0; row < c.rows; ++row)
            staging_[row * stride + k] = column[order_.empty() ? row : order_[row]];
    }
    glNamedBufferSubData(behind_, 0, static_cast<GLsizeiptr>(staging_.size() * sizeof(float)), staging_.data());
}

void ParticleRenderer::draw(const rt::DrawColumns& c, const rt::Memory& memory, const DrawStyle& style,
                            const glm::mat4& view, const glm::mat4& projection, float viewportHeight) {
    if (c.rows == 0 || (c.counted && c.drawn == 0)) return;
    if (!bind(c, memory, style, view)) return;
    bool points = style.kind == core::DrawKind::Point, trail = style.kind == core::DrawKind::Trail;
    GLuint program = points ? points_ : trail ? trails_ : quads_;
    glUseProgram(program);
    glUniformMatrix4fv(glGetUniformLocation(program, "view"), 1, GL_FALSE, glm::value_ptr(view));
    glUniformMatrix4fv(glGetUniformLocation(program, "projection"), 1, GL_FALSE, glm::value_ptr(projection));
    if (points) {
        glUniform1f(glGetUniformLocation(program, "reference"), kReferenceDistance * viewportHeight / 720.0f);
    } else {
        glUniform1i(glGetUniformLocation(program, "kind"), style.kind == core::DrawKind::Sprite ? 1 : 2);
        glUniform1i(glGetUniformLocation(program, "points"), static_cast<GLint>(c.trailPoints() + 1));
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, behind_);
        glUniform1i(glGetUniformLocation(program, "shape"), static_cast<int>(style.shape));
        glUniform1i(glGetUniformLocation(program, "softGround"), style.softGround ? 1 : 0);
        glm::mat4 inverse = glm::inverse(view);
        glUniformMatrix4fv(glGetUniformLocation(program, "viewInverse"), 1, GL_FALSE, glm::value_ptr(inverse));
        GLuint image = style.texture.empty() ? 0 : texture(style.texture);
        glUniform1i(glGetUniformLocation(program, "textured"), image ? 1 : 0);
        glUniform2i(glGetUniformLocation(program, "tiles"), std::max(style.columns, 1), std::max(style.rows, 1));
        glUniform1i(glGetUniformLocation(program, "image"), 0);
        glBindTextureUnit(0, image);
    }
    // Points are vertices; a sprite's or streak's row is an instance of six, a trail's of
    // six a segment.
    for (GLuint i = 0; i < kColumns; ++i) glVertexArrayBindingDivisor(vao_, i, points ? 0 : 1);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glEnable(GL_BLEND);
    if (style.blend == core::Blend::Add) glBlendFunc(GL_SRC_ALPHA, GL_ONE);
    else glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);  // particles blend over each other; the ground still hides what is below it
    glBindVertexArray(vao_);
    if (points) glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(c.rows));
    else glDrawArraysInstanced(GL_TRIANGLES, 0, trail ? static_cast<GLsizei>(6 * c.trailPoints()) : 6,
                               static_cast<GLsizei>(c.rows));
    glBindVertexArray(0);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
}

}  // namespace psys::viewer
