// Bytes → the front end (parse, resolve, type-check): every input ends in diagnostics or a
// checked program, never a crash, a hang or a sanitizer report.
#include <cstddef>
#include <cstdint>
#include <string>

#include "frontend/frontend.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    psys::SourceManager sources;
    psys::DiagnosticEngine diags(sources);
    // A path in no directory: imports resolve to nothing readable, so runs do not depend on the disk.
    psys::checkText("/nonexistent/fuzz.psys", std::string(reinterpret_cast<const char*>(data), size), sources, diags);
    (void)diags.render(false);
    return 0;
}
