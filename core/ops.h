// The operations of psys, as one table: for each, its name, its operand count, what kind
// of operation it is and its properties, the built-in function of .psys it is (if it is
// exactly one) and its spelling on each backend where that is a plain mapping. Every
// consumer — the IR's builder, verifier, printer and parser, the passes, the interpreter,
// the backends, the front end's built-ins and constant evaluation — reads this table; no
// property comes from an op's position in the enum. What a pure operation computes is
// core/lanes.h (componentwise arithmetic) and ir/evaluate.cpp (the rest), the random
// draws are core/hash.h.
//
// Adding a componentwise maths function (tanh): its row here, with PSYS_BUILTIN and
// PSYS_MAPS, and its meaning in core/lanes.h; the front end, the interpreter, the JIT and
// the GLSL backend need nothing else. tests/programs/every_operation.psys must use it (a
// test checks that it uses every op), and the backends' differential tests run it.
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
    Lookup,    // reads a table of the run-time's at the place its operand names (the instances')
};

// Properties.
constexpr unsigned kCommutative = 1;    // f(a, b) = f(b, a): operands are put in canonical order
constexpr unsigned kComponentwise = 2;  // lane i of the result is a function of lane i of the
                                        // operands (select: of its branches; the condition is one bool)
constexpr unsigned kOwnSite = 4;        // a call site of its own: never merged with an equal one
constexpr unsigned kJumps = 8;          // a change in an operand's last bits may change the result
                                        // by more than its last bits: comparisons, rounding to whole
                                        // numbers, atan2's cut, and poles and the edges of a domain
                                        // (a division, tan, sqrt, log, pow, asin, acos: sqrt(−0.0…1)
                                        // is NaN where sqrt(0) is 0)

// What an op is in the language and on the backends, where that is a plain mapping.
struct OpSpelling {
    // The built-in function of .psys that is exactly this op, componentwise: its
    // signature ("atan2(y: T, x: T) -> T"; a `T|float` argument broadcasts). Empty: none.
    std::string_view builtin;
    // The C library function core/lanes.h calls ("sinf"): the LLVM backend calls it in
    // exact maths (the interpreter's own result). Empty: the intrinsic, in both modes
    // (operations IEEE 754 defines exactly: sqrt, floor, …).
    std::string_view libm;
    // The LLVM intrinsic ("llvm.sin"): in fast maths, where the vectorizer can map it onto
    // a vector library. Empty: the libm call in both modes.
    std::string_view intrinsic;
    // The GLSL function ("sin"), on vectors as on floats; a `psys_` helper of the shaders'
    // preamble (psys_log: C's answer at the edges, where GLSL's is undefined) is applied
    // lane by lane.
    std::string_view glsl;
    // Whether the backends spell it from this row (else they have code of their own).
    constexpr bool mapped() const { return !glsl.empty() && (!libm.empty() || !intrinsic.empty()); }
};

#define PSYS_NONE ::psys::core::OpSpelling{}
// A built-in function of .psys that is this op, each backend with code of its own.
#define PSYS_BUILTIN(signature) ::psys::core::OpSpelling{signature, {}, {}, {}}
// A built-in that every backend spells from the row.
#define PSYS_MAPS(signature, libm, intrinsic, glsl) ::psys::core::OpSpelling{signature, libm, intrinsic, glsl}

