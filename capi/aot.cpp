// psys_open_aot: a system compiled ahead of time (`psysc build`), linked into the host. Its
// IR is parsed back and checked, and its kernels' machine code found by key
// (native::AotBackend); the interpreter and the GPU run its IR as they run any. No
// compiler and no LLVM: libpsys_runtime is this, capi/runtime.cpp and the run-time.
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "capi/handle.h"
#include "gpu/glsl_backend.h"
#include "interp/interpreter.h"
#include "ir/parser.h"
#include "ir/verifier.h"
#include "native/aot_backend.h"

using psys::capi::guarded;
using psys::capi::makeError;
using psys::capi::nullArgument;
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

// The backend an AOT system runs on, or why there is none.
std::shared_ptr<rt::Backend> makeBackend(const psys_aot& aot, const std::string& name, std::string& error) {
    if (name == "llvm" || name == "aot") {
        auto* table = reinterpret_cast<const psys::native::AotKernel*>(aot.kernels);
        return std::make_shared<psys::native::AotBackend>(aot.exact != 0, std::span(table, aot.kernel_count),
                                                           aot.target ? aot.target : "");
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

extern "C" psys_error* psys_open_aot(const psys_aot* aot, const psys_options* given, psys_system** out) {
    const char* function = "psys_open_aot";
    if (out) *out = nullptr;
    if (!out) return nullArgument(function, "the place for the system (out)");
    if (!aot) return nullArgument(function, "the build");
    if (aot->abi != PSYS_AOT_ABI)
        return makeError(fmt::format("{}: the build's format is {}, this library reads {}: build it again with this "
                                     "version of psysc",
                                     function, aot->abi, PSYS_AOT_ABI));
    if (!aot->ir || (!aot->kernels && aot->kernel_count)) return makeError(std::string(function) + ": the build is incomplete");
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
        s->running = std::make_unique<rt::System>(std::move(*module), *s->backend, o.system);
        s->describe();
        *out = s.release();
        return nullptr;
    });
}
