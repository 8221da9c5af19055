// One pool per object type: structure of arrays, one float column per component of every
// state slot, parameter and export the IR keeps, plus the bookkeeping every object needs.
//
// Rows are reused through a free list; a Handle is (row, generation), and a row's
// generation changes whenever it is freed, so a stale handle never reads a reused row.
// A killed object that children still read stays in its row, frozen (not updated, not
// drawn, its exports kept) until its last reader is gone.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "ir/ir.h"
#include "rt/backend.h"

namespace psys::rt {

struct Handle {
    uint32_t row = std::numeric_limits<uint32_t>::max();
    uint32_t generation = 0;
    bool valid() const { return row != std::numeric_limits<uint32_t>::max(); }
};

enum class Status : uint8_t { Free, Alive, Frozen };

// Component columns for a list of typed values: column(i, c)[row].
class Columns {
public:
    void define(const std::vector<ir::Type>& types);
    void resize(size_t rows);
    Value get(size_t i, size_t row) const;
    void set(size_t i, size_t row, const Value& v);
    size_t count() const { return types_.size(); }
    const std::vector<float>& column(size_t i, size_t component) const { return columns_[offset_[i] + component]; }
    float* data(size_t i, size_t component) { return columns_[offset_[i] + component].data(); }

private:
    std::vector<ir::Type> types_;
    std::vector<size_t> offset_;
    std::vector<std::vector<float>> columns_;
};

class Pool {
public:
    Pool(const ir::Object& object, size_t capacity);

    const ir::Object& object() const { return *object_; }
    size_t capacity() const { return capacity_; }
    size_t rows() const { return status_.size(); }  // the high-water mark
    size_t live() const { return live_; }
    size_t frozen() const { return frozen_; }
    size_t free() const { return capacity_ - live_ - frozen_; }

    // A new row for an object, or nullopt at capacity.
    std::optional<uint32_t> allocate();
    void release(uint32_t row);  // back to the free list; the generation moves on
    void freeze(uint32_t row);
    bool matches(Handle h) const { return h.row < rows() && generation_[h.row] == h.generation && status_[h.row] != Status::Free; }
    Handle handle(uint32_t row) const { return {row, generation_[row]}; }

    Columns state, params, exports;  // params: only the kept ones
    std::vector<int> paramColumn;     // per parameter: its column in `params`, or -1
    std::vector<double> created;
    std::vector<uint32_t> id;
    std::vector<Handle> parent;
    std::vector<uint32_t> readers;       // children that read this object live
    // 1 for rows a step updates: alive and not created during the current step. Rows
    // created during a step are listed in `fresh` until the next step begins.
    std::vector<uint8_t> updatable;
    std::vector<uint32_t> fresh;
    void beginStep();  // the rows created before this step become updatable
    std::vector<std::vector<double>> emitted;  // per rate site: events accumulated, in [0, 1)
    Status status(uint32_t row) const { return status_[row]; }

private:
    const ir::Object* object_;
    size_t capacity_;
    std::vector<Status> status_;
    std::vector<uint32_t> generation_;
    std::vector<uint32_t> freeRows_;
    size_t live_ = 0, frozen_ = 0;
};

}  // namespace psys::rt
