// psys_open_aot: a system compiled ahead of time (`psysc build`), linked into the host. Its
// IR is parsed back and checked, and its kernels' machine code found by key
// (native::AotBackend); the interpreter and the GPU run its IR as they run any. No
// compiler and no LLVM: libpsys_runtime is this, capi/runtime.cpp and the run-time.
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "capi/handle.h"
#include "gpu/glsl_backend.h"
#include "interp/interpreter.h"
#include "ir/parser.h"
#include "ir/verifier.h"
#include "native/aot_backend.h"

using psys::capi::guarded;
using psys::capi::makeError;
using psys::capi::nullArgument;
static_assert(PSYS_AOT_ABI == psys::native::kAotAbi, "the header's AOT ABI is the one psysc build writes");

namespace rt = psys::rt;

namespace {

struct AotSystem final : psys_system {
    std::shared_ptr<rt::Backend> backend;
    std::unique_ptr<rt::System> running;

    rt::System& system() override { return *running; }
    psys_error* reload(const char*) override {
        return makeError("psys_reload: an ahead-of-time compiled system does not reload (it carries no compiler): "
                         "build it again with psysc build");
    }
    ~AotSystem() override { running.reset(); }  // the system goes before its backend
};

// Whether this CPU has `feature` (LLVM's name for it: what psysc build records of a CPU's
// code, codegen_llvm/aot_object.cpp's kCheckedFeatures). A name this library cannot check
// is one it does not have: the build's code is not run on a guess.
bool cpuHas(std::string_view feature) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_cpu_init();
#define PSYS_FEATURE(name) \
    if (feature == name) return __builtin_cpu_supports(name);
    PSYS_FEATURE("sse3") PSYS_FEATURE("ssse3") PSYS_FEATURE("sse4.1") PSYS_FEATURE("sse4.2") PSYS_FEATURE("popcnt")
    PSYS_FEATURE("avx") PSYS_FEATURE("avx2") PSYS_FEATURE("fma") PSYS_FEATURE("bmi") PSYS_FEATURE("bmi2")
    PSYS_FEATURE("aes") PSYS_FEATURE("pclmul") PSYS_FEATURE("gfni") PSYS_FEATURE("vpclmulqdq")
    PSYS_FEATURE("avx512f") PSYS_FEATURE("avx512dq") PSYS_FEATURE("avx512cd") PSYS_FEATURE("avx512bw")
    PSYS_FEATURE("avx512vl") PSYS_FEATURE("avx512vnni") PSYS_FEATURE("avx512bf16") PSYS_FEATURE("avx512vbmi")
    PSYS_FEATURE("avx512vbmi2") PSYS_FEATURE("avx512ifma") PSYS_FEATURE("avx512bitalg")
    PSYS_FEATURE("avx512vpopcntdq")
#undef PSYS_FEATURE
#endif
    return false;
}

// The features of `cpu` this machine lacks (comma-separated as recorded).
std::vector<std::string> lacking(const psys_aot_cpu& cpu) {
    std::vector<std::string> out;
    for (std::string_view rest = cpu.features ? cpu.features : ""; !rest.empty();) {
        size_t comma = std::min(rest.find(','), rest.size());
        std::string_view f = rest.substr(0, comma);
        if (!f.empty() && !cpuHas(f)) out.emplace_back(f);
        rest.remove_prefix(std::min(comma + 1, rest.size()));
    }
    return out;
}

// Why none of the build's CPUs runs here: each with what it needs that this CPU lacks.
std::string noCpuFits(const psys_aot& aot) {
    std::string each;
    for (size_t c = 0; c < aot.cpu_count; ++c)
        each += fmt::format("{}{} (lacking {})", c ? ", " : "", aot.cpus[c].name ? aot.cpus[c].name : "?",
                            fmt::join(lacking(aot.cpus[c]), " "));
    return fmt::format("this CPU runs none of the build's kernels: it was built for {}; build it again with psysc build "
                       "--cpu naming this machine's CPU (or a generic one: x86-64-v2), or run its IR with "
                       "options.backend = \"interp\"",
                       each.empty() ? std::string("no CPU") : each);
}

