// The IR's instruction set is the op table of core/ops.h: one definition that the IR,
// the passes, the backends and the front end all read. The names are brought into
// psys::ir so the IR reads as its own language.
#pragma once

#include "core/ops.h"

namespace psys::ir {

using core::Op;
using core::OpInfo;
using core::OpKind;
using core::opInfo;
using core::opFromName;
using core::isConstant;
using core::isInput;
using core::isLeaf;
using core::isPure;
using core::jumps;
using core::isRandom;
using core::isTemporal;
using core::isCommutative;
using core::isComponentwise;
using core::hasOwnSite;
using core::mayReferForward;
using core::readsAncestor;
using core::isGathered;

}  // namespace psys::ir
