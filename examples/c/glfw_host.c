/* A host that embeds a system and draws it with OpenGL in a GLFW window: the draw columns
 * become vertex attributes — uploaded from the system's arrays on the CPU backends, bound
 * as they are on the glsl backend (the system computes in the window's GL context, and
 * nothing is read back).
 *
 *   glfw_host FILE [--backend llvm|interp|glsl] [--frames N] [--png OUT.png]
 *
 * Space fires the program's first trigger (with zeros); Escape quits. --frames stops after
 * N frames (and --png saves the last one).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <epoxy/gl.h>
#include <GLFW/glfw3.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

#include <psys/psys.h>

enum { kAttributes = 9 }; /* visible, x y z, r g b a, size */

static const char* kVertex =
    "#version 450\n"
    "layout(location = 0) in float visible;\n"
    "layout(location = 1) in float x;\n"
    "layout(location = 2) in float y;\n"
    "layout(location = 3) in float z;\n"
    "layout(location = 4) in float r;\n"
    "layout(location = 5) in float g;\n"
    "layout(location = 6) in float b;\n"
    "layout(location = 7) in float a;\n"
    "layout(location = 8) in float size;\n"
    "uniform mat4 view_projection;\n"
    "uniform float pixels;\n"
    "out vec4 colour;\n"
    "void main() {\n"
    "    gl_Position = visible > 0.5 ? view_projection * vec4(x, y, z, 1) : vec4(2, 2, 2, 1);\n"
    "    gl_PointSize = max(1.0, pixels * size / max(gl_Position.w, 0.1));\n"
    "    colour = vec4(r, g, b, a);\n"
    "}\n";
static const char* kFragment =
    "#version 450\n"
    "in vec4 colour;\n"
    "out vec4 frag;\n"
    "void main() {\n"
    "    vec2 d = gl_PointCoord * 2.0 - 1.0;\n"
    "    float fade = max(0.0, 1.0 - dot(d, d));\n"
    "    frag = vec4(colour.rgb * colour.a * fade, 0);\n" /* added: glows where they crowd */
    "}\n";

static int failed(psys_error* error) {
    if (!error) return 0;
    fprintf(stderr, "%s\n", psys_error_message(error));
    psys_error_free(error);
    return 1;
}

static GLuint program(void) {
    GLuint p = glCreateProgram(), s[2];
    const char* sources[2] = {kVertex, kFragment};
    GLenum kinds[2] = {GL_VERTEX_SHADER, GL_FRAGMENT_SHADER};
    int i;
    for (i = 0; i < 2; ++i) {
        s[i] = glCreateShader(kinds[i]);
        glShaderSource(s[i], 1, &sources[i], NULL);
        glCompileShader(s[i]);
        glAttachShader(p, s[i]);
    }
    glLinkProgram(p);
    return p;
}

/* A camera at `eye` looking at `at`, 45° vertical field: column-major, as GL takes it. */
static void camera(float aspect, const float eye[3], const float at[3], float out[16]) {
    float f[3] = {at[0] - eye[0], at[1] - eye[1], at[2] - eye[2]}, s[3], u[3], n, t = 1.0f / tanf(0.3927f);
    float near = 0.1f, far = 200.0f;
    int i;
    n = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (i = 0; i < 3; ++i) f[i] /= n;
    s[0] = -f[2], s[1] = 0, s[2] = f[0]; /* f × (0, 1, 0) */
    n = sqrtf(s[0] * s[0] + s[2] * s[2]);
    s[0] /= n, s[2] /= n;
    u[0] = s[1] * f[2] - s[2] * f[1], u[1] = s[2] * f[0] - s[0] * f[2], u[2] = s[0] * f[1] - s[1] * f[0];
    memset(out, 0, 16 * sizeof(float));
    for (i = 0; i < 3; ++i) {
        out[4 * i + 0] = t / aspect * s[i];
        out[4 * i + 1] = t * u[i];
        out[4 * i + 2] = -(far + near) / (far - near) * -f[i];
        out[4 * i + 3] = f[i];
    }
    out[12] = -t / aspect * (s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]);
    out[13] = -t * (u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
    out[14] = -(far + near) / (far - near) * (f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2]) - 2 * far * near / (far - near);
    out[15] = -(f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2]);
}

/* Attribute `location` from a column: the GL buffer the system computed it in, its own
 * array uploaded into `staging`, or its constant. */
static void attribute(GLuint location, const psys_column* c, size_t rows, GLuint staging) {
    GLuint buffer = c->gl_buffer;
    if (!buffer && c->data) {
        glNamedBufferData(staging, (GLsizeiptr)(rows * sizeof(float)), c->data, GL_STREAM_DRAW);
        buffer = staging;
    }
    if (!buffer) {
        glDisableVertexAttribArray(location);
        glVertexAttrib1f(location, c->constant);
        return;
    }
    glBindBuffer(GL_ARRAY_BUFFER, buffer);
    glVertexAttribPointer(location, 1, GL_FLOAT, GL_FALSE, 0, NULL);
    glEnableVertexAttribArray(location);
}

/* Draws every type's points: each column an attribute of its own. On the glsl backend
 * psys_get_draw may dispatch compute shaders (what is drawn is computed on first ask), which
 * changes the bound program: the host binds its own after it. */
