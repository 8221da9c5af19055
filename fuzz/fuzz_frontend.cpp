// Bytes → the front end (parse, resolve, type-check) and the formatter: every input ends in
// diagnostics or a checked program, never a crash, a hang or a sanitizer report; what the
// formatter lays out, it lays out the same way again; a parse by top-level declaration
// through a parse cache (the language server's, frontend/parse_cache.h), cold and after
// every declaration moved, gives what a parse of the whole text gives.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "frontend/format.h"
#include "frontend/frontend.h"
#include "frontend/loader.h"
#include "frontend/parse_cache.h"

namespace {

// The diagnostics, and the checked tree where there are none.
std::string parsed(const std::string& text, psys::ParseCache* cache) {
    psys::SourceManager sources;
    psys::DiagnosticEngine diags(sources);
    auto program = psys::loadProgramFromText("/nonexistent/fuzz.psys", text, sources, diags, nullptr, cache);
    if (program) psys::checkProgram(*program, diags);
    std::string out = diags.render(false);
    if (program && diags.errorCount() == 0) out += psys::printAst(*program, sources);
    return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::string text(reinterpret_cast<const char*>(data), size);
    psys::ParseCache cache;
    if (parsed(text, &cache) != parsed(text, nullptr)) std::abort();
    cache.sweep();
    if (parsed("\n" + text, &cache) != parsed("\n" + text, nullptr)) std::abort();

    psys::SourceManager sources;
    psys::DiagnosticEngine diags(sources);
    // A path in no directory: imports resolve to nothing readable, so runs do not depend on the disk.
    psys::checkText("/nonexistent/fuzz.psys", text, sources, diags);
    (void)diags.render(false);
    auto formatted = psys::formatSource(0, sources, diags);
    if (formatted) {
        int again = sources.add("/nonexistent/formatted.psys", *formatted);
        auto twice = psys::formatSource(again, sources, diags);
        if (!twice || *twice != *formatted) std::abort();
    }
    return 0;
}
