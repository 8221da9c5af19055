// IR text → the parser, the verifier, and when it verifies, every pass (with the verifier
// after each): a module either is refused with a message or goes through the pipeline.
#include <cstddef>
#include <cstdint>
#include <string>

#include "ir/parser.h"
#include "ir/printer.h"
#include "ir/verifier.h"
#include "opt/passes.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::string error;
    auto module = psys::ir::parseModule(std::string(reinterpret_cast<const char*>(data), size), error);
    if (!module || !psys::ir::verify(*module).empty()) return 0;
    (void)psys::ir::print(*module);
    psys::opt::PipelineOptions options;
    options.verifyEach = true;
    psys::opt::PassErrors errors;
    psys::opt::runPipeline(*module, options, errors);
    return 0;
}
