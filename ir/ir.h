// The psys IR: typed SSA kernels, one set per object type.
//
// A Kernel is a straight-line list of instructions (conditionals are `select`; the loop
// over particles belongs to each backend) and a list of yields: what the kernel produces
// (next state, kill flag, point, emission rates, spawn arguments, …). Instructions are
// hash-consed: building an instruction equal to an existing one returns the existing
// value, and commutative operands are put in canonical order first, so `a*b` and `b*a`
// meet. That is value numbering for free.
//
// Right after lowering, an object has a single `behaviour` kernel that still holds the
// thesis's temporal constructs (integrate, derive, snapshot, prev, `->`, rand, parent
// reads) and may refer forward through them (recursive equations). The passes in opt/
// turn those into explicit state, keyed random numbers and parent exports, and split the
// behaviour into `init`, `update` and the post-update kernels `render`, `exports` and one
// `spawn.N` per emit site. See ir/ops.h for the instruction set and docs/ir.md for the
// text form.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "core/draw.h"
#include "core/fold.h"
#include "core/instances.h"
#include "core/integrators.h"
#include "ir/ops.h"
#include "ir/types.h"

namespace psys::ir {

using ValueId = uint32_t;

// Where an instruction came from in the source: a file of Module::files, a line and a
// column (1-based) and the length of the range on that line. Every instruction is built
// with one (a pass gives what it builds the location of what it replaces), so a pass can
// report an error or a warning at the equation it concerns.
struct Loc {
    int32_t file = -1;  // -1: unknown
    uint32_t line = 0, column = 0, length = 0;
    bool valid() const { return file >= 0; }
    bool operator==(const Loc&) const = default;
};

struct Inst {
    Op op = Op::Const;
    Type type;
    std::vector<ValueId> operands;
    int32_t attr = 0;                 // slot / param / extern / export / site / component index
    int32_t attr2 = 0;                // parent reads: how many levels up
    std::array<float, 4> constant{};  // Const: components (bool: 0 or 1)
    std::vector<uint8_t> lanes;       // Shuffle: component indices
    std::string name;                 // for reading only: the equation it came from
    Loc loc;                          // not part of its identity: equal instructions merge

    bool sameAs(const Inst& other) const;  // equal but for the name and location

