// Helpers for front-end tests: check a program given as text.
#pragma once

#include <memory>
#include <string>

#include "frontend/frontend.h"

namespace psys::test {

struct Checked {
    std::unique_ptr<SourceManager> sources;
    std::unique_ptr<DiagnosticEngine> diags;
    std::unique_ptr<ast::Program> program;  // null when there were errors
    std::string output;                     // the diagnostics as printed, without colour

    bool ok() const { return program != nullptr; }
    const ast::ObjectDecl& object(const std::string& name) const;
    const ast::Equation& equation(const std::string& object, const std::string& name) const;
    const ast::Decl& decl(const std::string& name) const;
};

// Checks `text` as the file `path` (imports resolve relative to it).
Checked check(const std::string& text, const std::string& path = "test.psys");

// The whole of a file, such as a sample.
std::string readFile(const std::string& path);

}  // namespace psys::test
