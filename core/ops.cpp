#include "core/ops.h"

#include <iterator>

namespace psys::core {
namespace {

constexpr OpInfo kOps[] = {
#define PSYS_OP_INFO(id, text, arity, kind, flags, delayed, spelling) {text, arity, OpKind::kind, flags, delayed, spelling},
    PSYS_OPS(PSYS_OP_INFO)
#undef PSYS_OP_INFO
};

}  // namespace

const OpInfo& opInfo(Op op) { return kOps[static_cast<size_t>(op)]; }

std::optional<Op> opFromName(std::string_view name) {
    for (size_t i = 0; i < std::size(kOps); ++i)
        if (kOps[i].name == name) return static_cast<Op>(i);
    return std::nullopt;
}

}  // namespace psys::core
