#include "render.h"

#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/gtc/type_ptr.hpp>


namespace psys::viewer {

namespace {

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

namespace {

// Links the compiled shaders into a program (and lets them go); throws with the log.
GLuint link(std::initializer_list<GLuint> shaders) {
    GLuint program = glCreateProgram();
    for (GLuint shader : shaders) glAttachShader(program, shader);
    glLinkProgram(program);
    for (GLuint shader : shaders) glDeleteShader(shader);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[2048];
        glGetProgramInfoLog(program, sizeof log, nullptr, log);
        throw std::runtime_error(std::string("a viewer program does not link: ") + log);
    }
    return program;
}

}  // namespace

GLuint linkProgram(const char* vertex, const char* fragment) {
    return link({compile(GL_VERTEX_SHADER, vertex), compile(GL_FRAGMENT_SHADER, fragment)});
}

GLuint linkComputeProgram(const char* source) { return link({compile(GL_COMPUTE_SHADER, source)}); }

void clearFrame() {
    glClearColor(0.035f, 0.04f, 0.055f, 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
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
