#include "ir/ops.h"

#include <array>

namespace psys::ir {
namespace {

constexpr OpInfo kOps[] = {
#define PSYS_IR_INFO(id, text, arity, flags) {text, arity, flags},
    PSYS_IR_OPS(PSYS_IR_INFO)
#undef PSYS_IR_INFO
};

}  // namespace

const OpInfo& opInfo(Op op) { return kOps[static_cast<size_t>(op)]; }

std::optional<Op> opFromName(std::string_view name) {
    for (size_t i = 0; i < std::size(kOps); ++i)
        if (kOps[i].name == name) return static_cast<Op>(i);
    return std::nullopt;
}

bool isInput(Op op) { return op <= Op::Uniform; }

bool mayReferForward(Op op, size_t operand) {
    if (op == Op::FollowedBy) return operand == 1;
    return opInfo(op).flags & kDelays;
}

}  // namespace psys::ir
