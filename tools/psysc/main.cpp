// psysc: the psys compiler driver.
//
//   psysc check FILE…                   check and compile; exit 0 when clean, 1 on errors
//   psysc run FILE [options]            compile and run a system (host/: the host library)
//   psysc --emit=ast|ir FILE            print the checked AST, or the IR after the passes
//   psysc --emit=glsl FILE              print the GLSL shaders the GPU backend runs
//   psysc build FILE -o NAME            NAME.a and NAME.h: the system compiled ahead of time
//   psysc --stats FILE                  the cost of each object type, without and with the optimizer
//   psysc --list-passes                 the passes in pipeline order (opt/passes.h: the registry)
//   psysc lsp                           the language server, on stdin and stdout (editor-support/)
//   psysc builtins                      the language's keywords and built-ins, as JSON
//
// Exit status: 0 success, 1 errors in the input, 2 bad usage. README.md lists the options.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <iostream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "host/large_stack.h"
#include "codegen_glsl/glsl_shaders.h"
#include "frontend/frontend.h"
#include "frontend/loader.h"
#include "ir/printer.h"
#include "opt/passes.h"
#include "stats_command.h"
#include "driver/compile.h"
#include "host/backends.h"
#include "host/session.h"
#include "lsp/features.h"
#include "lsp/server.h"
#include "rt/system.h"
#include "build_command.h"
#include "fmt_command.h"
#include "run_command.h"