// X(id, text, arity (-1: any), kind, flags, delayed operands (bit i: operand i may refer to
// a value defined later, closing a recursive equation), spelling)
#define PSYS_OPS(X)                                                                                                                                           \
    X(Const, "const", 0, Constant, 0, 0, PSYS_NONE)                                                                                                           \
    X(Param, "param", 0, Input, 0, 0, PSYS_NONE)               /* attr: parameter */                                                                          \
    X(StateRead, "state", 0, Input, 0, 0, PSYS_NONE)           /* attr: slot; its value before this update */                                                 \
    X(Age, "age", 0, Input, 0, 0, PSYS_NONE)                                                                                                                  \
    X(Dt, "dt", 0, Input, 0, 0, PSYS_NONE)                     /* the length of this update */                                                                \
    X(Time, "time", 0, Input, 0, 0, PSYS_NONE)                                                                                                                \
    X(First, "first", 0, Input, 0, 0, PSYS_NONE)               /* true while the object is being created */                                                   \
    X(Extern, "extern", 0, Input, 0, 0, PSYS_NONE)             /* attr: extern */                                                                             \
    X(TriggerParam, "trigger.param", 0, Input, 0, 0, PSYS_NONE)                                                                                               \
    X(ParentRead, "parent.read", 0, Input, 0, 0, PSYS_NONE)    /* attr: index into Object::parentReads */                                                     \
    X(ParentExport, "parent.export", 0, Input, 0, 0, PSYS_NONE) /* attr: export, attr2: levels up */                                                          \
    X(ParentAlive, "parent.alive", 0, Input, 0, 0, PSYS_NONE)  /* attr2: levels up */                                                                         \
    X(ParentAge, "parent.age", 0, Input, 0, 0, PSYS_NONE)      /* attr2: levels up */                                                                         \
    X(ObjectId, "object.id", 0, Input, 0, 0, PSYS_NONE)        /* u32: this object's id */                                                                    \
    X(DrawIndex, "draw.index", 0, Input, 0, 0, PSYS_NONE)      /* u32: which draw of every random site */                                                     \
    X(Uniform, "uniform", 0, Input, 0, 0, PSYS_NONE)           /* attr: a value of the uniform kernel */                                                      \
    X(NeighbourRead, "neighbour.read", 0, Input, 0, 0, PSYS_NONE) /* pair kernels: attr: index into Object::neighbourReads */                                 \
    X(NeighbourExport, "neighbour.export", 0, Input, 0, 0, PSYS_NONE) /* pair kernels: attr: export; attr2: 0 this object, 1 the other */                     \
    X(Fold, "fold", 0, Input, 0, 0, PSYS_NONE)                 /* attr: fold (Object::folds): over the neighbours, this step */                               \
    X(Instance, "instance", 1, Lookup, 0, 0, PSYS_NONE)        /* operand: the instance (f32); attr: value k of its record; attr2: where the table starts among the externs (core/instances.h) */ \
    X(Add, "add", 2, Pure, kCommutative | kComponentwise, 0, PSYS_NONE)                                                                                       \
    X(Sub, "sub", 2, Pure, kComponentwise, 0, PSYS_NONE)                                                                                                      \
    X(Mul, "mul", 2, Pure, kCommutative | kComponentwise, 0, PSYS_NONE)                                                                                       \
    X(Div, "div", 2, Pure, kComponentwise | kJumps, 0, PSYS_NONE)                                                                                             \
    X(Mod, "mod", 2, Pure, kComponentwise | kJumps, 0, PSYS_BUILTIN("mod(x: T, y: T|float) -> T"))                                                            \
    X(Neg, "neg", 1, Pure, kComponentwise, 0, PSYS_NONE)                                                                                                      \
    X(Min, "min", 2, Pure, kCommutative | kComponentwise, 0, PSYS_BUILTIN("min(a: T, b: T|float) -> T"))                                                      \
    X(Max, "max", 2, Pure, kCommutative | kComponentwise, 0, PSYS_BUILTIN("max(a: T, b: T|float) -> T"))                                                      \
    X(Step, "step", 2, Pure, kComponentwise | kJumps, 0, PSYS_BUILTIN("step(edge: T|float, x: T) -> T"))     /* x < edge ? 0 : 1 */                           \
    X(Atan2, "atan2", 2, Pure, kComponentwise | kJumps, 0, PSYS_MAPS("atan2(y: T, x: T) -> T", "atan2f", "", "psys_atan2"))                                   \
    X(Pow, "pow", 2, Pure, kComponentwise | kJumps, 0, PSYS_MAPS("pow(x: T, y: T|float) -> T", "powf", "llvm.pow", "psys_pow"))                               \
    X(Sin, "sin", 1, Pure, kComponentwise, 0, PSYS_MAPS("sin(x: T) -> T", "sinf", "llvm.sin", "sin"))                                                         \
    X(Cos, "cos", 1, Pure, kComponentwise, 0, PSYS_MAPS("cos(x: T) -> T", "cosf", "llvm.cos", "cos"))                                                         \
    X(Tan, "tan", 1, Pure, kComponentwise | kJumps, 0, PSYS_MAPS("tan(x: T) -> T", "tanf", "llvm.tan", "tan"))                                                \
    X(Asin, "asin", 1, Pure, kComponentwise | kJumps, 0, PSYS_MAPS("asin(x: T) -> T", "asinf", "llvm.asin", "psys_asin"))                                     \
    X(Acos, "acos", 1, Pure, kComponentwise | kJumps, 0, PSYS_MAPS("acos(x: T) -> T", "acosf", "llvm.acos", "psys_acos"))                                     \
    X(Atan, "atan", 1, Pure, kComponentwise, 0, PSYS_MAPS("atan(x: T) -> T", "atanf", "llvm.atan", "atan"))                                                   \
    X(Tanh, "tanh", 1, Pure, kComponentwise, 0, PSYS_MAPS("tanh(x: T) -> T", "tanhf", "llvm.tanh", "tanh"))                                                   \
    X(Exp, "exp", 1, Pure, kComponentwise, 0, PSYS_MAPS("exp(x: T) -> T", "expf", "llvm.exp", "exp"))                                                         \
    X(Log, "log", 1, Pure, kComponentwise | kJumps, 0, PSYS_MAPS("log(x: T) -> T", "logf", "llvm.log", "psys_log"))                                           \
    X(Sqrt, "sqrt", 1, Pure, kComponentwise | kJumps, 0, PSYS_MAPS("sqrt(x: T) -> T", "", "llvm.sqrt", "psys_sqrt"))                                          \
    X(Abs, "abs", 1, Pure, kComponentwise, 0, PSYS_MAPS("abs(x: T) -> T", "", "llvm.fabs", "abs"))                                                            \
    X(Sign, "sign", 1, Pure, kComponentwise | kJumps, 0, PSYS_BUILTIN("sign(x: T) -> T"))                                                                     \
    X(Floor, "floor", 1, Pure, kComponentwise | kJumps, 0, PSYS_MAPS("floor(x: T) -> T", "", "llvm.floor", "floor"))                                          \
    X(Ceil, "ceil", 1, Pure, kComponentwise | kJumps, 0, PSYS_MAPS("ceil(x: T) -> T", "", "llvm.ceil", "ceil"))                                               \
    X(Round, "round", 1, Pure, kComponentwise | kJumps, 0, PSYS_MAPS("round(x: T) -> T", "", "llvm.nearbyint", "roundEven"))   /* to nearest, ties to even */ \
    X(Fract, "fract", 1, Pure, kComponentwise | kJumps, 0, PSYS_BUILTIN("fract(x: T) -> T"))                                                                  \
    X(Lt, "lt", 2, Pure, kJumps, 0, PSYS_NONE)                      /* floats → bool */                                                                       \
    X(Le, "le", 2, Pure, kJumps, 0, PSYS_NONE)                                                                                                                \
    X(Gt, "gt", 2, Pure, kJumps, 0, PSYS_NONE)                                                                                                                \
    X(Ge, "ge", 2, Pure, kJumps, 0, PSYS_NONE)                                                                                                                \
    X(Eq, "eq", 2, Pure, kCommutative | kJumps, 0, PSYS_NONE)           /* any two values of one type → bool */                                               \
    X(Ne, "ne", 2, Pure, kCommutative | kJumps, 0, PSYS_NONE)                                                                                                 \
    X(And, "and", 2, Pure, kCommutative, 0, PSYS_NONE)                                                                                                        \
    X(Or, "or", 2, Pure, kCommutative, 0, PSYS_NONE)                                                                                                          \
    X(Not, "not", 1, Pure, 0, 0, PSYS_NONE)                                                                                                                   \
    X(Select, "select", 3, Pure, kComponentwise, 0, PSYS_NONE) /* cond ? a : b */                                                                             \
    X(Splat, "splat", 1, Pure, 0, 0, PSYS_NONE)                /* float → every component */                                                                  \
    X(Compose, "compose", -1, Pure, 0, 0, PSYS_NONE)           /* components (floats or vectors) → vector */                                                  \
    X(Extract, "extract", 1, Pure, 0, 0, PSYS_NONE)            /* attr: component */                                                                          \
    X(Shuffle, "shuffle", 1, Pure, 0, 0, PSYS_NONE)            /* lanes: components */                                                                        \
    X(Dot, "dot", 2, Pure, kCommutative, 0, PSYS_NONE)                                                                                                        \
    X(Hash, "hash", 1, Pure, kJumps, 0, PSYS_BUILTIN("hash(x: T) -> T")) /* a lattice point's random lanes in [-1, 1): core/hash.h */                         \
    X(Rand, "rand", -1, Random, kOwnSite, 0, PSYS_NONE)        /* in [0, 1); keyed: (object.id, draw.index) */                                                \
    X(NRand, "nrand", -1, Random, kOwnSite, 0, PSYS_NONE)      /* in [-1, 1) */                                                                               \
    X(Integrate, "integrate", 1, Temporal, kOwnSite, 1, PSYS_NONE)                                                                                            \
    X(Derive, "derive", 1, Temporal, kOwnSite, 0, PSYS_NONE)                                                                                                  \
    X(Snapshot, "snapshot", 1, Temporal, kOwnSite, 0, PSYS_NONE)                                                                                              \
    X(Prev, "prev", 1, Temporal, kOwnSite, 1, PSYS_NONE)                                                                                                      \
    X(FollowedBy, "fby", 2, Temporal, kOwnSite, 2, PSYS_NONE)  /* init -> next: the next side is delayed */                                                   \
    X(Recur, "recur", 1, Temporal, kOwnSite, 1, PSYS_NONE)     /* closes a cycle: the value of a later                                                        \
                                                       equation (resolved by opt/) */

