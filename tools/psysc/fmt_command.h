// `psysc fmt FILE…`: the canonical layout (frontend/format.h) printed, written back
// (--write) or checked (--check, for CI).
#pragma once

#include <string>
#include <vector>

namespace psys::tools {

struct FormatOptions {
    std::vector<std::string> files;  // `-` reads standard input
    bool check = false;              // report the files that are not formatted; change nothing
    bool write = false;              // rewrite the files that are not formatted
    bool colour = false;
    int width = 100;                 // lines longer are broken (0: never)
};

// Returns the process exit status: 0, or 1 when a file cannot be read, has syntax errors
// or (--check) is not formatted.
int formatFiles(const FormatOptions& options);

}  // namespace psys::tools