namespace {

bool useColour(const std::string& mode) {
    if (mode == "always") return true;
    if (mode == "never") return false;
    const char* noColour = std::getenv("NO_COLOR");
    return isatty(STDERR_FILENO) && !(noColour && *noColour);
}

double millisecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// Checks one file, and compiles it unless `compile` is null; prints its diagnostics (and,
// with `time`, how long each part took); returns the program when it is clean.
std::unique_ptr<psys::ast::Program> checkOne(const std::string& path, psys::SourceManager& sources,
                                             const psys::CompileOptions* compile, bool colour, bool time,
                                             bool* failed, bool remarks = false) {
    psys::DiagnosticEngine diags(sources);
    auto start = std::chrono::steady_clock::now();
    auto program = psys::loadProgram(path, sources, diags);
    double parseMs = millisecondsSince(start);
    start = std::chrono::steady_clock::now();
    if (program) {
        psys::checkProgram(*program, diags);
        if (diags.errorCount() > 0) program.reset();
    }
    double checkMs = millisecondsSince(start);
    // The passes report too: an integral without a closed form under @integrator(exact),
    // a decay beyond the integrator's stability limit.
    start = std::chrono::steady_clock::now();
    if (program && compile) {
        auto module = psys::compileProgram(program.get(), sources, diags, *compile);
        if (!module) program.reset();
        else if (remarks)
            for (const psys::opt::PassMessage& m : psys::opt::largeArgumentRemarks(*module))
                diags.remark(psys::sourceRange(sources, m.loc), m.text);
    }
    double compileMs = millisecondsSince(start);
    diags.print(std::cerr, colour);
    if (time)
        std::cerr << path << ": parse " << parseMs << " ms, check " << checkMs << " ms, compile " << compileMs
                  << " ms (" << sources.count()
                  << " file" << (sources.count() == 1 ? "" : "s") << ")\n";
    if (!program) *failed = true;
    return program;
}

// CLI11's own checks let NaN through (it compares false with both bounds) and print a
// range of 300 digits for `abc`: these say what is wanted, in words.
const CLI::Validator kPositiveMetres(
    [](std::string& text) {
        char* end = nullptr;
        double v = std::strtod(text.c_str(), &end);
        return !text.empty() && *end == '\0' && std::isfinite(v) && v > 0
                   ? std::string()
                   : "takes a positive number of metres (such as 0.01), not `" + text + "`";
    },
    "");
// A whole count from 1 to 2^32 − 1, written as 1000000 or 1e6.
const CLI::Validator kCount(
    [](std::string& text) {
        char* end = nullptr;
        double v = std::strtod(text.c_str(), &end);
        if (text.empty() || *end != '\0' || !(v >= 1 && v <= 4294967295.0) || v != std::floor(v))
            return "takes a whole number from 1 to 4294967295 (such as 100000 or 1e6), not `" + text + "`";
        text = fmt::format("{:.0f}", v);
        return std::string();
    },
    "");

// The options of `psysc run`.
void addRunOptions(CLI::App& run, psys::tools::RunOptions& o) {
    run.add_option("file", o.file, "The system to run")->required()->type_name("FILE");
    run.add_option("--frames", o.frames, "Frames to run (600)")->check(CLI::Range(0, 1000000000));
    run.add_option("--dt", o.dt, "Seconds per frame (1/60)");
    run.add_option("--seed", o.seed, "Random seed (1)");
    run.add_option("--capacity", o.capacity, "Most live objects per type, unless @capacity says (1048576)")
        ->transform(kCount)->type_name("COUNT");
    run.add_option("--set", o.sets, "Set an extern: NAME=VALUE or NAME=X,Y,Z (repeatable)")
        ->allow_extra_args(false);
    run.add_option("--fire", o.fires, "Fire a trigger before a frame: TRIGGER[:X,Y,Z]@FRAME (repeatable)")->allow_extra_args(false);
    run.add_option("--dump", o.dump, "Write every drawn point per frame to FILE.csv or FILE.json");
    run.add_option("--dump-every", o.dumpEvery, "Dump every Nth frame (1)")->check(CLI::Range(1, 1000000000));
    run.add_flag("--quiet", o.quiet, "No line per frame, only the summary");
    run.add_flag("--events", o.events,
                 "Print each frame's notifications (`notify \"NAME\"(…)`): a line each, `event NAME at frame F: values`");
    run.add_flag("--until-finished", o.untilFinished,
                 "Stop after the frame that leaves the system finished: nothing alive, nothing to create (--frames is "
                 "the most frames, and no --fire is left)");
    run.add_option("--backend", o.backend, "llvm (JIT-compiled, the default), interp (the reference) or glsl (compute shaders on OpenGL 4.5: a GPU, or llvmpipe)")
        ->check(CLI::IsMember(psys::host::backendNames()));
    run.add_option("--math", o.math,
                    "llvm backend: fast (fused multiply-adds, vector math functions, the optimizer's relaxed "
                    "rewrites; the default) or exact (the interpreter's results bit for bit)")
        ->check(CLI::IsMember({"fast", "exact"}));
    run.add_option("--threads", o.threads, "Threads for pool updates: 0 for every core (0)")
        ->check(CLI::Range(0u, psys::rt::SystemOptions::kMostThreads));
    run.add_option("--rows", o.rows,
                   "Where pools keep their rows: backend (as the backend keeps them, the default: glsl in the "
                   "GPU's memory wherever a type can, emitters whose emissions the memory decides and children "
                   "with their parents among them), memory (so on any backend, drawing after each step as the "
                   "GPU does) or host")
        ->check(CLI::IsMember({"backend", "memory", "host"}));
    run.add_flag("--timing", o.timing, "Print compile time and the time spent stepping and drawing");
    run.add_flag("--print-schedule", o.printSchedule, "Print the phases a step runs, in order, and run no frame");
    run.add_flag("--remarks", o.remarks, "llvm backend: print whether each update loop vectorized, and the library functions compiled code calls");
}

// `psysc --emit=ast FILE`
int printAst(const std::string& file, bool colour) {
    psys::SourceManager sources;
    bool failed = false;
    auto program = checkOne(file, sources, nullptr, colour, false, &failed);
    if (!program) return 1;
    std::cout << psys::printAst(*program, sources);
    return 0;
}

// `psysc --emit=ir FILE [--print-after=PASS…] [--locations]`
int printIr(const std::string& file, psys::CompileOptions options, bool colour) {
    for (const std::string& pass : options.pipeline.printAfter) {
        bool known = false;
        for (auto& info : psys::opt::passes()) known |= pass == info.name;
        if (!known) {
            std::cerr << "psysc: error: unknown pass `" << pass << "` for --print-after; the passes are:\n";
            for (auto& info : psys::opt::passes()) std::cerr << "  " << info.name << ": " << info.summary << "\n";
            return 2;
        }
    }
    psys::SourceManager sources;
    psys::DiagnosticEngine diags(sources);
    options.pipeline.log = &std::cout;
    auto module = psys::compileFile(file, sources, diags, options);
    diags.print(std::cerr, colour);
    if (!module) return 1;
    if (!options.pipeline.printAfterAll && options.pipeline.printAfter.empty())
        std::cout << psys::ir::print(*module, options.pipeline.print);
    return 0;
}

// `psysc --emit=glsl FILE`: every shader of the module, each after a line naming it.
int printGlsl(const std::string& file, const psys::CompileOptions& options, bool colour) {
    psys::SourceManager sources;
    psys::DiagnosticEngine diags(sources);
    auto module = psys::compileFile(file, sources, diags, options);
    diags.print(std::cerr, colour);
    if (!module) return 1;
    if (module->instanced()) {
        std::cerr << "psysc: error: " << psys::core::kNoInstances << "\n";
        return 1;
    }
    for (const auto& shader : psys::codegen_glsl::moduleShaders(psys::rt::launchPlan(*module)))
        std::cout << "//// " << shader.name << "\n" << shader.source << "\n";
    return 0;
}

}  // namespace

