// The column table of a launch: where each column a kernel reads or writes sits, fixed by
// the object's types and the kernel's storage record alone (ir::KernelStorage, which the
// compiler's lower-storage pass fixes: no IR pattern is read here), so a backend can
// compile a kernel's loop once and run it on any pool (or creation scratch) of that
// object type.
//
//   created  f64 per row: the creation time (age = ageAt(now, created), rt/clock.h)
//   ids      u32 per row
//   kill     u8 per row, written (0 or 1) for every row of the range by kernels that kill
//   now, dt  f64 and f32 per row, read when the launch's clock says PerRow
//   state, params, exports: one f32 column per component, in declaration order; a
//     parameter the pool does not keep has no column (an invalid buffer)
//   emits    per emit site, a rate and a count column (f32), written for every row
//   render   visible (0 or 1), position x y z, colour r g b a, size, rotation, frame,
//     end x y z, then a trail's points behind its head (x y z each): f32, written for
//     every row by render kernels (but those drawn from a state column or constant)
//   parents  per parent read of the kernel, in instruction order, one f32 column per
//     component (gathered by the run-time; `alive` is 0 or 1)
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ir/ir.h"
#include "ir/value.h"

namespace psys::rt {

struct ColumnLayout {
    static constexpr int kCreated = 0, kIds = 1, kKill = 2, kNow = 3, kDt = 4, kFirstColumn = 5;
    int state = 0, params = 0, exports = 0, emits = 0, render = 0, parents = 0, total = 0;
    static constexpr int kVisible = 0, kPosition = 1, kColor = 4, kSize = 8, kRotation = 9, kFrame = 10, kEnd = 11,
                         kRenderColumns = 14, kTrail = 14;
    // This object's render columns: kRenderColumns, and a trail's 3 per point behind its
    // head from kTrail on (ir::renderColumns).
    int renderColumns = kRenderColumns;
    std::vector<int> stateOffset, paramOffset, exportOffset;
    struct ParentColumn {
        ir::Op op;
        int depth;
        int exportIndex;  // ParentExport only
        int width;
        int offset;       // its first column
    };
    std::vector<ParentColumn> parentColumns;  // in the kernel's instruction order
    // Per emit and render column: whether the kernel writes it. A table gives scratch
    // columns only to these (and the parents'): a pool's update needs no render columns.
    std::vector<bool> writes;
    bool needs(int column) const { return column >= parents || writes[static_cast<size_t>(column - emits)]; }
    // A render value that is a state value as it is (`point(pos, col, 2)`: the position is
    // the state slot `pos`) is not copied into a render column: it is drawn from the state
    // column itself. Per render column (kVisible … kSize): the state column it is drawn
    // from, or -1 where the render kernel writes it. Every backend and the drawing read
    // this one rule.
    std::vector<int> renderFromState;
    // The table column render column `c` is drawn from: its state column, or its own.
    int drawnFrom(int c) const {
        return renderFromState.empty() || renderFromState[static_cast<size_t>(c)] < 0
                   ? render + c
                   : renderFromState[static_cast<size_t>(c)];
    }
    bool fromState(const ir::Yield& y) const {
        int c = renderColumn(y.kind, y.index);
        return drawnFrom(c) != render + c;
    }
    // A position, colour or size component every row draws alike (`point(pos, col, 2)`:
    // the size is 2; `(0, 1 − age, 0, 1)`: three of the colour's four) has no column at
    // all: the drawing hands over its value. Per render column (kVisible … kSize); the
    // `visible` column is never constant (it is where the drawn rows are marked). Every
    // backend and the drawing read this one rule.
    struct Constant {
        bool is = false;
        float value = 0;
    };
    std::vector<Constant> renderConstant;
    std::optional<float> constant(int c) const {
        if (renderConstant.empty() || !renderConstant[static_cast<size_t>(c)].is) return std::nullopt;
        return renderConstant[static_cast<size_t>(c)].value;
    }

    // An emission rate or count that every row of a launch at a uniform clock shares: a
    // constant, an extern (`at rate per second`) or a value of the kernel's uniform
    // kernel (`at population / 3 per second`). At a uniform clock the run-time takes it
    // from there, not from its column (which a backend still writes), so a backend whose
    // columns live on a device need not send the column back. Per emit column (a site's
    // rate, then its count); the run-time and every backend read this one rule.
    struct Shared {
        enum class From : uint8_t { Column, Constant, Extern, Uniform } from = From::Column;
        int index = 0;     // Extern: the extern; Uniform: the uniform kernel's value
        float value = 0;   // Constant
    };
    std::vector<Shared> emitShared;
    // The value emit column `column` has in every row of a launch at a uniform clock, with
    // these externs and uniform values, if it is shared.
    std::optional<float> sharedEmit(int column, const ir::Value* externs, const ir::Value* uniforms) const {
        const Shared& s = emitShared.at(static_cast<size_t>(column - emits));
        switch (s.from) {
            case Shared::From::Constant: return s.value;
            case Shared::From::Extern: return externs[s.index].f[0];
            case Shared::From::Uniform: return uniforms[s.index].f[0];
            case Shared::From::Column: break;
        }
        return std::nullopt;
    }

    int emitRate(int site) const { return emits + 2 * site; }
    int emitCount(int site) const { return emits + 2 * site + 1; }
    // The first render column of a render yield (a trail's point: its index).
    static int renderColumn(ir::YieldKind kind, int index = 0);
    // Names every column position, so two kernels with the same text and signature can
    // share compiled code.
    std::string signature() const;
};

ColumnLayout columnLayout(const ir::Object& object, const ir::Kernel& kernel);

// An object's init kernel where it sets anything (an object whose state starts at zero
// and that bursts nothing has an empty one: creating it runs no init).
const ir::Kernel* initKernel(const ir::Object& object);

// The argument columns of a spawn kernel (ChildrenLaunch::args): one per component of each
// argument (emit.arg #sub), arguments in order. `first[sub]` is where argument sub starts.
struct ArgumentColumns {
    std::vector<size_t> first;
    size_t total = 0;
};
ArgumentColumns argumentColumns(const ir::Kernel& spawn);
// The same into `out`, reusing its vector (a launch allocates nothing).
void argumentColumns(const ir::Kernel& spawn, ArgumentColumns& out);

// Rows per chunk when a launch over a pool is split over threads. Chunks never depend on
// the number of threads, so every row is computed by the same code path (vector body or
// remainder) with 1 or N threads, and results are identical.
constexpr size_t kRowsPerChunk = 8192;

}  // namespace psys::rt
