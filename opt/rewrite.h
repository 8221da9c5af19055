// Rebuilding a kernel: the tool most passes are written with.
//
// A Rewriter copies the instructions of a kernel that its yields and named equations use,
// in order, into a fresh kernel (so dead code disappears and hash-consing merges what
// has become equal). For each live instruction a pass's hook may build a replacement;
// otherwise the instruction is copied with its operands mapped. Copies fold the trivial
// cases that specialisation creates: `select` on a constant, `and`/`or`/`not` of
// constants. What a hook builds gets the location of the instruction it replaces.
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include "ir/ir.h"

namespace psys::opt {

class Rewriter {
public:
    using Hook = std::function<std::optional<ir::ValueId>(Rewriter&, ir::ValueId old, const ir::Inst& inst,
                                                          const std::vector<ir::ValueId>& operands)>;

    explicit Rewriter(const ir::Kernel& from) : from_(from) {}

    // Rebuilds from the given roots (old values); returns the new kernel with yields and
    // equations mapped (those whose value is live).
    ir::Kernel run(const Hook& hook, const std::vector<ir::ValueId>& roots);
    ir::Kernel run(const Hook& hook);  // roots: every yield and equation

    ir::Kernel& to() { return to_; }
    // The new value of an old one; valid for old values already visited.
    ir::ValueId map(ir::ValueId old) const { return mapped_.at(old); }
    bool visited(ir::ValueId old) const { return mapped_.count(old) > 0; }
    // Adds `inst` to the new kernel, folding trivial cases.
    ir::ValueId emit(ir::Inst inst);

private:
    const ir::Kernel& from_;
    ir::Kernel to_;
    std::map<ir::ValueId, ir::ValueId> mapped_;
};

// The zero value of a type: false, 0 or a zero vector.
ir::ValueId zeroOf(ir::Kernel& k, ir::Type t);

// Whether `v` depends only on what is fixed when an object is created: its parameters and
// constants, through pure instructions.
bool creationInvariant(const ir::Kernel& k, ir::ValueId v);

}  // namespace psys::opt
