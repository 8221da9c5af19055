// A kernel over a range of rows of a pool: the calling convention of the loops that
// update whole pools (the update and exports kernels).
//
// The run-time hands a backend one table of column pointers; where each column sits in
// the table is fixed by the object's types and the kernel alone (BatchLayout), so a
// backend can compile a kernel's loop once and run it on any pool of that object type.
// Rows whose mask byte is 0 (free, frozen, or created during this step) are left alone:
// their state and exports are not written, their kill flag reads 0.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "ir/ir.h"
#include "ir/value.h"

namespace psys::rt {

// Where each column of a batched kernel sits in the column table.
//   created: double per row (the creation time; age = float(time − created))
//   ids: u32 per row
//   kill: u8 per row, written (0 or 1) for every row of the range by kernels that kill
//   state, params, exports: one float column per component, in declaration order;
//     a parameter the pool does not keep has a null column
//   emits: per emit site, a rate and a count column (floats), written for every row
//   render: visible (0 or 1), position x y z, colour r g b a, size: floats, written for
//     every row by render kernels
//   parents: per parent read of the kernel, in instruction order, one float column per
//     component (gathered by the run-time; `alive` is 0 or 1)
struct BatchLayout {
    static constexpr int kCreated = 0, kIds = 1, kKill = 2, kFirstColumn = 3;
    int state = 0, params = 0, exports = 0, emits = 0, render = 0, parents = 0, total = 0;
    static constexpr int kVisible = 0, kPosition = 1, kColor = 4, kSize = 8, kRenderColumns = 9;
    std::vector<int> stateOffset, paramOffset, exportOffset;
    struct ParentColumn {
        ir::Op op;
        int depth;
        int exportIndex;  // ParentExport only
        int width;
        int offset;       // its first column
    };
    std::vector<ParentColumn> parentColumns;  // in the kernel's instruction order

    int emitRate(int site) const { return emits + 2 * site; }
    int emitCount(int site) const { return emits + 2 * site + 1; }
    // Names every column position, so two kernels with the same text and signature can
    // share compiled code.
    std::string signature() const;
};

BatchLayout batchLayout(const ir::Object& object, const ir::Kernel& kernel);

// What time it is for the rows of a batch.
enum class RowsMode : uint8_t {
    // Objects stepped together: time is `time`, age float(time − created), dt `dt`, and
    // the uniform values are `uniforms`.
    Step,
    // Objects being created (their init kernel): time is their creation time, age 0, dt
    // 0, `first` true.
    Init,
    // Objects just created, advanced over the rest of the step: time is `time`, dt is
    // float(time − created), different for each, and so are the uniform values, which
    // are computed for each object from `uniformKernel`.
    FirstUpdate,
};

// One call of a batched kernel: rows [begin, end) of a pool.
struct RowBatch {
    size_t begin = 0, end = 0;
    const uint8_t* mask = nullptr;
    void* const* columns = nullptr;  // BatchLayout positions
    const ir::Value* externs = nullptr;
    const ir::Value* uniforms = nullptr;
    double time = 0;                 // the end of the step
    float dt = 0;
    uint32_t seed = 0;
    uint32_t draw = 0;               // the step
    RowsMode mode = RowsMode::Step;
    const ir::Kernel* uniformKernel = nullptr;  // FirstUpdate
};

// Rows per chunk when a pool's update is split over threads. Chunks never depend on the
// number of threads, so every row is computed by the same code path (vector body or
// remainder) with 1 or N threads, and results are identical.
constexpr size_t kRowsPerChunk = 8192;

}  // namespace psys::rt
