// What a compiled system costs per object: the figures `psysc --stats` prints and
// docs/optimizer.md tabulates.
#pragma once

#include <string>
#include <vector>

#include "ir/ir.h"

namespace psys::opt {

struct ObjectCost {
    std::string name;
    size_t opsPerUpdate = 0;   // scalar operations run per object per frame: update + render + exports
    size_t treeOpsPerUpdate = 0;  // the same if every use evaluated its expression tree again (no
                                  // sharing): the form the thesis measured its 20–40% against
    size_t opsAtCreation = 0;  // the same for init and the spawn kernels
    size_t uniformOps = 0;     // scalar operations per type per step (uniform kernels)
    size_t stateBytes = 0;     // state slots kept per object
    size_t paramBytes = 0;     // parameters kept per object
};

std::vector<ObjectCost> measure(const ir::Module& module);
size_t countOps(const ir::Kernel& kernel);
size_t countTreeOps(const ir::Kernel& kernel);

}  // namespace psys::opt