    // An instruction from its parts; built into a kernel it gets the builder's location.
    static Inst make(Op op, Type type, std::vector<ValueId> operands = {}, int32_t attr = 0, int32_t attr2 = 0) {
        Inst inst;
        inst.op = op;
        inst.type = type;
        inst.operands = std::move(operands);
        inst.attr = attr;
        inst.attr2 = attr2;
        return inst;
    }
};

enum class YieldKind {
    StateNext,  // index: state slot
    Kill,
    Visible,    // render: whether the point is drawn
    Position,
    Color,
    Size,       // a point's pixels, a sprite's size, a streak's width
    Rotation,   // a sprite's turn, in radians (0 where the command gives none)
    Frame,      // a sprite's frame of a flip-book (0 where the command gives none)
    End,        // a streak's other end (0 for the others)
    Trail,      // index k: a trail's point k + 1 updates back (its head is the position)
    EmitRate,   // index: emit site; objects per second (rate emitters)
    EmitCount,  // index: emit site; objects per event (rate emitters) or in all (bursts)
    EmitArg,    // index: emit site, sub: argument
    Export,     // index: export (a value children read live)
    Uniform,    // index: a value of a uniform kernel, the same for every object of the type
    Fold,       // pair kernels, index: fold (Object::folds): this neighbour's term
    Unstable,   // update: whether this step is beyond the integration method's stability
                // limit for a decay rate the compiler found (counted per type in the stats)
};

struct Yield {
    YieldKind kind;
    int index = 0;
    int sub = 0;
    ValueId value = 0;
};

enum class KernelKind {
    Behaviour, Init, Update, Render, Exports, Spawn, Trigger, Start,
    // Once per pair of an object and a neighbour within a group's radius (site: the
    // group, Object::neighbours): each fold's term, from both objects' exports.
    Pair,
    // Once per step (and per distinct dt, time and externs) for a whole type: what the
    // kernel it serves computes identically for every object (opt/hoist_uniform).
    UniformUpdate, UniformRender, UniformExports,
};
// The uniform kernel serving `kind`, if it can have one.
std::optional<KernelKind> uniformFor(KernelKind kind);

// What the run-time stores for a kernel beyond its object's declared columns (state,
// parameters, exports), fixed by the last pass (opt/lower_storage.cpp) from the kernel's
// values: rt::columnLayout turns it into column positions, and neither the run-time nor a
// backend reads the instructions for it. Printed with the kernel as `storage` lines.
struct KernelStorage {
    bool fixed = false;  // lower-storage has run (a bare `storage` line)
    // Per emit column — site s's rate at 2s, its count at 2s + 1 — a value every row of a
    // launch at a uniform clock shares (a constant, an extern, a value of the uniform
    // kernel), or none (its column).
    struct Shared {
        enum class From : uint8_t { Column, Constant, Extern, Uniform } from = From::Column;
        int index = 0;    // Extern: the extern; Uniform: the uniform kernel's value
        float value = 0;  // Constant
    };
    std::vector<Shared> emits;
    // Render kernels, per render column (visible; position x y z; colour r g b a; size):
    // drawn from the kernel's own column, from a lane of a state slot as it is, or a
    // constant every row draws alike.
    struct Drawn {
        enum class From : uint8_t { Column, State, Constant } from = From::Column;
        int slot = 0, lane = 0;  // State
        float value = 0;         // Constant
    };
    std::vector<Drawn> drawn;
    // The parent reads, in instruction order: the run-time gathers each into columns.
    struct ParentRead {
        Op op;
        int depth;        // levels up
        int exportIndex;  // parent.export: which export; else -1
        int width;
    };
    std::vector<ParentRead> parents;
    // Init kernels: the state slots a new object's row must hold zero before it runs —
    // those it does not set, or every one where it reads state.
    std::vector<int> zeroed;
};

// The render columns as the IR's text names them (`position.y`, `size`, `end.z`, 0 … 13;
// past them a trail's points, `trail.1.x` … : point k + 1 back at 14 + 3k).
std::string drawnColumnName(int column);
constexpr int kDrawnColumns = 14;
// The first render column of a drawn yield: visible 0, position 1, colour 4, size 8,
// rotation 9, frame 10, end 11, trail point k 14 + 3k (the one definition: the storage
// pass records by it, the run-time lays columns out by it).
constexpr int drawnColumn(YieldKind kind, int index = 0) {
    switch (kind) {
        case YieldKind::Position: return 1;
        case YieldKind::Color: return 4;
        case YieldKind::Size: return 8;
        case YieldKind::Rotation: return 9;
        case YieldKind::Frame: return 10;
        case YieldKind::End: return 11;
        case YieldKind::Trail: return kDrawnColumns + 3 * index;
        default: return 0;
    }
}
// The render yields: what a render kernel computes for the drawing.
constexpr bool isDrawnYield(YieldKind kind) {
    return kind == YieldKind::Visible || kind == YieldKind::Position || kind == YieldKind::Color ||
           kind == YieldKind::Size || kind == YieldKind::Rotation || kind == YieldKind::Frame ||
           kind == YieldKind::End || kind == YieldKind::Trail;
}
// The drawn values beyond a point's (rotation, frame, end), where a render kernel yields
// none of them: 0, a constant with no column.
constexpr bool drawnDefaultsToZero(int column) { return column >= 9 && column < kDrawnColumns; }

class Kernel;
// A render kernel's storage record (fixed): the drawn columns past a point's that it
// yields nothing for are the constant 0 (the storage pass and the IR's parser both apply
// it; the printer leaves those lines out).
void defaultDrawn(Kernel& render);

class Kernel {
public:
    KernelKind kind = KernelKind::Behaviour;
    int site = -1;  // Spawn: the emit site it computes the arguments of; Pair: the group

    const std::vector<Inst>& insts() const { return insts_; }
    const Inst& at(ValueId v) const { return insts_.at(v); }
    Inst& mutableAt(ValueId v) { return insts_.at(v); }
    size_t size() const { return insts_.size(); }

    std::vector<Yield> yields;
    KernelStorage storage;
    // The values of the object's equations (and parameters) by name, for passes that look
    // them up (scoping) and for people reading the IR. Printed as `let name = %v`.
    std::map<std::string, ValueId> equations;

