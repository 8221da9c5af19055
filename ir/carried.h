// The slots split-kernels adds to carry a value from the update to the kernels that run
// after it (`carried.NAME`, `carried%N`): named by the value, which an edit or another
// maths renumbers, and written by every update before anything reads them — not state a
// reload keeps or loses (rt/reload.cpp leaves them out of its report).
#pragma once

#include <string_view>

#include "ir/ir.h"

namespace psys::ir {

inline constexpr std::string_view kCarriedSlot = "carried";

inline bool isCarried(const StateSlot& slot) {
    const std::string& n = slot.name;
    return n.size() > kCarriedSlot.size() && n.compare(0, kCarriedSlot.size(), kCarriedSlot) == 0 &&
           (n[kCarriedSlot.size()] == '.' || n[kCarriedSlot.size()] == '%');
}

}  // namespace psys::ir
