// The IR instruction set, as one table: name, operand count, and properties the builder,
// verifier, printer, parser and passes need.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace psys::ir {

#define PSYS_IR_OPS(X)                                                                        \
    /* inputs: what a kernel reads; attr says which */                                       \
    X(Const, "const", 0, 0)                                                                    \
    X(Param, "param", 0, 0)               /* attr: parameter */                               \
    X(StateRead, "state", 0, 0)           /* attr: slot; the value before this update */      \
    X(Age, "age", 0, 0)                                                                        \
    X(Dt, "dt", 0, 0)                     /* the length of this update */                     \
    X(Time, "time", 0, 0)                                                                      \
    X(First, "first", 0, 0)               /* true while the object is being created */        \
    X(Extern, "extern", 0, 0)             /* attr: extern */                                  \
    X(TriggerParam, "trigger.param", 0, 0)                                                     \
    X(ParentRead, "parent.read", 0, 0)    /* attr: index into Object::parentReads */          \
    X(ParentExport, "parent.export", 0, 0) /* attr: export, attr2: levels up */               \
    X(ParentAlive, "parent.alive", 0, 0)  /* attr2: levels up */                              \
    X(ParentAge, "parent.age", 0, 0)      /* attr2: levels up */                              \
    X(ObjectId, "object.id", 0, 0)        /* u32: this object's id */                         \
    X(DrawIndex, "draw.index", 0, 0)      /* u32: which draw of every random site this is */  \
    X(Uniform, "uniform", 0, 0)           /* attr: a value of the uniform kernel */            \
    /* arithmetic, componentwise on equal types */                                             \
    X(Add, "add", 2, kCommutative)                                                             \
    X(Sub, "sub", 2, 0)                                                                        \
    X(Mul, "mul", 2, kCommutative)                                                             \
    X(Div, "div", 2, 0)                                                                        \
    X(Mod, "mod", 2, 0)                                                                        \
    X(Neg, "neg", 1, 0)                                                                        \
    X(Min, "min", 2, kCommutative)                                                             \
    X(Max, "max", 2, kCommutative)                                                             \
    X(Step, "step", 2, 0)                 /* x < edge ? 0 : 1 */                              \
    X(Atan2, "atan2", 2, 0)                                                                    \
    X(Pow, "pow", 2, 0)                                                                        \
    X(Sin, "sin", 1, 0)                                                                        \
    X(Cos, "cos", 1, 0)                                                                        \
    X(Tan, "tan", 1, 0)                                                                        \
    X(Asin, "asin", 1, 0)                                                                      \
    X(Acos, "acos", 1, 0)                                                                      \
    X(Atan, "atan", 1, 0)                                                                      \
    X(Exp, "exp", 1, 0)                                                                        \
    X(Log, "log", 1, 0)                                                                        \
    X(Sqrt, "sqrt", 1, 0)                                                                      \
    X(Abs, "abs", 1, 0)                                                                        \
    X(Sign, "sign", 1, 0)                                                                      \
    X(Floor, "floor", 1, 0)                                                                    \
    X(Ceil, "ceil", 1, 0)                                                                      \
    X(Round, "round", 1, 0)                                                                    \
    X(Fract, "fract", 1, 0)                                                                    \
    /* comparisons and logic: floats compare to bool; == and != on any equal types */         \
    X(Lt, "lt", 2, 0)                                                                          \
    X(Le, "le", 2, 0)                                                                          \
    X(Gt, "gt", 2, 0)                                                                          \
    X(Ge, "ge", 2, 0)                                                                          \
    X(Eq, "eq", 2, kCommutative)                                                               \
    X(Ne, "ne", 2, kCommutative)                                                               \
    X(And, "and", 2, kCommutative)                                                             \
    X(Or, "or", 2, kCommutative)                                                               \
    X(Not, "not", 1, 0)                                                                        \
    X(Select, "select", 3, 0)             /* cond ? a : b */                                  \
    /* vectors */                                                                              \
    X(Splat, "splat", 1, 0)               /* float -> every component */                      \
    X(Compose, "compose", -1, 0)          /* components (floats or vectors) -> vector */      \
    X(Extract, "extract", 1, 0)           /* attr: component */                               \
    X(Shuffle, "shuffle", 1, 0)           /* lanes: components */                             \
    X(Dot, "dot", 2, kCommutative)                                                             \
    /* random numbers: attr is the call site */                                               \
    X(Rand, "rand", -1, kTemporal)        /* in [0, 1); keyed: (object.id, draw.index) */     \
    X(NRand, "nrand", -1, kTemporal)      /* in [-1, 1) */                                    \
    /* the thesis's temporal constructs: only in behaviour kernels, before opt/ lowers them */ \
    X(Integrate, "integrate", 1, kTemporal | kDelays)                                          \
    X(Derive, "derive", 1, kTemporal)                                                          \
    X(Snapshot, "snapshot", 1, kTemporal)                                                      \
    X(Prev, "prev", 1, kTemporal | kDelays)                                                    \
    X(FollowedBy, "fby", 2, kTemporal)    /* init -> next; its second operand is delayed */ \
    X(Recur, "recur", 1, kTemporal | kDelays) /* a reference that closes a cycle: the value of a \
                                                 later equation (resolved by opt/) */

constexpr unsigned kCommutative = 1;
constexpr unsigned kTemporal = 2;  // a call site of its own: never merged by hash-consing
constexpr unsigned kDelays = 4;    // its operand may be defined later (closes a cycle)

enum class Op : uint8_t {
#define PSYS_IR_ENUM(id, text, arity, flags) id,
    PSYS_IR_OPS(PSYS_IR_ENUM)
#undef PSYS_IR_ENUM
};

struct OpInfo {
    std::string_view name;
    int arity;  // -1: any
    unsigned flags;
};

const OpInfo& opInfo(Op op);
std::optional<Op> opFromName(std::string_view name);
inline bool isCommutative(Op op) { return opInfo(op).flags & kCommutative; }
inline bool isTemporal(Op op) { return opInfo(op).flags & kTemporal; }
// An instruction with no operands that reads the kernel's context.
bool isInput(Op op);
// Operand `i` of `op` may refer to a value defined later (a recursive equation).
bool mayReferForward(Op op, size_t operand);

}  // namespace psys::ir
