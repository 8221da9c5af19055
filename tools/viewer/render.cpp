#include "render.h"

#include <stdexcept>
#include <string>
#include <vector>

#include <glm/gtc/type_ptr.hpp>

#include "codegen_glsl/glsl_shaders.h"

namespace psys::viewer {

namespace {

const char* kPointVertex = R"(#version 450 core
layout(location = 0) in float visible;
layout(location = 1) in float x;
layout(location = 2) in float y;
layout(location = 3) in float z;
layout(location = 4) in float r;
layout(location = 5) in float g;
layout(location = 6) in float b;
layout(location = 7) in float a;
layout(location = 8) in float size;
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


const char* kLineVertex = R"(#version 450 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec4 colour;
uniform mat4 viewProjection;
out vec4 lineColour;
void main() {
    gl_Position = viewProjection * vec4(position, 1.0);
    lineColour = colour;
}
)";

const char* kLineFragment = R"(#version 450 core
in vec4 lineColour;
out vec4 fragment;
void main() { fragment = lineColour; }
)";

GLuint compile(GLenum kind, const char* source) {
    GLuint shader = glCreateShader(kind);
    glShaderSource(shader, 1, &source, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[2048];
        glGetShaderInfoLog(shader, sizeof log, nullptr, log);
        glDeleteShader(shader);
        throw std::runtime_error(std::string("a viewer shader does not compile: ") + log);
    }
    return shader;
}

}  // namespace

GLuint linkProgram(const char* vertex, const char* fragment) {
    GLuint v = compile(GL_VERTEX_SHADER, vertex), f = compile(GL_FRAGMENT_SHADER, fragment);
    GLuint program = glCreateProgram();
    glAttachShader(program, v);
    glAttachShader(program, f);
    glLinkProgram(program);
    glDeleteShader(v);
    glDeleteShader(f);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[2048];
        glGetProgramInfoLog(program, sizeof log, nullptr, log);
        throw std::runtime_error(std::string("a viewer program does not link: ") + log);
    }
    return program;
}

void clearFrame() {
    glClearColor(0.035f, 0.04f, 0.055f, 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

PointRenderer::PointRenderer() {
    program_ = linkProgram(kPointVertex, codegen_glsl::drawFragmentShader().c_str());
    glCreateVertexArrays(1, &vao_);
    glCreateBuffers(kColumns, buffers_);
    for (GLuint i = 0; i < kColumns; ++i) {
        glVertexArrayVertexBuffer(vao_, i, buffers_[i], 0, sizeof(float));
        glVertexArrayAttribFormat(vao_, i, 1, GL_FLOAT, GL_FALSE, 0);
        glVertexArrayAttribBinding(vao_, i, i);
        glEnableVertexArrayAttrib(vao_, i);
    }
}

PointRenderer::~PointRenderer() {
    glDeleteBuffers(kColumns, buffers_);
    glDeleteVertexArrays(1, &vao_);
    glDeleteProgram(program_);
}

void PointRenderer::draw(const rt::DrawColumns& c, const rt::Memory& memory, const glm::mat4& view,
                         const glm::mat4& projection, float viewportHeight, Blend blend) {
    if (c.rows == 0 || (c.counted && c.drawn == 0)) return;
    const rt::Buffer columns[kColumns] = {c.visible, c.position[0], c.position[1], c.position[2], c.color[0],
                                          c.color[1], c.color[2], c.color[3], c.size};
    for (int i = 0; i < kColumns; ++i) {
        // A component every point draws alike has no column: a constant attribute.
        if (!columns[i].valid()) {
            glDisableVertexArrayAttrib(vao_, static_cast<GLuint>(i));
            glVertexAttrib1f(static_cast<GLuint>(i), i == 0 ? 1.0f : c.constant[static_cast<size_t>(i - 1)]);
            continue;
        }
        glEnableVertexArrayAttrib(vao_, static_cast<GLuint>(i));
        // Straight from the column's GL buffer where the backend computes in GL (the GLSL
        // backend, in this context); else uploaded from the host.
        if (unsigned gl = memory.glBuffer(columns[i])) {
            glVertexArrayVertexBuffer(vao_, static_cast<GLuint>(i), gl, 0, sizeof(float));
            continue;
        }
        glVertexArrayVertexBuffer(vao_, static_cast<GLuint>(i), buffers_[i], 0, sizeof(float));
        const void* data = memory.view(columns[i]);
        if (!data) {
            staging_.resize(c.rows);
            memory.read(columns[i], 0, c.rows, staging_.data());
            data = staging_.data();
        }
        auto bytes = static_cast<GLsizeiptr>(c.rows * sizeof(float));
        if (c.rows > capacity_[i]) {
            glNamedBufferData(buffers_[i], bytes, data, GL_STREAM_DRAW);
            capacity_[i] = c.rows;
        } else {
            glNamedBufferSubData(buffers_[i], 0, bytes, data);
        }
    }
    glUseProgram(program_);
    glUniformMatrix4fv(glGetUniformLocation(program_, "view"), 1, GL_FALSE, glm::value_ptr(view));
    glUniformMatrix4fv(glGetUniformLocation(program_, "projection"), 1, GL_FALSE, glm::value_ptr(projection));
    glUniform1f(glGetUniformLocation(program_, "reference"), kReferenceDistance * viewportHeight / 720.0f);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glEnable(GL_BLEND);
    if (blend == Blend::Additive) glBlendFunc(GL_SRC_ALPHA, GL_ONE);
    else glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);  // points blend over each other; the ground still hides what is below it
    glBindVertexArray(vao_);
    glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(c.rows));
    glBindVertexArray(0);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
}

