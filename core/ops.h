// The operations of psys, as one table: for each, its name, its operand count, what kind
// of operation it is and its properties. Every consumer — the IR's builder, verifier,
// printer and parser, the passes, the interpreter, the backends and the front end's
// constant evaluation — reads this table; no property comes from an op's position in the
// enum. What a pure operation computes is core/lanes.h (componentwise arithmetic) and
// ir/evaluate.cpp (the rest), the random draws are core/hash.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace psys::core {

// What kind of thing an operation is.
enum class OpKind : uint8_t {
    Constant,  // a literal value (no operands)
    Input,     // reads the kernel's context: attr (and attr2) say which; no operands
    Pure,      // a function of its operands only
    Random,    // a counter-based random draw; attr is its call site
    Temporal,  // the thesis's constructs over an object's history (lowered by opt/)
};

// Properties.
constexpr unsigned kCommutative = 1;    // f(a, b) = f(b, a): operands are put in canonical order
constexpr unsigned kComponentwise = 2;  // lane i of the result is a function of lane i of the
                                        // operands (select: of its branches; the condition is one bool)
constexpr unsigned kOwnSite = 4;        // a call site of its own: never merged with an equal one

// X(id, text, arity (-1: any), kind, flags, delayed operands (bit i: operand i may refer to
// a value defined later, closing a recursive equation))
#define PSYS_OPS(X)                                                                               \
    X(Const, "const", 0, Constant, 0, 0)                                                         \
    X(Param, "param", 0, Input, 0, 0)               /* attr: parameter */                         \
    X(StateRead, "state", 0, Input, 0, 0)           /* attr: slot; its value before this update */\
    X(Age, "age", 0, Input, 0, 0)                                                                 \
    X(Dt, "dt", 0, Input, 0, 0)                     /* the length of this update */               \
    X(Time, "time", 0, Input, 0, 0)                                                               \
    X(First, "first", 0, Input, 0, 0)               /* true while the object is being created */  \
    X(Extern, "extern", 0, Input, 0, 0)             /* attr: extern */                            \
    X(TriggerParam, "trigger.param", 0, Input, 0, 0)                                              \
    X(ParentRead, "parent.read", 0, Input, 0, 0)    /* attr: index into Object::parentReads */    \
    X(ParentExport, "parent.export", 0, Input, 0, 0) /* attr: export, attr2: levels up */         \
    X(ParentAlive, "parent.alive", 0, Input, 0, 0)  /* attr2: levels up */                        \
    X(ParentAge, "parent.age", 0, Input, 0, 0)      /* attr2: levels up */                        \
    X(ObjectId, "object.id", 0, Input, 0, 0)        /* u32: this object's id */                   \
    X(DrawIndex, "draw.index", 0, Input, 0, 0)      /* u32: which draw of every random site */    \
    X(Uniform, "uniform", 0, Input, 0, 0)           /* attr: a value of the uniform kernel */     \
    X(Add, "add", 2, Pure, kCommutative | kComponentwise, 0)                                      \
    X(Sub, "sub", 2, Pure, kComponentwise, 0)                                                     \
    X(Mul, "mul", 2, Pure, kCommutative | kComponentwise, 0)                                      \
    X(Div, "div", 2, Pure, kComponentwise, 0)                                                     \
    X(Mod, "mod", 2, Pure, kComponentwise, 0)                                                     \
    X(Neg, "neg", 1, Pure, kComponentwise, 0)                                                     \
    X(Min, "min", 2, Pure, kCommutative | kComponentwise, 0)                                      \
    X(Max, "max", 2, Pure, kCommutative | kComponentwise, 0)                                      \
    X(Step, "step", 2, Pure, kComponentwise, 0)     /* x < edge ? 0 : 1 */                        \
    X(Atan2, "atan2", 2, Pure, kComponentwise, 0)                                                 \
    X(Pow, "pow", 2, Pure, kComponentwise, 0)                                                     \
    X(Sin, "sin", 1, Pure, kComponentwise, 0)                                                     \
    X(Cos, "cos", 1, Pure, kComponentwise, 0)                                                     \
    X(Tan, "tan", 1, Pure, kComponentwise, 0)                                                     \
    X(Asin, "asin", 1, Pure, kComponentwise, 0)                                                   \
    X(Acos, "acos", 1, Pure, kComponentwise, 0)                                                   \
    X(Atan, "atan", 1, Pure, kComponentwise, 0)                                                   \
    X(Exp, "exp", 1, Pure, kComponentwise, 0)                                                     \
    X(Log, "log", 1, Pure, kComponentwise, 0)                                                     \
    X(Sqrt, "sqrt", 1, Pure, kComponentwise, 0)                                                   \
    X(Abs, "abs", 1, Pure, kComponentwise, 0)                                                     \
    X(Sign, "sign", 1, Pure, kComponentwise, 0)                                                   \
    X(Floor, "floor", 1, Pure, kComponentwise, 0)                                                 \
    X(Ceil, "ceil", 1, Pure, kComponentwise, 0)                                                   \
    X(Round, "round", 1, Pure, kComponentwise, 0)   /* to nearest, ties to even */                \
    X(Fract, "fract", 1, Pure, kComponentwise, 0)                                                 \
    X(Lt, "lt", 2, Pure, 0, 0)                      /* floats → bool */                           \
    X(Le, "le", 2, Pure, 0, 0)                                                                    \
    X(Gt, "gt", 2, Pure, 0, 0)                                                                    \
    X(Ge, "ge", 2, Pure, 0, 0)                                                                    \
    X(Eq, "eq", 2, Pure, kCommutative, 0)           /* any two values of one type → bool */       \
    X(Ne, "ne", 2, Pure, kCommutative, 0)                                                         \
    X(And, "and", 2, Pure, kCommutative, 0)                                                       \
    X(Or, "or", 2, Pure, kCommutative, 0)                                                         \
    X(Not, "not", 1, Pure, 0, 0)                                                                  \
    X(Select, "select", 3, Pure, kComponentwise, 0) /* cond ? a : b */                            \
    X(Splat, "splat", 1, Pure, 0, 0)                /* float → every component */                 \
    X(Compose, "compose", -1, Pure, 0, 0)           /* components (floats or vectors) → vector */ \
    X(Extract, "extract", 1, Pure, 0, 0)            /* attr: component */                         \
    X(Shuffle, "shuffle", 1, Pure, 0, 0)            /* lanes: components */                       \
    X(Dot, "dot", 2, Pure, kCommutative, 0)                                                       \
    X(Rand, "rand", -1, Random, kOwnSite, 0)        /* in [0, 1); keyed: (object.id, draw.index) */ \
    X(NRand, "nrand", -1, Random, kOwnSite, 0)      /* in [-1, 1) */                              \
    X(Integrate, "integrate", 1, Temporal, kOwnSite, 1)                                           \
    X(Derive, "derive", 1, Temporal, kOwnSite, 0)                                                 \
    X(Snapshot, "snapshot", 1, Temporal, kOwnSite, 0)                                             \
    X(Prev, "prev", 1, Temporal, kOwnSite, 1)                                                     \
    X(FollowedBy, "fby", 2, Temporal, kOwnSite, 2)  /* init -> next: the next side is delayed */  \
    X(Recur, "recur", 1, Temporal, kOwnSite, 1)     /* closes a cycle: the value of a later      \
                                                       equation (resolved by opt/) */

