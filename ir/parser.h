// Reads the IR's text form (see printer.h) back, so each pass can be tested on its own:
// IR text in, pass, IR text out.
#pragma once

#include <optional>
#include <string>

#include "ir/ir.h"

namespace psys::ir {

// On failure returns nullopt and sets `error` to "line N: what is wrong".
std::optional<Module> parseModule(const std::string& text, std::string& error);

}  // namespace psys::ir