SceneRenderer::SceneRenderer() {
    program_ = linkProgram(kLineVertex, kLineFragment);
    std::vector<float> v;  // x y z r g b a
    auto line = [&](glm::vec3 a, glm::vec3 b, glm::vec4 colour) {
        for (glm::vec3 p : {a, b}) v.insert(v.end(), {p.x, p.y, p.z, colour.r, colour.g, colour.b, colour.a});
    };
    const int half = 20;
    for (int i = -half; i <= half; ++i) {
        float a = i % 5 == 0 ? 0.16f : 0.07f;
        glm::vec4 grey{0.6f, 0.65f, 0.75f, a};
        line({float(i), 0, float(-half)}, {float(i), 0, float(half)}, grey);
        line({float(-half), 0, float(i)}, {float(half), 0, float(i)}, grey);
    }
    gridVertices_ = static_cast<GLsizei>(v.size() / 7);
    line({0, 0.001f, 0}, {2, 0.001f, 0}, {0.9f, 0.25f, 0.25f, 0.9f});
    line({0, 0, 0}, {0, 2, 0}, {0.3f, 0.85f, 0.3f, 0.9f});
    line({0, 0.001f, 0}, {0, 0.001f, 2}, {0.3f, 0.45f, 0.95f, 0.9f});
    axisVertices_ = static_cast<GLsizei>(v.size() / 7) - gridVertices_;
    glCreateVertexArrays(1, &vao_);
    glCreateBuffers(1, &buffer_);
    glNamedBufferData(buffer_, static_cast<GLsizeiptr>(v.size() * sizeof(float)), v.data(), GL_STATIC_DRAW);
    glVertexArrayVertexBuffer(vao_, 0, buffer_, 0, 7 * sizeof(float));
    glVertexArrayAttribFormat(vao_, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribFormat(vao_, 1, 4, GL_FLOAT, GL_FALSE, 3 * sizeof(float));
    glVertexArrayAttribBinding(vao_, 0, 0);
    glVertexArrayAttribBinding(vao_, 1, 0);
    glEnableVertexArrayAttrib(vao_, 0);
    glEnableVertexArrayAttrib(vao_, 1);
}

SceneRenderer::~SceneRenderer() {
    glDeleteBuffers(1, &buffer_);
    glDeleteVertexArrays(1, &vao_);
    glDeleteProgram(program_);
}

void SceneRenderer::draw(const glm::mat4& view, const glm::mat4& projection, bool grid) {
    if (!grid) return;
    glm::mat4 vp = projection * view;
    glUseProgram(program_);
    glUniformMatrix4fv(glGetUniformLocation(program_, "viewProjection"), 1, GL_FALSE, glm::value_ptr(vp));
    glEnable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glBindVertexArray(vao_);
    glDrawArrays(GL_LINES, 0, gridVertices_ + axisVertices_);
    glBindVertexArray(0);
    glDisable(GL_BLEND);
}

}  // namespace psys::viewer