enum class Op : uint8_t {
#define PSYS_OP_ENUM(id, text, arity, kind, flags, delayed) id,
    PSYS_OPS(PSYS_OP_ENUM)
#undef PSYS_OP_ENUM
};

struct OpInfo {
    std::string_view name;
    int arity;  // -1: any
    OpKind kind;
    unsigned flags;
    unsigned delayedOperands;
};

const OpInfo& opInfo(Op op);
std::optional<Op> opFromName(std::string_view name);

inline OpKind kindOf(Op op) { return opInfo(op).kind; }
inline bool isConstant(Op op) { return kindOf(op) == OpKind::Constant; }
inline bool isInput(Op op) { return kindOf(op) == OpKind::Input; }
// Constants and inputs: the instructions without operands.
inline bool isLeaf(Op op) { return isConstant(op) || isInput(op); }
inline bool isPure(Op op) { return kindOf(op) == OpKind::Pure; }
inline bool isRandom(Op op) { return kindOf(op) == OpKind::Random; }
inline bool isTemporal(Op op) { return kindOf(op) == OpKind::Temporal; }
inline bool isCommutative(Op op) { return opInfo(op).flags & kCommutative; }
inline bool isComponentwise(Op op) { return opInfo(op).flags & kComponentwise; }
inline bool hasOwnSite(Op op) { return opInfo(op).flags & kOwnSite; }
// The inputs that read an ancestor object (its exports, whether it is alive, its age).
inline bool readsAncestor(Op op) { return op == Op::ParentExport || op == Op::ParentAlive || op == Op::ParentAge; }
// Operand `i` of `op` may refer to a value defined later (a recursive equation).
inline bool mayReferForward(Op op, size_t operand) {
    return operand < 8 && (opInfo(op).delayedOperands >> operand & 1u);
}

}  // namespace psys::core
