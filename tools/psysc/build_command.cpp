#include "build_command.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "codegen_glsl/glsl_shaders.h"
#include "codegen_llvm/aot_object.h"
#include "driver/compile.h"
#include "host/session.h"
#include "ir/parser.h"
#include "ir/printer.h"
#include "rt/system.h"

namespace psys::tools {
namespace {

// A C identifier from a file's name: `my-effect` → my_effect.
std::string identifier(const std::string& name) {
    std::string out;
    for (char c : name) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out = "_" + out;
    return out;
}


// A name the language accepts as a C parameter in C99 and C++17: with `_` after it where
// it is a keyword of either (`int`, `default`, `class`, `new`, …), looks like a macro
// (all capitals: `SIZE_MAX`), or would hide a function the body calls (`psys_fire`);
// with `p` before it where it is reserved to the implementation (`_Atomic`, `__x`).
std::string parameterName(const std::string& name) {
    static const std::set<std::string> keywords = {
        // C99 and C11
        "auto", "break", "case", "char", "const", "continue", "default", "do", "double", "else", "enum", "extern",
        "float", "for", "goto", "if", "inline", "int", "long", "register", "restrict", "return", "short", "signed",
        "sizeof", "static", "struct", "switch", "typedef", "union", "unsigned", "void", "volatile", "while",
        // C++17 and its alternative tokens; names the standard headers make macros of
        "alignas", "alignof", "and", "and_eq", "asm", "bitand", "bitor", "bool", "catch", "char16_t", "char32_t", "class",
        "compl", "constexpr", "const_cast", "decltype", "delete", "dynamic_cast", "explicit", "export", "false",
        "friend", "mutable", "namespace", "new", "noexcept", "not", "not_eq", "nullptr", "operator", "or", "or_eq",
        "private", "protected", "public", "reinterpret_cast", "static_assert", "static_cast", "template", "this",
        "thread_local", "throw", "true", "try", "typeid", "typename", "using", "virtual", "wchar_t", "xor", "xor_eq",
        "assert", "errno", "offsetof"};
    bool capitals = std::none_of(name.begin(), name.end(), [](char c) { return std::islower(static_cast<unsigned char>(c)); });
    if (name.size() > 1 && name[0] == '_' && (name[1] == '_' || std::isupper(static_cast<unsigned char>(name[1]))))
        return "p" + name;
    if (keywords.count(name) || capitals || name.rfind("psys_", 0) == 0) return name + "_";
    return name;
}

// The C parameters of a value of type `t` called `language`, and the statement that packs
// them into `float v[]`; `used` holds the names taken already (the function's own
// `system` and `v`, the parameters before), and a name taken gets `_` after it until it
// is not (`int` beside `int_`).
void parameters(const ir::Type& t, const std::string& language, std::string& list, std::vector<std::string>& values,
                std::set<std::string>& used) {
    static const char* xyzw[] = {"x", "y", "z", "w"};
    auto unique = [&](std::string name) {
        while (used.count(name)) name += "_";
        used.insert(name);
        return name;
    };
    if (t.isBool()) {
        std::string name = unique(parameterName(language));
        list += ", int " + name;
        values.push_back(name + " ? 1.0f : 0.0f");
    } else if (t.width == 1) {
        std::string name = unique(parameterName(language));
        list += ", float " + name;
        values.push_back(name);
    } else {
        for (int c = 0; c < t.width; ++c) {
            std::string name = unique(parameterName(fmt::format("{}_{}", language, xyzw[c])));
            list += ", float " + name;
            values.push_back(name);
        }
    }
}

std::string header(const ir::Module& m, const BuildOptions& o, const std::string& name,
                   const codegen_llvm::AotObject& object) {
    std::string guard = "PSYS_AOT_" + name + "_H";
    std::string h = fmt::format(
        "/* {name}.h: `{file}` compiled ahead of time by psysc build ({math} maths, for {cpu} {triple}).\n"
        " * Link {name}.a with libpsys_runtime (pkg-config psys-runtime){libs}: no compiler, no LLVM.\n"
        " * Written by psysc: edit the .psys file and build again. */\n"
        "#ifndef {guard}\n#define {guard}\n\n#include <psys/psys.h>\n\n"
        "#ifdef __cplusplus\nextern \"C\" {{\n#endif\n\n"
        "extern const psys_aot {name}_aot;\n\n"
        "/* Starts the system (options may be NULL: its compiled kernels). */\n"
        "static inline psys_error* {name}_open(const psys_options* options, psys_system** out) {{\n"
        "    return psys_open_aot(&{name}_aot, options, out);\n}}\n\n",
        fmt::arg("name", name), fmt::arg("file", std::filesystem::path(o.file).filename().string()),
        fmt::arg("math", o.math), fmt::arg("cpu", fmt::format("{}", fmt::join(object.cpus, ", "))),
        fmt::arg("triple", object.triple),
        fmt::arg("libs", o.math == "fast" ? " and -lmvec -lm" : " and -lm"), fmt::arg("guard", guard));
    h += "/* Object types: the `type` of psys_get_draw, psys_read_points, psys_get_type_stats. */\nenum {\n";
    for (size_t t = 0; t < m.objects.size(); ++t) h += fmt::format("    {}_type_{} = {},\n", name, identifier(m.objects[t].name), t);
    h += "};\n";
    for (const ir::Extern& e : m.externs) {
        std::string list;
        std::vector<std::string> values;
        std::set<std::string> used = {"system", "v"};
        parameters(e.type, e.name, list, values, used);
        h += fmt::format("\n/* extern {}: {} */\nstatic inline psys_error* {}_set_{}(psys_system* system{}) {{\n"
                         "    const float v[] = {{{}}};\n    return psys_set_extern(system, \"{}\", v, {});\n}}\n",
                         e.name, rt::languageName(e), name, e.name, list, fmt::join(values, ", "), e.name, values.size());
    }
    for (const ir::Trigger& t : m.triggers) {
        std::string list, types;
        std::vector<std::string> values;
        std::set<std::string> used = {"system", "v"};
        for (const ir::Param& p : t.hostParams()) {
            parameters(p.type, p.name, list, values, used);
            types += (types.empty() ? "" : ", ") + p.name + ": " + rt::languageName(p);
        }
        if (values.empty())
            h += fmt::format("\n/* trigger {}() */\nstatic inline psys_error* {}_fire_{}(psys_system* system) {{\n"
                             "    return psys_fire(system, \"{}\", NULL, 0);\n}}\n",
                             t.name, name, t.name, t.name);
        else
            h += fmt::format("\n/* trigger {}({}) */\nstatic inline psys_error* {}_fire_{}(psys_system* system{}) {{\n"
                             "    const float v[] = {{{}}};\n    return psys_fire(system, \"{}\", v, {});\n}}\n",
                             t.name, types, name, t.name, list, fmt::join(values, ", "), t.name, values.size());
    }
    h += fmt::format("\n#ifdef __cplusplus\n}}\n#endif\n\n#endif /* {} */\n", guard);
    return h;
}

bool write(const std::string& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) std::cerr << "psysc: error: cannot write `" << path << "`\n";
    return static_cast<bool>(out);
}

}  // namespace