    // Adds `inst` unless an equal one exists (hash-consing); returns its value.
    // Operands of commutative ops are sorted first. Temporal ops and random draws are
    // never merged: each is its own call site. An instruction without a location gets the
    // builder's (setLoc).
    ValueId add(Inst inst);
    // Appends without merging, for operands not known yet (recursive equations).
    ValueId addUnique(Inst inst);
    // Convenience builders.
    ValueId constant(Type type, std::array<float, 4> value);
    ValueId scalar(float value) { return constant(Type::f32(), {value, 0, 0, 0}); }
    ValueId boolean(bool value) { return constant(Type::boolean(), {value ? 1.0f : 0.0f, 0, 0, 0}); }
    ValueId op(Op op, Type type, std::vector<ValueId> operands, int32_t attr = 0);

    // Yields of one kind (and index), in order.
    std::vector<const Yield*> find(YieldKind kind, int index = -1) const;
    const Yield* findOne(YieldKind kind, int index = 0, int sub = 0) const;

    // Rebuilds the hash-consing table after instructions were edited in place.
    void rehash();

    // The location given to instructions built without one (LocScope sets it for a scope).
    void setLoc(Loc loc) { loc_ = loc; }
    Loc loc() const { return loc_; }

private:
    std::vector<Inst> insts_;
    std::unordered_map<std::string, ValueId> table_;
    Loc loc_;
};

// Builds with `loc` until the end of the scope, then with what was there before.
class LocScope {
public:
    LocScope(Kernel& k, Loc loc) : k_(k), saved_(k.loc()) { k.setLoc(loc); }
    ~LocScope() { k_.setLoc(saved_); }
    LocScope(const LocScope&) = delete;
    LocScope& operator=(const LocScope&) = delete;

private:
    Kernel& k_;
    Loc saved_;
};

// ---------------------------------------------------------------- objects

struct Param {
    std::string name;
    Type type;
    bool kept = true;  // false: read only at creation, so the pool does not store it
    // Its type as declared where that says more (`color`, `point`): a trigger's, for hosts.
    std::string spelling = std::string();
};

enum class StateInit {
    Zero,  // the slot starts at zero (an integral at creation)
    Next,  // the slot starts at its next-value evaluated when the object is created
};

struct StateSlot {
    std::string name;
    Type type;
    StateInit init = StateInit::Next;
};

struct EmitSite {
    // When the site creates objects (docs/language.md, "Emitting").
    enum class When : uint8_t {
        Creation,  // `emit X count N` outside a `when`: N when the emitter is created
        Rate,      // `emit X at R per second`: R a second, in every update
        Edge,      // `emit X count N` in a `when`: N at creation if the condition holds then,
                   // and N in each update where it becomes true (false before)
        Death,     // in `on death`: N in the update that kills the emitter
    };
    std::string target;  // the created object type
    When when = When::Creation;

