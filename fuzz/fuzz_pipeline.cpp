// Bytes → compile → a few frames on the interpreter and on the JIT (exact maths), with
// small capacities: the two must agree on what lives, what dies and what is dropped.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "codegen_llvm/llvm_backend.h"
#include "driver/compile.h"
#include "interp/interpreter.h"
#include "rt/system.h"

// Every input is a new program: caching its compiled code on disk would only fill the disk.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
    ::setenv("PSYS_JIT_CACHE", "0", 1);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size > 4096) return 0;  // the JIT's time per input
    psys::SourceManager sources;
    psys::DiagnosticEngine diags(sources);
    auto module = psys::compileText("/nonexistent/fuzz.psys", std::string(reinterpret_cast<const char*>(data), size),
                                    sources, diags);
    if (!module) return 0;
    psys::rt::SystemOptions options;
    options.capacity = 64;
    options.threads = 1;
    psys::interp::Interpreter interpreter;
    psys::codegen_llvm::LlvmBackend jit(psys::codegen_llvm::MathMode::Exact);
    psys::rt::System a(*module, interpreter, options), b(*module, jit, options);
    for (int frame = 0; frame < 8; ++frame) {
        if (a.step(1.0 / 60) || b.step(1.0 / 60)) return 0;
        psys::rt::Stats statsA = a.stats(), statsB = b.stats();  // copies
        for (size_t t = 0; t < a.typeCount(); ++t) {
            const auto& sa = statsA.types[t];
            const auto& sb = statsB.types[t];
            if (sa.live != sb.live || sa.killed != sb.killed || sa.dropped != sb.dropped) std::abort();
        }
    }
    return 0;
}