enum class Op : uint8_t {
#define PSYS_OP_ENUM(id, text, arity, kind, flags, delayed, spelling) id,
    PSYS_OPS(PSYS_OP_ENUM)
#undef PSYS_OP_ENUM
};
#define PSYS_OP_COUNT(id, text, arity, kind, flags, delayed, spelling) +1
constexpr size_t kOpCount = 0 PSYS_OPS(PSYS_OP_COUNT);
#undef PSYS_OP_COUNT

struct OpInfo {
    std::string_view name;
    int arity;  // -1: any
    OpKind kind;
    unsigned flags;
    unsigned delayedOperands;
    OpSpelling spelling;
};

const OpInfo& opInfo(Op op);
std::optional<Op> opFromName(std::string_view name);

inline OpKind kindOf(Op op) { return opInfo(op).kind; }
inline bool isConstant(Op op) { return kindOf(op) == OpKind::Constant; }
inline bool isInput(Op op) { return kindOf(op) == OpKind::Input; }
// Constants and inputs: the instructions without operands.
inline bool isLeaf(Op op) { return isConstant(op) || isInput(op); }
inline bool isPure(Op op) { return kindOf(op) == OpKind::Pure; }
inline bool jumps(Op op) { return (opInfo(op).flags & kJumps) != 0; }
inline bool isRandom(Op op) { return kindOf(op) == OpKind::Random; }
inline bool isTemporal(Op op) { return kindOf(op) == OpKind::Temporal; }
inline bool isLookup(Op op) { return kindOf(op) == OpKind::Lookup; }
inline bool isCommutative(Op op) { return opInfo(op).flags & kCommutative; }
inline bool isComponentwise(Op op) { return opInfo(op).flags & kComponentwise; }
inline bool hasOwnSite(Op op) { return opInfo(op).flags & kOwnSite; }
// The inputs that read an ancestor object (its exports, whether it is alive, its age).
inline bool readsAncestor(Op op) { return op == Op::ParentExport || op == Op::ParentAlive || op == Op::ParentAge; }
// The inputs the run-time gathers into columns before a kernel runs: the ancestor reads
// and the neighbour folds (KernelStorage::parents, in instruction order).
inline bool isGathered(Op op) { return readsAncestor(op) || op == Op::Fold; }
// Operand `i` of `op` may refer to a value defined later (a recursive equation).
inline bool mayReferForward(Op op, size_t operand) {
    return operand < 8 && (opInfo(op).delayedOperands >> operand & 1u);
}

}  // namespace psys::core
