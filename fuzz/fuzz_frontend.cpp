// Bytes → the front end (parse, resolve, type-check) and the formatter: every input ends in
// diagnostics or a checked program, never a crash, a hang or a sanitizer report; what the
// formatter lays out, it lays out the same way again.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "frontend/format.h"
#include "frontend/frontend.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    psys::SourceManager sources;
    psys::DiagnosticEngine diags(sources);
    // A path in no directory: imports resolve to nothing readable, so runs do not depend on the disk.
    psys::checkText("/nonexistent/fuzz.psys", std::string(reinterpret_cast<const char*>(data), size), sources, diags);
    (void)diags.render(false);
    auto formatted = psys::formatSource(0, sources, diags);
    if (formatted) {
        int again = sources.add("/nonexistent/formatted.psys", *formatted);
        auto twice = psys::formatSource(again, sources, diags);
        if (!twice || *twice != *formatted) std::abort();
    }
    return 0;
}
