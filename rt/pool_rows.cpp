// A pool's rows on the host: the allocation rule's rows for a batch, a row frozen and
// freed, and the same for lists of many rows — in pieces of detail::kHostRows rows on
// every thread, each piece's place on the free stack from the counts of the pieces before
// it, so that the stack, the rows and the ids are the same bits on any number of threads
// (docs/architecture.md, "The life of a step"). The rows the memory keeps are its own
// operations' (rt/pool.cpp).
#include <algorithm>
#include <atomic>
#include <stdexcept>

#include "rt/allocation.h"
#include "rt/parallel.h"
#include "rt/pool.h"

namespace psys::rt {

size_t Pool::allocate(size_t n, uint32_t* out) {
    FreeRows free{freeRows_.data(), freeRows_.size(), rows(), capacity_};
    size_t kept = std::min(n, free.room());
    if (kept > free.top) grow(free.highWater + (kept - free.top));  // once, for the whole batch
    std::vector<double*>& accumulated = accumulated_;  // (kept from call to call: no allocation)
    accumulated.clear();
    for (Buffer e : emitted) accumulated.push_back(hostData<double>(*memory_, e));
    forPieces(n, [&](size_t begin, size_t end) {  // (row k depends on k alone: rt/allocation.h)
        for (size_t k = begin; k < end; ++k) {
            if (k >= kept) {
                out[k] = kSkipRow;
                continue;
            }
            uint32_t row = free.row(k);
            out[k] = row;
            status_[row] = Status::Alive;
            readers[row] = 0;
            parent[row] = {};
            for (double* a : accumulated) a[row] = 0;
            updatable.set(row, 0);
            alive.set(row, 1);
        }
    });
    freeRows_.resize(free.top - std::min(kept, free.top));
    fresh.insert(fresh.end(), out, out + kept);
    live_ += kept;
    return kept;
}

void Pool::forPieces(size_t n, core::FunctionRef<void(size_t, size_t)> fn) const {
    size_t pieces = (n + detail::kHostRows - 1) / detail::kHostRows;
    auto piece = [&](size_t p) { fn(p * detail::kHostRows, std::min(n, (p + 1) * detail::kHostRows)); };
    if (pieces > 1 && runPieces_ && updatable.direct() && alive.direct()) {
        runPieces_(pieces, piece);
        return;
    }
    for (size_t p = 0; p < pieces; ++p) piece(p);
}

void Pool::freeze(uint32_t row, double at) {
    if (status_[row] != Status::Alive) return;
    status_[row] = Status::Frozen;
    diedAt[row] = at;
    updatable.set(row, 0);
    alive.set(row, 0);
    --live_;
    ++frozen_;
}

void Pool::release(uint32_t row) {
    if (status_[row] == Status::Alive) --live_;
    else if (status_[row] == Status::Frozen) --frozen_;
    else return;
    status_[row] = Status::Free;
    updatable.set(row, 0);
    alive.set(row, 0);
    ++generation_[row];
    freeRows_.push_back(row);
}

void Pool::forListPieces(RowLists lists, core::FunctionRef<void(size_t, const ListPiece&)> fn) const {
    std::vector<ListPiece>& pieces = listPieces_;  // (kept from call to call: no allocation)
    pieces.clear();
    const size_t total = rowCount(lists);
    // Where each piece starts: a walk over the lists' sizes (a list a chunk: few).
    for (size_t l = 0, at = 0, first = 0; first < total; first += detail::kHostRows) {
        while (at == lists[l].size()) ++l, at = 0;
        pieces.push_back({lists, l, at, first, std::min(detail::kHostRows, total - first)});
        for (size_t left = pieces.back().count; left > 0;) {  // on past this piece's rows
            size_t take = std::min(left, lists[l].size() - at);
            left -= take, at += take;
            if (left > 0) ++l, at = 0;
        }
    }
    if (pieces.size() > 1 && runPieces_ && updatable.direct() && alive.direct()) {
        runPieces_(pieces.size(), [&](size_t p) { fn(p, pieces[p]); });
        return;
    }
    for (size_t p = 0; p < pieces.size(); ++p) fn(p, pieces[p]);
}

void Pool::freeze(RowLists lists, std::span<const double> at) {
    std::atomic<size_t> frozen = 0;
    forListPieces(lists, [&](size_t, const ListPiece& piece) {
        size_t its = 0;
        piece.each([&](size_t k, uint32_t row) {
            if (status_[row] != Status::Alive) return;
            status_[row] = Status::Frozen;
            diedAt[row] = at[at.size() == 1 ? 0 : k];
            updatable.set(row, 0);
            alive.set(row, 0);
            ++its;
        });
        frozen += its;
    });
    live_ -= frozen;
    frozen_ += frozen;
}

// In two passes over the same pieces: how many rows each frees, then each piece's rows at
// its place on the stack (the places a prefix sum of the counts). The rows are distinct (a
// launch's kill lists): no two pieces touch one row.
size_t Pool::releaseRows(RowLists lists, Status from) {
    const size_t total = rowCount(lists);
    const size_t pieces = (total + detail::kHostRows - 1) / detail::kHostRows;
    std::vector<size_t>& at = pieceStarts_;  // (kept from call to call: no allocation)
    at.assign(pieces + 1, 0);
    forListPieces(lists, [&](size_t p, const ListPiece& piece) {
        size_t its = 0;
        piece.each([&](size_t, uint32_t row) { its += status_[row] == from; });
        at[p + 1] = its;
    });
    for (size_t p = 0; p < pieces; ++p) at[p + 1] += at[p];
    size_t top = freeRows_.size();
    freeRows_.resize(top + at[pieces]);
    std::atomic<bool> twice = false;  // a piece that freed fewer than it counted: a row twice in it
    forListPieces(lists, [&](size_t p, const ListPiece& piece) {
        uint32_t* stack = freeRows_.data() + top + at[p];
        piece.each([&](size_t, uint32_t row) {
            if (from == Status::Alive) {  // (releaseKilled: every row's masks cleared)
                updatable.set(row, 0);
                alive.set(row, 0);
            }
            if (status_[row] != from) return;
            status_[row] = Status::Free;
            ++generation_[row];
            *stack++ = row;
        });
        if (stack != freeRows_.data() + top + at[p + 1]) twice = true;
    });
    // (The stack would hold rows never written: a broken rule of the caller's, said, not used.)
    if (twice) throw std::logic_error("Pool::releaseRows: a row listed twice");
    return at[pieces];
}

void Pool::releaseKilled(RowLists lists) { live_ -= releaseRows(lists, Status::Alive); }

void Pool::beginStep() {
    if (inMemory_) {
        for (const FreshRows& f : freshRows_) {
            memory_->markFresh(rows_, f.rows, 0, f.count);
            recycle(f.rows);
        }
        if (!freshRows_.empty()) ++version_;
        freshRows_.clear();
        return;
    }
    forPieces(fresh.size(), [&](size_t begin, size_t end) {
        for (size_t k = begin; k < end; ++k)
            if (status_[fresh[k]] == Status::Alive) updatable.set(fresh[k], 1);
    });
    fresh.clear();
}

}  // namespace psys::rt
