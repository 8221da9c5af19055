#include "host/backends.h"

#include "codegen_llvm/llvm_backend.h"
#include "gpu/glsl_backend.h"
#include "interp/interpreter.h"

namespace psys::host {

std::vector<std::string> backendNames() { return {"llvm", "interp", "glsl"}; }

Parsed<std::shared_ptr<rt::Backend>> makeBackend(const BackendChoice& choice) {
    using Result = Parsed<std::shared_ptr<rt::Backend>>;
    if (choice.math != "fast" && choice.math != "exact")
        return Result::fail("the maths is fast or exact, not `" + choice.math + "`");
    if (choice.name == "llvm") {
        auto mode = choice.math == "exact" ? codegen_llvm::MathMode::Exact : codegen_llvm::MathMode::Fast;
        return {std::make_shared<codegen_llvm::LlvmBackend>(mode, choice.jitCache), {}};
    }
    if (choice.name == "interp") return {std::make_shared<interp::Interpreter>(), {}};
    if (choice.name == "glsl") {
        std::string error;
        std::shared_ptr<gpu::GlslBackend> gpu = gpu::GlslBackend::create(error);
        if (!gpu) return Result::fail("the glsl backend cannot start: " + error);
        gpu->setHostSide(std::make_unique<interp::Interpreter>(gpu->memory()));
        return {gpu, {}};
    }
    std::string names;
    for (const std::string& n : backendNames()) names += (names.empty() ? "" : ", ") + n;
    return Result::fail("there is no backend `" + choice.name + "`; the backends are " + names);
}

}  // namespace psys::host