// The backend an AOT system runs on, or why there is none.
std::shared_ptr<rt::Backend> makeBackend(const psys_aot& aot, const std::string& name, std::string& error) {
    if (name == "llvm" || name == "aot") {
        const psys_aot_cpu* cpu = psys_aot_choose_cpu(&aot);
        if (!cpu) {
            error = noCpuFits(aot);
            return nullptr;
        }
        auto* table = reinterpret_cast<const psys::native::AotKernel*>(cpu->kernels);
        return std::make_shared<psys::native::AotBackend>(aot.exact != 0, std::span(table, cpu->kernel_count),
                                                           cpu->name ? cpu->name : "");
    }
    if (name == "interp") return std::make_shared<psys::interp::Interpreter>();
    if (name == "glsl") {  // as host::makeBackend makes it: small pools on the host side, interpreted
        std::shared_ptr<psys::gpu::GlslBackend> gpu = psys::gpu::GlslBackend::create(error);
        if (!gpu) {
            error = "the glsl backend cannot start: " + error;
            return nullptr;
        }
        gpu->setHostSide(std::make_unique<psys::interp::Interpreter>(gpu->memory()));
        return gpu;
    }
    error = "there is no backend `" + name + "` for an ahead-of-time build; the backends are llvm (its compiled "
            "kernels), interp and glsl";
    return nullptr;
}

static_assert(sizeof(psys::native::AotKernel) == sizeof(psys_aot_kernel), "the AOT table's rows are one layout");

}  // namespace

extern "C" const psys_aot_cpu* psys_aot_choose_cpu(const psys_aot* aot) {
    if (!aot || aot->abi != PSYS_AOT_ABI || !aot->cpus) return nullptr;
    for (size_t c = 0; c < aot->cpu_count; ++c)
        if (lacking(aot->cpus[c]).empty()) return &aot->cpus[c];
    return nullptr;
}

extern "C" psys_error* psys_open_aot(const psys_aot* aot, const psys_options* given, psys_system** out) {
    const char* function = "psys_open_aot";
    if (out) *out = nullptr;
    if (!out) return nullArgument(function, "the place for the system (out)");
    if (!aot) return nullArgument(function, "the build");
    if (aot->abi != PSYS_AOT_ABI)
        return makeError(fmt::format("{}: the build's format is {}, this library reads {}: build it again with this "
                                     "version of psysc",
                                     function, aot->abi, PSYS_AOT_ABI));
    bool whole = aot->ir && (aot->cpus || aot->cpu_count == 0);
    for (size_t c = 0; whole && c < aot->cpu_count; ++c) whole = aot->cpus[c].kernels || aot->cpus[c].kernel_count == 0;
    if (!whole) return makeError(std::string(function) + ": the build is incomplete");
    return guarded(function, [&]() -> psys_error* {
        psys::capi::Options o;
        if (psys_error* e = psys::capi::readOptions(function, given, o)) return e;
        std::string error;
        std::optional<psys::ir::Module> module = psys::ir::parseModule(aot->ir, error);
        if (!module) return makeError(fmt::format("{}: the build's IR does not read back: {}", function, error));
        if (auto problems = psys::ir::verify(*module); !problems.empty())
            return makeError(fmt::format("{}: the build's IR is not valid: {}", function, problems.front()));
        if (auto tooLarge = rt::System::checkCapacity(*module, o.system))
            return makeError(fmt::format("{}: {}", function, *tooLarge));
        auto s = std::make_unique<AotSystem>();
        s->backend = makeBackend(*aot, o.backend, error);
        if (!s->backend) return makeError(fmt::format("{}: {}", function, error));
        if (auto refused = rt::System::checkBackend(*module, *s->backend))
            return makeError(fmt::format("{}: {}", function, *refused));
        s->running = std::make_unique<rt::System>(std::move(*module), *s->backend, o.system);
        s->describe();
        *out = s.release();
        return nullptr;
    });
}
