// What the pass tests share: IR text in, one pass, IR text out.
#pragma once

#include <doctest/doctest.h>

#include <string>

#include "ir/parser.h"
#include "ir/printer.h"
#include "ir/verifier.h"
#include "opt/passes.h"

namespace psys::test {

inline ir::Module parseIr(const std::string& text) {
    std::string error;
    auto m = ir::parseModule(text, error);
    INFO(error);
    REQUIRE(m.has_value());
    return *m;
}

// The module after `pass`, printed, after the pass's errors and any verifier complaint.
inline std::string after(const std::string& text, void (*pass)(ir::Module&, opt::PassErrors&)) {
    ir::Module m = parseIr(text);
    opt::PassErrors errors;
    pass(m, errors);
    std::string all;
    for (auto& e : errors) all += "error: " + e.text + "\n";
    for (auto& e : ir::verify(m)) all += "malformed: " + e + "\n";
    return all + ir::print(m);
}

}  // namespace psys::test