int buildSystem(const BuildOptions& o) {
    // NAME names NAME.a, NAME.h and the C symbols NAME_aot, NAME_open, NAME_set_…: not
    // empty (that wrote the hidden files `.a` and `.h`), and not the C API's own prefix.
    std::string stem = std::filesystem::path(o.output).filename().string();
    if (stem.empty() || stem == "." || stem == "..") {
        std::cerr << "psysc: error: --output takes a path whose last part names the build (NAME.a, NAME.h), not `"
                  << o.output << "`\n";
        return 2;
    }
    if (std::string id = identifier(stem); id == "psys" || id.rfind("psys_", 0) == 0) {
        std::cerr << "psysc: error: --output `" << o.output << "` would name the build's C symbols `" << id
                  << "_…`, which are the C API's own (psys_aot, psys_open_aot, …): choose another name\n";
        return 2;
    }
    CompileOptions options;
    options.pipeline.optimize = o.optimize;
    options.pipeline.pass.relaxed = o.relaxed || o.math == "fast";  // as the JIT's fast maths compiles
    options.pipeline.pass.everyObject = o.integrator;
    // @tolerance chooses as `psysc run` does, its trials on the JIT in the build's maths:
    // the archive computes what the JIT would (it kept the default integrator before).
    tune::TuneOptions tune;
    tune.tolerance = o.tolerance;
    host::chooseUnderTolerance(options, tune, host::BackendChoice{"llvm", o.math});
    SourceManager sources;
    DiagnosticEngine diags(sources);
    std::optional<ir::Module> compiled = compileFile(o.file, sources, diags, options);
    diags.print(std::cerr, o.colour);
    if (!compiled) return 1;
    // The build's keys are computed from the IR as the host will read it back.
    std::string irText = ir::print(*compiled);
    std::string error;
    std::optional<ir::Module> module = ir::parseModule(irText, error);
    if (!module || ir::print(*module) != irText) {
        std::cerr << "psysc: internal error: the IR does not read back as it was printed" << (error.empty() ? "" : ": ")
                  << error << "\n";
        return 1;
    }
    std::string glsl;
    const bool shaders = o.glsl && !module->instanced();  // (the glsl backend plays no instances yet)
    if (shaders)
        for (const auto& shader : codegen_glsl::moduleShaders(rt::launchPlan(*module)))
            glsl += "//// " + shader.name + "\n" + shader.source + "\n";
    std::vector<std::string> cpus;
    for (std::string_view rest = o.cpu; !rest.empty();) {
        size_t comma = std::min(rest.find(','), rest.size());
        if (comma > 0) cpus.emplace_back(rest.substr(0, comma));
        rest.remove_prefix(std::min(comma + 1, rest.size()));
    }
    std::string name = identifier(std::filesystem::path(o.output).filename().string());
    codegen_llvm::AotObject object;
    try {
        auto mode = o.math == "exact" ? codegen_llvm::MathMode::Exact : codegen_llvm::MathMode::Fast;
        object = codegen_llvm::buildAotObject(*module, irText, glsl, mode, {o.target, cpus}, name + "_aot");
    } catch (const std::exception& e) {
        std::cerr << "psysc: error: " << e.what() << "\n";
        return 1;
    }
    if (!write(o.output + ".a", object.bytes) || !write(o.output + ".h", header(*module, o, name, object))) return 1;
    std::cout << fmt::format("wrote {0}.a ({1} kernels for {2} {3}, {4} bytes{5}) and {0}.h\n", o.output, object.kernels,
                             fmt::join(object.cpus, ", "), object.triple, object.bytes.size(),
                             shaders ? "" : o.glsl ? ", no shaders: the glsl backend does not play instances yet" : ", no shaders");
    if (!object.calls.empty()) std::cout << fmt::format("it calls: {}\n", fmt::join(object.calls, " "));
    return 0;
}

}  // namespace psys::tools
