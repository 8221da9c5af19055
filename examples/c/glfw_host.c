/* A host that embeds systems and draws them with OpenGL in a GLFW window: the draw columns
 * become vertex attributes — uploaded from the system's arrays on the CPU backends, bound
 * as they are on the glsl backend (the system computes in the window's GL context, and
 * nothing is read back).
 *
 *   glfw_host FILE... [--backend llvm|interp|glsl] [--frames N] [--png OUT.png] [--play N]
 *
 * Each FILE is a system of its own (up to 4). --play N plays N instances of each (an
 * instanced program: docs/embedding.md, "Instances") on a turning ring, moved every frame,
 * each played again where it is when it finishes. Space fires each program's first trigger
 * (with zeros); Escape quits. --frames stops after N frames (and --png saves the last one).
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

enum { kMostFiles = 4, kMostInstances = 1024 };

/* Where instance j of the `n` of system k is at time t: on a ring of its own for each
 * system, turning, tilted a little (a rotation about z: a transform in columns). */
static void placement(int k, int j, int n, double t, float out[16]) {
    float ring = 3.0f + 2.0f * (float)k, a = 6.2831853f * (float)j / (float)n + (float)t * (k % 2 ? -0.3f : 0.4f);
    float tilt = 0.3f * sinf(a * 2.0f), c = cosf(tilt), s = sinf(tilt);
    float m[16] = {c, s, 0, 0, -s, c, 0, 0, 0, 0, 1, 0, ring * cosf(a), 2.0f + 1.5f * (float)k, ring * sinf(a), 1};
    memcpy(out, m, sizeof m);
}

/* The instances of system k, moved to where they are at time t; those that finished in
 * the last step played again. */
static int playInstances(psys_system* sys, int k, psys_instance* played, int n, double t) {
    psys_instance done[kMostInstances];
    size_t finished = psys_finished_instances(sys, done, kMostInstances), f;
    float m[16];
    int j;
    for (j = 0; j < n; ++j) {
        int again = played[j] == 0;
        for (f = 0; f < finished && !again; ++f) again = done[f] == played[j];
        placement(k, j, n, t, m);
        if (again ? failed(psys_play(sys, m, &played[j])) : failed(psys_instance_transform(sys, played[j], m)))
            return 1;
    }
    return 0;
}

int main(int argc, char** argv) {
    const char *files[kMostFiles], *png = NULL;
    long frames = -1, frame;
    float eye[3] = {0, 4, 13}, at[3] = {0, 3.5f, 0}, viewProjection[16];
    int i, k, width = 960, height = 540, status = 0, count = 0, instances = 0;
    psys_options options;
    psys_system* sys[kMostFiles] = {NULL};
    static psys_instance played[kMostFiles][kMostInstances];
    GLFWwindow* window;
    GLuint shaders, vao, staging[kAttributes];

    psys_options_init(&options);
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--backend") && i + 1 < argc) options.backend = argv[++i];
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc) frames = atol(argv[++i]);
        else if (!strcmp(argv[i], "--png") && i + 1 < argc) png = argv[++i];
        else if (!strcmp(argv[i], "--eye") && i + 1 < argc) parseVec3(argv[++i], eye);
        else if (!strcmp(argv[i], "--at") && i + 1 < argc) parseVec3(argv[++i], at);
        else if (!strcmp(argv[i], "--play") && i + 1 < argc) instances = atoi(argv[++i]);
        else if (count < kMostFiles) files[count++] = argv[i];
    }
    if (count == 0 || instances < 0 || instances > kMostInstances) {
        fprintf(stderr, "usage: glfw_host FILE... [--backend llvm|interp|glsl] [--frames N] [--png OUT.png] "
                        "[--eye X,Y,Z] [--at X,Y,Z] [--play N (at most %d)]\n", kMostInstances);
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

    for (k = 0; k < count; ++k) {
        if (failed(psys_compile_file(files[k], &options, &sys[k]))) {
            status = 1;
            break;
        }
        /* The host plays them all: the system's own instance goes before it starts. */
        if (instances > 0 && (failed(psys_instance_kill(sys[k], 0)) || playInstances(sys[k], k, played[k], instances, 0)))
            status = 1;
    }
    shaders = program();
    glCreateVertexArrays(1, &vao);
    glCreateBuffers(kAttributes, staging);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);

    for (frame = 0; !status && !glfwWindowShouldClose(window) && (frames < 0 || frame < frames); ++frame) {
        glfwPollEvents();
        if (glfwGetKey(window, GLFW_KEY_ESCAPE) == GLFW_PRESS) break;
        glfwGetFramebufferSize(window, &width, &height);
        glViewport(0, 0, width, height);
        glClearColor(0.02f, 0.02f, 0.04f, 1);
        glClear(GL_COLOR_BUFFER_BIT);
        camera((float)width / (float)(height > 0 ? height : 1), eye, at, viewProjection);
        for (k = 0; k < count && !status; ++k) {
            if (glfwGetKey(window, GLFW_KEY_SPACE) == GLFW_PRESS && psys_trigger_count(sys[k]) > 0) {
                psys_input trigger;
                float zeros[16] = {0};
                psys_trigger_info(sys[k], 0, &trigger);
                if (trigger.values <= 16) failed(psys_fire(sys[k], trigger.name, zeros, trigger.values));
            }
            if (failed(psys_step(sys[k], 1.0 / 60)) ||
                (instances > 0 && playInstances(sys[k], k, played[k], instances, psys_time(sys[k])))) {
                status = 1;
                break;
            }
            glUseProgram(shaders);
            glUniformMatrix4fv(glGetUniformLocation(shaders, "view_projection"), 1, GL_FALSE, viewProjection);
            glUniform1f(glGetUniformLocation(shaders, "pixels"), (float)height);
            if (draw(sys[k], shaders, vao, staging)) status = 1;
        }
        if (png && frames >= 0 && frame == frames - 1) savePng(png, width, height);
        glfwSwapBuffers(window);
    }
    for (k = 0; k < count; ++k) {
        printf("glfw_host: %ld frames of %s on %s", frame, files[k], options.backend);
        if (instances > 0 && sys[k]) printf(", %zu instances playing", psys_instance_count(sys[k]));
        printf("\n");
        psys_system_free(sys[k]); /* with its context current: its GL objects go with it */
    }
    glDeleteBuffers(kAttributes, staging);
    glDeleteVertexArrays(1, &vao);
    glDeleteProgram(shaders);
    glfwDestroyWindow(window);
    glfwTerminate();
    return status;
}