namespace {

int realMain(int argc, char** argv) {
    CLI::App app{"psysc: compiler for .psys particle systems"};
    app.set_version_flag("--version", std::string("psysc ") + PSYS_VERSION);
    std::string colourMode = "auto";
    app.add_option("--color", colourMode, "Colour diagnostics: auto (on a terminal), always or never")
        ->check(CLI::IsMember({"auto", "always", "never"}));

    std::string emit;
    std::vector<std::string> emitFiles;
    app.add_option("--emit", emit, "Print an intermediate form of FILE")->check(CLI::IsMember({"ast", "ir", "glsl"}));
    app.add_option("files", emitFiles, "Source file for --emit")->type_name("FILE");
    std::vector<std::string> printAfter;
    bool printAfterAll = false;
    std::string passNames;
    for (const auto& pass : psys::opt::passes()) passNames += std::string(passNames.empty() ? "" : ", ") + pass.name;
    app.add_option("--print-after", printAfter,
                   "With --emit=ir: print the IR after this pass (repeatable), one of: " + passNames +
                       " (--list-passes says what each does)")
        ->type_name("PASS")->allow_extra_args(false);
    bool listPasses = false;
    app.add_flag("--list-passes", listPasses, "Print the passes in pipeline order, what each does and when it runs");
    app.add_flag("--print-after-all", printAfterAll, "With --emit=ir: print the IR after every pass");
    bool locations = false;
    app.add_flag("--locations", locations, "With --emit=ir: say where each instruction came from (file:line:column)");
    bool relaxedMath = false, noOptimize = false;
    app.add_flag("--relaxed-math", relaxedMath,
                 "Allow rewrites that may change the last bits of a result (docs/optimizer.md)");
    app.add_flag("--no-optimize", noOptimize, "Only the lowering passes");
    std::string integrator;
    std::vector<std::string> methods(psys::core::kIntegratorNames.begin(), psys::core::kIntegratorNames.end());
    app.add_option("--integrator", integrator,
                   "Integrate every object with this method, whatever its @integrator says (to try one without "
                   "editing the source)")
        ->check(CLI::IsMember(methods))->type_name("METHOD");
    double tolerance = 0;
    app.add_option("--tolerance", tolerance,
                   "For check, run and build: the largest position error in metres an object without @tolerance may have "
                   "over 10 s; the compiler chooses its integrator and sub-step (docs/accuracy.md)")
        ->check(kPositiveMetres)->type_name("METRES");
    std::string statsFile;
    app.add_option("--stats", statsFile, "Per object type: operations per update before and after optimization, "
                   "state bytes per object")->type_name("FILE");

    auto* check = app.add_subcommand("check", "Check and compile .psys files and report every error and warning");
    std::vector<std::string> checkFiles;
    check->add_option("files", checkFiles, "Files to check")->required()->type_name("FILE");
    bool time = false;
    check->add_flag("--time", time, "Print how long parsing and checking took");
    bool remarks = false;
    bool explain = false;
    check->add_flag("--explain", explain, "Say what integrator and sub-step @tolerance (or --tolerance) chose for each "
                    "object, what else was tried, and the error of each");
    check->add_flag("--remarks", remarks, "Also say where a large argument meets sin, cos or tan (fast maths may round it "
                    "differently: docs/accuracy.md)");

    auto* run = app.add_subcommand("run", "Compile FILE and run the system (JIT-compiled with LLVM, or interpreted)");
    psys::tools::RunOptions runOptions;
    addRunOptions(*run, runOptions);
    run->fallthrough();

    auto* build = app.add_subcommand("build", "Compile FILE ahead of time: NAME.a (its kernels for a CPU) and NAME.h, for a "
                                     "host that links libpsys_runtime (no compiler, no LLVM)");
    psys::tools::BuildOptions buildOptions;
    build->add_option("file", buildOptions.file, "The system to compile")->required()->type_name("FILE");
    build->add_option("-o,--output", buildOptions.output, "Write NAME.a and NAME.h")->required()->type_name("NAME");
    build->add_option("--math", buildOptions.math, "fast (the default) or exact (the interpreter's results bit for bit)")
        ->check(CLI::IsMember({"fast", "exact"}));
    build->add_option("--target", buildOptions.target, "The target triple (the host's by default)")->type_name("TRIPLE");
    build->add_option("--cpu", buildOptions.cpu, "The CPUs to compile for, comma-separated (x86-64-v2,x86-64-v3,znver4): names LLVM "
                      "knows, or native (this machine's, the default; generic for another triple). The archive holds "
                      "each one's kernels and runs the most capable the running machine has")->type_name("CPU[,CPU…]");
    build->add_flag("!--no-glsl", buildOptions.glsl, "Leave the compute shaders out of the archive (psys_aot.glsl is NULL)");
    build->fallthrough();

    auto* lsp = app.add_subcommand("lsp", "Serve the Language Server Protocol on stdin and stdout (for editors)");
    int debounceMs = 150;
    lsp->add_option("--debounce", debounceMs, "Milliseconds of quiet after an edit before it is checked (150)")
        ->check(CLI::Range(0, 10000));
    bool stdio = true;  // what vscode-languageclient passes for its stdio transport
    lsp->add_flag("--stdio", stdio, "Use stdin and stdout (the default and only transport)");
    auto* format = app.add_subcommand("fmt", "Print .psys files in the canonical layout (comments kept, meaning unchanged)");
    psys::tools::FormatOptions formatOptions;
    format->add_option("files", formatOptions.files, "Files to format (- reads standard input)")->required()
        ->type_name("FILE");
    format->add_option("--width", formatOptions.width,
                       "Break lines longer than this after a comma or an operator (0: never)")
        ->check(CLI::Range(0, 10000))
        ->capture_default_str();
    auto* checkFlag = format->add_flag("--check", formatOptions.check, "Change nothing; list the files that are not formatted and exit 1 "
                     "if there are any");
    checkFlag->excludes(format->add_flag("-w,--write", formatOptions.write,
                                         "Rewrite the files that are not formatted, in place"));
    auto* builtins = app.add_subcommand("builtins", "Print the language's keywords, built-ins and attributes as JSON");

    app.require_subcommand(0, 1);
    check->fallthrough();
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        int code = app.exit(e);
        return e.get_exit_code() == 0 ? 0 : (code == 0 ? 0 : 2);
    }
    bool colour = useColour(colourMode);