    bool rate() const { return when == When::Rate; }
    // Its count (or rate) is the init kernel's: it creates as the emitter is created.
    bool atCreation() const { return when == When::Creation || when == When::Edge; }
    // Its count (or rate) is the update kernel's: it creates as the emitter is updated.
    bool inUpdate() const { return when != When::Creation; }
    // It creates in the update that kills the emitter (a rate emitter does not).
    bool whenKilled() const { return when == When::Edge || when == When::Death; }
};
// Its name in the IR's text (`rate`, `burst`, `edge`, `death`) and back.
std::string_view emitWhenName(EmitSite::When when);
std::optional<EmitSite::When> emitWhenFromName(std::string_view name);

struct Export {
    std::string name;  // the parent's equation (or parameter) children read
    Type type;
};

// `rocket.pos` in a nested object, before scoping turns it into a parent export.
struct ParentRead {
    int depth = 1;        // 1: the enclosing object, 2: its parent, …
    std::string member;   // the equation or parameter read
    Type type;
};

using core::Integrator;

// `near_sum(boid, 2, other.vel)`: folds over the objects of a type within a radius of this
// one (docs/language.md, "Neighbours"). The folds over one type and radius share a group:
// one walk over the grid, one pair kernel yielding each fold's term.
struct NeighbourGroup {
    std::string target;  // the type folded over
    float radius = 0;
    // The exports holding the drawn positions: this object's and the target's (-1 until
    // scoping makes them).
    int selfPosition = -1, otherPosition = -1;
};
using core::Reduce;
struct Fold {
    int group = 0;
    Reduce reduce = Reduce::Sum;
    Type type;
};
// A member a pair kernel reads, before scoping makes it an export: this object's or the
// other's.
struct NeighbourRead {
    bool other = false;
    std::string member;
    Type type;
};

using core::Precision;
using core::precisionName;
using core::precisionFromName;

// An object's @attributes (the object's own, else the file's, else none).
struct Attributes {
    std::optional<Integrator> integrator;  // none: the pipeline's default
    Loc integratorLoc;
    float step = 0;                        // @step: the longest update, in seconds; 0: none
    // @tolerance: the largest position error accepted (metres; 0: none) over `over`
    // seconds (0: the default time); the chooser (tune/) turns it into integrator and step.
    float tolerance = 0, toleranceOver = 0;
    Precision precision = Precision::Float;  // @precision
    std::optional<uint64_t> capacity;      // @capacity: most objects alive at once
    std::optional<core::Shape> shape;      // @shape: a sprite's (none: soft)
    std::optional<core::Blend> blend;      // @blend (none: core::defaultBlend)
    // @texture: a sprite's image, the file's path as the program's directory resolves it
    // (empty: none), cut into columns × rows frames (a flip-book)
    std::string texture;
    int textureColumns = 1, textureRows = 1;
    bool operator==(const Attributes&) const = default;
};

struct Object {
    std::string name;
    Loc loc;             // its declaration
    std::string parent;  // the enclosing object type; empty at file level
    core::DrawKind draw = core::DrawKind::Point;  // its render command (core/draw.h)
    int trail = 0;  // a trail's points (its head and trail - 1 behind); 0 for the others
    std::vector<Param> params;
    std::vector<StateSlot> state;
    std::vector<EmitSite> emits;
    std::vector<Export> exports;
    std::vector<ParentRead> parentReads;
    std::vector<NeighbourGroup> neighbours;
    std::vector<Fold> folds;
    std::vector<NeighbourRead> neighbourReads;  // cleared by scoping
    Attributes attributes;
    std::vector<Kernel> kernels;

    const Kernel* kernel(KernelKind kind, int site = -1) const;
    Kernel* kernel(KernelKind kind, int site = -1);
};

// The render columns of an object's tables: a point's 14, and 3 per point of a trail
// behind its head.
inline int renderColumns(const Object& o) { return kDrawnColumns + 3 * std::max(o.trail - 1, 0); }

// The object type an event makes (`notify "hit"(…)`: docs/language.md, "Events"): one
// object a notification, living until the end of the next step's update, its values its
// parameters. `notify` is a keyword, so no type of a program is named so.
inline std::string eventType(std::string_view event) { return "notify." + std::string(event); }
inline bool isEventType(std::string_view type) { return type.starts_with("notify."); }

struct Extern {
    std::string name;
    Type type;
    std::string spelling;  // its type as declared where that says more (`color`, `point`): for hosts' controls
    std::array<float, 4> defaultValue{};
    std::optional<std::array<float, 4>> low, high;
};

// `trigger NAME(params) { emits }` and the start of the system (`spawn …`) are kernels
// with emit yields, run once when fired.
struct Trigger {
    std::string name;
    std::vector<Param> params;
    std::vector<EmitSite> emits;
    Kernel kernel;
    // The parameters a host gives: all but an instanced program's hidden `instance`, which
    // the run-time fills in (core/instances.h).
    std::span<const Param> hostParams() const {
        size_t n = params.size();
        if (n > 0 && params.back().name == core::kInstanceParam) --n;
        return {params.data(), n};
    }
};

struct Module {
    std::vector<std::string> files;  // the source files locations refer to
    std::vector<Extern> externs;
    std::vector<Object> objects;  // parents before children
    std::vector<Trigger> triggers;
    Trigger start;                // the `spawn`s: emits at time 0

    const Object* object(const std::string& name) const;
    int objectIndex(const std::string& name) const;
    // Whether it is played as instances (core/instances.h): every object, trigger and the
    // start then have the hidden parameter `instance`, last.
    bool instanced() const { return !start.params.empty(); }
    int externIndex(const std::string& name) const;
};

const char* kernelName(KernelKind kind);

// What every backend says, the same way, of an instruction it has no code for (it then
// throws it): "internal error: the GLSL backend has no code for `recur` (the instruction
// from line 4, column 9)". An op the table spells for it never gets here.
std::string unexpectedOp(const Inst& inst, std::string_view backend);

}  // namespace psys::ir
