#include "gpu/gl_programs.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <system_error>
#include <unistd.h>
#include <vector>

#include <epoxy/gl.h>
#include <fmt/format.h>

#include "gpu/gl_context.h"

namespace psys::gpu {

namespace {

std::filesystem::path cacheDirectory() {
    if (const char* v = std::getenv("PSYS_GL_CACHE"); v && *v) return std::string(v) == "0" ? "" : v;
    if (const char* v = std::getenv("XDG_CACHE_HOME"); v && *v) return std::filesystem::path(v) / "psys" / "gl";
    if (const char* v = std::getenv("HOME"); v && *v) return std::filesystem::path(v) / ".cache" / "psys" / "gl";
    return "";
}

uint64_t fnv1a(const std::string& text, uint64_t h = 14695981039346656037ull) {
    for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
    return h;
}

std::string infoLog(GLuint object, bool isProgram) {
    GLint length = 0;
    isProgram ? glGetProgramiv(object, GL_INFO_LOG_LENGTH, &length) : glGetShaderiv(object, GL_INFO_LOG_LENGTH, &length);
    std::string text(static_cast<size_t>(std::max(length, 1)), '\0');
    isProgram ? glGetProgramInfoLog(object, length, nullptr, text.data())
              : glGetShaderInfoLog(object, length, nullptr, text.data());
    return text;
}

}  // namespace

unsigned computeProgram(const std::string& source, const std::string& what) {
    ProgramCompiler compiler(false);
    unsigned program = compiler.begin(source);
    compiler.finish(program, source, what);
    return program;
}

ProgramCompiler::ProgramCompiler(bool cache) {
    renderer_ = rendererName();
    if (epoxy_has_gl_extension("GL_KHR_parallel_shader_compile")) {
        glMaxShaderCompilerThreadsKHR(0xFFFFFFFFu);  // as many as the driver likes
        parallel = true;
    } else if (epoxy_has_gl_extension("GL_ARB_parallel_shader_compile")) {
        glMaxShaderCompilerThreadsARB(0xFFFFFFFFu);
        parallel = true;
    }
    GLint formats = 0;
    glGetIntegerv(GL_NUM_PROGRAM_BINARY_FORMATS, &formats);
    if (cache) directory_ = cacheDirectory();
    binaries = formats > 0 && !directory_.empty();
}

// The file of a source's binary: named by the renderer, the GL version and the source
// (64-bit FNV-1a of each); the source's length is stored in it and checked too.
std::filesystem::path ProgramCompiler::file(const std::string& source) const {
    return directory_ / fmt::format("{:016x}-{:016x}.bin", fnv1a(renderer_), fnv1a(source));
}

unsigned ProgramCompiler::begin(const std::string& source) {
    GLuint program = glCreateProgram();
    if (binaries) {
        std::ifstream in(file(source), std::ios::binary);
        std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        uint64_t length = 0;
        GLenum format = 0;
        if (bytes.size() > sizeof length + sizeof format) {
            std::copy_n(bytes.data(), sizeof length, reinterpret_cast<char*>(&length));
            std::copy_n(bytes.data() + sizeof length, sizeof format, reinterpret_cast<char*>(&format));
            if (length == source.size()) {
                size_t header = sizeof length + sizeof format;
                glProgramBinary(program, format, bytes.data() + header, static_cast<GLsizei>(bytes.size() - header));
                GLint ok = 0;
                glGetProgramiv(program, GL_LINK_STATUS, &ok);
                if (ok) {
                    ++loaded;
                    return program;
                }
            }
        }
        glDeleteProgram(program);  // refused or not there: compiled
        program = glCreateProgram();
        glProgramParameteri(program, GL_PROGRAM_BINARY_RETRIEVABLE_HINT, GL_TRUE);
    }
    GLuint shader = glCreateShader(GL_COMPUTE_SHADER);
    const char* text = source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    glAttachShader(program, shader);
    glLinkProgram(program);
    glDeleteShader(shader);  // freed with the program
    ++compiled;
    return program;
}

void ProgramCompiler::finish(unsigned program, const std::string& source, const std::string& what) {
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);  // waits for it
    if (!ok) {
        // The shader's log says why it did not compile, the program's why it did not link.
        GLuint shader = 0;
        GLsizei count = 0;
        glGetAttachedShaders(program, 1, &count, &shader);
        GLint compiled = 1;
        if (count) glGetShaderiv(shader, GL_COMPILE_STATUS, &compiled);
        std::string message = count && !compiled ? infoLog(shader, false) : infoLog(program, true);
        glDeleteProgram(program);
        throw std::runtime_error("the GL did not " + std::string(count && !compiled ? "compile" : "link") +
                                 " the shader of " + what + ":\n" + message);
    }
    if (!binaries) return;
    GLint size = 0;
    glGetProgramiv(program, GL_PROGRAM_BINARY_LENGTH, &size);
    if (size <= 0) return;
    std::filesystem::path path = file(source);
    if (std::filesystem::exists(path)) return;  // loaded from it
    std::vector<char> bytes(static_cast<size_t>(size));
    GLenum format = 0;
    glGetProgramBinary(program, size, nullptr, &format, bytes.data());
    std::error_code error;
    std::filesystem::create_directories(directory_, error);
    // Written aside and renamed: another process never reads half a file. A cache that
    // cannot be written is no cache, not an error.
    std::filesystem::path part = path;
    part += fmt::format(".{}", static_cast<unsigned>(::getpid()));
    {
        std::ofstream out(part, std::ios::binary);
        uint64_t length = source.size();
        out.write(reinterpret_cast<const char*>(&length), sizeof length);
        out.write(reinterpret_cast<const char*>(&format), sizeof format);
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        if (!out) return;
    }
    std::filesystem::rename(part, path, error);
    if (error) std::filesystem::remove(part, error);
}

}  // namespace psys::gpu