    std::optional<psys::core::Integrator> everyObject;
    if (!integrator.empty()) everyObject = psys::core::integratorFromName(integrator);
    if (lsp->parsed()) {
        psys::lsp::ServerOptions options;
        options.debounce = std::chrono::milliseconds(debounceMs);
        options.version = PSYS_VERSION;
        return psys::lsp::serve(STDIN_FILENO, STDOUT_FILENO, options);
    }
    if (format->parsed()) {
        formatOptions.colour = colour;
        return psys::tools::formatFiles(formatOptions);
    }
    if (builtins->parsed()) {
        std::cout << psys::lsp::vocabulary().dump(2) << "\n";
        return 0;
    }
    if (listPasses) {
        std::cout << psys::opt::passTable();
        return 0;
    }
    if (!statsFile.empty()) return psys::tools::printStats(statsFile, everyObject, colour);
    if (run->parsed()) {
        runOptions.colour = colour;
        runOptions.relaxed = relaxedMath;
        runOptions.optimize = !noOptimize;
        runOptions.integrator = everyObject;
        runOptions.tolerance = tolerance;
        try {
            return psys::tools::runSystem(runOptions);
        } catch (const std::exception& e) {  // a backend that cannot go on (a GL that refuses a shader, …)
            std::cerr << "psysc: error: " << e.what() << "\n";
            return 1;
        }
    }
    if (build->parsed()) {
        buildOptions.colour = colour;
        buildOptions.relaxed = relaxedMath;
        buildOptions.optimize = !noOptimize;
        buildOptions.integrator = everyObject;
        buildOptions.tolerance = tolerance;
        return psys::tools::buildSystem(buildOptions);
    }
    if (check->parsed()) {
        bool failed = false;
        psys::CompileOptions options;
        options.pipeline.pass.everyObject = everyObject;
        psys::tune::TuneOptions tune;
        tune.tolerance = tolerance;
        auto choices = std::make_shared<std::vector<psys::tune::Choice>>();
        psys::host::BackendChoice jit;  // as `psysc run` runs it: the JIT, fast maths
        psys::host::chooseUnderTolerance(options, tune, jit, choices);
        for (const std::string& file : checkFiles) {
            psys::SourceManager sources;
            choices->clear();
            bool thisFailed = false;
            checkOne(file, sources, &options, colour, time, &thisFailed, remarks);
            failed |= thisFailed;
            // A file with errors chose nothing: its errors say why, not "no object states…".
            if (explain)
                std::cout << (checkFiles.size() > 1 ? file + ":\n" : "")
                          << (thisFailed       ? "not compiled: nothing chosen\n"
                              : choices->empty() ? "no object states a tolerance (@tolerance, or --tolerance)\n"
                                                 : psys::tune::explain(*choices));
        }
        return failed ? 1 : 0;
    }
    if (!emit.empty()) {
        if (emitFiles.size() != 1) {
            std::cerr << "psysc: --emit=" << emit << " takes exactly one FILE\n";
            return 2;
        }
        if (emit == "ast") return printAst(emitFiles[0], colour);
        psys::CompileOptions options;
        options.pipeline.optimize = !noOptimize;
        options.pipeline.pass.relaxed = relaxedMath;
        options.pipeline.pass.everyObject = everyObject;
        options.pipeline.printAfter = {printAfter.begin(), printAfter.end()};
        options.pipeline.printAfterAll = printAfterAll;
        options.pipeline.print.locations = locations;
        if (emit == "glsl") return printGlsl(emitFiles[0], options, colour);
        return printIr(emitFiles[0], options, colour);
    }
    std::cerr << app.help();
    return 2;
}

}  // namespace

// Everything runs on a thread with a large stack (host/large_stack.h).
int main(int argc, char** argv) {
    return psys::host::runWithLargeStack([&] { return realMain(argc, argv); });
}