static int draw(psys_system* sys, GLuint shaders, GLuint vao, GLuint staging[kAttributes]) {
    size_t type;
    for (type = 0; type < psys_type_count(sys); ++type) {
        psys_draw d;
        const psys_column* columns[kAttributes];
        GLuint k;
        if (failed(psys_get_draw(sys, type, &d))) return 1;
        if (d.rows == 0 || (!d.visible.data && !d.visible.gl_buffer)) continue;
        glUseProgram(shaders);
        glBindVertexArray(vao);
        columns[0] = &d.visible;
        for (k = 0; k < 3; ++k) columns[1 + k] = &d.position[k];
        for (k = 0; k < 4; ++k) columns[4 + k] = &d.color[k];
        columns[8] = &d.size;
        for (k = 0; k < kAttributes; ++k) attribute(k, columns[k], d.rows, staging[k]);
        glDrawArrays(GL_POINTS, 0, (GLsizei)d.rows);
    }
    return 0;
}

static void savePng(const char* path, int width, int height) {
    unsigned char* pixels = malloc((size_t)width * (size_t)height * 4);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, pixels);
    stbi_flip_vertically_on_write(1);
    if (!stbi_write_png(path, width, height, 4, pixels, width * 4)) fprintf(stderr, "cannot write %s\n", path);
    free(pixels);
}

static void parseVec3(const char* text, float out[3]) { sscanf(text, "%f,%f,%f", &out[0], &out[1], &out[2]); }

int main(int argc, char** argv) {
    const char *file = NULL, *png = NULL;
    long frames = -1, frame;
    float eye[3] = {0, 4, 13}, at[3] = {0, 3.5f, 0}, viewProjection[16];
    int i, width = 960, height = 540, status = 0;
    psys_options options;
    psys_system* sys = NULL;
    GLFWwindow* window;
    GLuint shaders, vao, staging[kAttributes];

    psys_options_init(&options);
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--backend") && i + 1 < argc) options.backend = argv[++i];
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc) frames = atol(argv[++i]);
        else if (!strcmp(argv[i], "--png") && i + 1 < argc) png = argv[++i];
        else if (!strcmp(argv[i], "--eye") && i + 1 < argc) parseVec3(argv[++i], eye);
        else if (!strcmp(argv[i], "--at") && i + 1 < argc) parseVec3(argv[++i], at);
        else file = argv[i];
    }
    if (!file) {
        fprintf(stderr, "usage: glfw_host FILE [--backend llvm|interp|glsl] [--frames N] [--png OUT.png] "
                        "[--eye X,Y,Z] [--at X,Y,Z]\n");
        return 2;
    }
    if (!glfwInit()) {
        fprintf(stderr, "glfw_host: no display\n");
        return 2;
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    /* EGL: the glsl backend computes in the context current when the system is made, an
     * EGL one (GLX elsewhere: the system would make its own, and its buffers not be ours). */
    glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_EGL_CONTEXT_API);
    window = glfwCreateWindow(width, height, "psys: glfw_host", NULL, NULL);
    if (!window) {
        fprintf(stderr, "glfw_host: no OpenGL 4.5 window\n");
        glfwTerminate();
        return 2;
    }
    glfwMakeContextCurrent(window);
    glfwSwapInterval(1);

    if (failed(psys_compile_file(file, &options, &sys))) {
        glfwTerminate();
        return 1;
    }
    shaders = program();
    glCreateVertexArrays(1, &vao);
    glCreateBuffers(kAttributes, staging);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);

    for (frame = 0; !glfwWindowShouldClose(window) && (frames < 0 || frame < frames); ++frame) {
        glfwPollEvents();
        if (glfwGetKey(window, GLFW_KEY_ESCAPE) == GLFW_PRESS) break;
        if (glfwGetKey(window, GLFW_KEY_SPACE) == GLFW_PRESS && psys_trigger_count(sys) > 0) {
            psys_input trigger;
            float zeros[16] = {0};
            psys_trigger_info(sys, 0, &trigger);
            if (trigger.values <= 16) failed(psys_fire(sys, trigger.name, zeros, trigger.values));
        }
        if (failed(psys_step(sys, 1.0 / 60))) {
            status = 1;
            break;
        }
        glfwGetFramebufferSize(window, &width, &height);
        glViewport(0, 0, width, height);
        glClearColor(0.02f, 0.02f, 0.04f, 1);
        glClear(GL_COLOR_BUFFER_BIT);
        glUseProgram(shaders);
        camera((float)width / (float)(height > 0 ? height : 1), eye, at, viewProjection);
        glUniformMatrix4fv(glGetUniformLocation(shaders, "view_projection"), 1, GL_FALSE, viewProjection);
        glUniform1f(glGetUniformLocation(shaders, "pixels"), (float)height);
        if (draw(sys, shaders, vao, staging)) {
            status = 1;
            break;
        }
        if (png && frames >= 0 && frame == frames - 1) savePng(png, width, height);
        glfwSwapBuffers(window);
    }
    printf("glfw_host: %ld frames of %s on %s\n", frame, file, options.backend);
    psys_system_free(sys); /* with its context current: its GL objects go with it */
    glDeleteBuffers(kAttributes, staging);
    glDeleteVertexArrays(1, &vao);
    glDeleteProgram(shaders);
    glfwDestroyWindow(window);
    glfwTerminate();
    return status;
}
