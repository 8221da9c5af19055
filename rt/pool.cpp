// A pool's columns, masks and host arrays, its growth and room, and its rows where the
// memory keeps them (rt/pool.h); its rows on the host, one at a time or in pieces on every
// thread: rt/pool_rows.cpp.
#include "rt/pool.h"

#include <algorithm>
#include <array>
#include <stdexcept>

#include <unistd.h>

#include "core/fold.h"
#include "rt/parallel.h"

namespace psys::rt {

void ValueColumns::define(Memory& memory, const std::vector<ir::Type>& types, size_t rows) {
    types_ = types;
    offset_.clear();
    size_t n = 0;
    for (auto& t : types) {
        offset_.push_back(n);
        n += static_cast<size_t>(t.width);
    }
    columns_.clear();
    for (size_t i = 0; i < n; ++i) columns_.push_back(memory.create(Elem::F32, rows));
}

void ValueColumns::release(Memory& memory) {
    for (Buffer b : columns_) memory.release(b);
    columns_.clear();
}

void ValueColumns::resize(Memory& memory, size_t rows) {
    for (Buffer b : columns_) memory.resize(b, rows);
}

ir::Value ValueColumns::get(const Memory& memory, size_t i, size_t row) const {
    ir::Value v;
    for (int c = 0; c < types_[i].width; ++c)
        memory.read(column(i, static_cast<size_t>(c)), row, 1, &v.f[static_cast<size_t>(c)]);
    return v;
}

void ValueColumns::set(Memory& memory, size_t i, size_t row, const ir::Value& v) const {
    for (int c = 0; c < types_[i].width; ++c)
        memory.write(column(i, static_cast<size_t>(c)), row, 1, &v.f[static_cast<size_t>(c)]);
}

void SyncedMask::create(Memory& memory) {
    column = memory.create(Elem::U8, 0);
    staging_ = memory.create(Elem::U8, 0);
    resident_ = memory.hostResident();
}

void SyncedMask::release(Memory& memory) {
    memory.release(column);
    memory.release(staging_);
}

void SyncedMask::grow(Memory& memory, size_t rows) {
    memory.resize(column, rows);
    if (resident_)
        direct_ = hostData<uint8_t>(memory, column);  // it may have moved
    else
        host_.resize(rows, 0);
}

void SyncedMask::reserved(Memory& memory) {
    if (resident_) direct_ = hostData<uint8_t>(memory, column);  // (where the reservation put it)
}

void SyncedMask::sync(Memory& memory) {
    if (changed_.empty()) return;
    // A row changed twice is listed twice, with its one current value: the order of the
    // scatter's writes does not matter.
    std::vector<uint8_t> values(changed_.size());
    for (size_t i = 0; i < changed_.size(); ++i) values[i] = host_[changed_[i]];
    if (memory.rows(staging_) < values.size()) memory.resize(staging_, values.size());
    memory.write(staging_, 0, values.size(), values.data());
    memory.scatter(staging_, 0, column, changed_);
    changed_.clear();
}

void SyncedMask::restore(Memory& memory, std::vector<uint8_t> values) {
    values.resize(memory.rows(column), 0);
    changed_.clear();
    memory.write(column, 0, values.size(), values.data());
    if (resident_)
        direct_ = hostData<uint8_t>(memory, column);
    else
        host_ = std::move(values);
}

Pool::Pool(const ir::Object& object, size_t capacity, Memory& memory)
    : object_(&object), capacity_(capacity), memory_(&memory) {
    if (const HostAllocator& host = memory.allocator()) {  // (its host arrays are the host's memory too)
        parent = HostArray<Handle>(MappedAllocator<Handle>(host));
        readers = HostArray<uint32_t>(MappedAllocator<uint32_t>(host));
        diedAt = HostArray<double>(MappedAllocator<double>(host));
        status_ = HostArray<Status>(MappedAllocator<Status>(host));
        generation_ = HostArray<uint32_t>(MappedAllocator<uint32_t>(host));
        freeRows_ = HostArray<uint32_t>(MappedAllocator<uint32_t>(host));
    }
    created = memory.create(Elem::F64, 0);
    ids = memory.create(Elem::U32, 0);
    updatable.create(memory);
    alive.create(memory);
    std::vector<ir::Type> types;
    for (auto& s : object.state) types.push_back(s.type);
    state.define(memory, types, 0);
    types.clear();
    for (auto& p : object.params) {
        paramColumn.push_back(p.kept ? static_cast<int>(types.size()) : -1);
        if (p.kept) types.push_back(p.type);
    }
    params.define(memory, types, 0);
    types.clear();
    for (auto& e : object.exports) types.push_back(e.type);
    exports.define(memory, types, 0);
    types.clear();
    for (auto& f : object.folds) types.push_back(f.type);
    folds.define(memory, types, 1);  // row foldRows (0 until the first fold): the empty folds
    for (size_t f = 0; f < object.folds.size(); ++f) {
        float empty = core::emptyFold(object.folds[f].reduce);
        for (int c = 0; c < object.folds[f].type.width; ++c) memory.write(folds.column(f, static_cast<size_t>(c)), 0, 1, &empty);
    }
    for (size_t e = 0; e < object.emits.size(); ++e) emitted.push_back(memory.create(Elem::F64, 0));
    reserveRows();
}

// Every column and host array that grows with the pool's rows takes its capacity's room
// now — address space, not memory: no page is touched before its rows are used — so that
// a pool growing inside a step (a rate filling it) moves and copies nothing: growing a
// 500,000-row pool's arrays by doubling took 5.6 ms of a 0.2 ms step (`psys_bench
// --hitches`, docs/performance.md).
void Pool::forEachRowColumn(core::FunctionRef<void(Buffer)> f) const {
    for (Buffer b : {created, ids, updatable.column, alive.column, rows_.stack, rows_.generation, rows_.readers,
                     rows_.waiting, parentRows, frozenAt})
        if (b.valid()) f(b);
    for (Buffer b : emitted)
        if (b.valid()) f(b);
    for (const ValueColumns* v : {&state, &params, &exports})
        for (size_t i = 0; i < v->count(); ++i)
            for (int c = 0; c < v->type(i).width; ++c)
                if (Buffer b = v->column(i, static_cast<size_t>(c)); b.valid()) f(b);
}

void Pool::reserveRows() {
    // (The host's allocator gives memory, not address space: its pools take room only
    // when the host reserves rows — populate.)
    if (memory_->allocator()) return;
    room_ = reservableRows(capacity_, rowBytes(*object_));
    forEachRowColumn([&](Buffer b) { memory_->reserve(b, room_); });
    updatable.reserved(*memory_);
    alive.reserved(*memory_);
    if (inMemory_) return;  // (its host arrays are copies, read back when asked)
    reserveRoom(status_, room_);
    reserveRoom(generation_, room_);
    reserveRoom(freeRows_, room_);
    reserveRoom(parent, room_);
    reserveRoom(readers, room_);
    reserveRoom(diedAt, room_);
}

void Pool::populate(size_t rows) {
    if (memory_->allocator()) {  // room for them from the host's allocator, whose memory is the host's to page
        rows = std::min(rows, capacity_);
        try {
            forEachRowColumn([&](Buffer b) { memory_->reserve(b, rows); });
        } catch (...) {
            updatable.reserved(*memory_);  // (a mask column that moved before the failure)
            alive.reserved(*memory_);
            throw;
        }
        updatable.reserved(*memory_);
        alive.reserved(*memory_);
        room_ = std::max(room_, rows);
        if (inMemory_) return;
        for (auto* v : {&generation_, &freeRows_, &readers}) v->reserve(rows);
        status_.reserve(rows);
        parent.reserve(rows);
        diedAt.reserve(rows);
        return;
    }
    rows = std::min(rows, room_);
    forEachRowColumn([&](Buffer b) { memory_->populate(b, rows); });
    if (inMemory_) return;
    populateRoom(status_, rows);
    populateRoom(generation_, rows);
    populateRoom(freeRows_, rows);
    populateRoom(parent, rows);
    populateRoom(readers, rows);
    populateRoom(diedAt, rows);
}

size_t reservableRows(size_t capacity, size_t rowBytes) {
    auto pages = static_cast<size_t>(::sysconf(_SC_PHYS_PAGES)), page = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
    return std::min(capacity, pages * page / std::max<size_t>(rowBytes, 1));
}

size_t Pool::rowBytes(const ir::Object& object) {
    size_t floats = 0;
    for (auto& s : object.state) floats += static_cast<size_t>(s.type.width);
    for (auto& p : object.params)
        if (p.kept) floats += static_cast<size_t>(p.type.width);
    for (auto& e : object.exports) floats += static_cast<size_t>(e.type.width);
    for (auto& f : object.folds) floats += static_cast<size_t>(f.type.width);
    size_t columns = sizeof(double) + sizeof(uint32_t) + 2 + 4 * floats;  // created, id, updatable, alive, values
    size_t host = sizeof(Status) + sizeof(uint32_t) + sizeof(Handle) + sizeof(uint32_t) + sizeof(double) + 2 +
                  sizeof(double) * object.emits.size();  // status, generation, parent, readers, diedAt, masks, emitted
    return columns + host;
}

Pool::Pool(Pool&& other) noexcept
    : created(other.created), ids(other.ids), parentRows(other.parentRows), frozenAt(other.frozenAt), updatable(std::move(other.updatable)), alive(std::move(other.alive)), state(std::move(other.state)),
      params(std::move(other.params)), exports(std::move(other.exports)), folds(std::move(other.folds)),
      foldRows(other.foldRows), paramColumn(std::move(other.paramColumn)),
      parent(std::move(other.parent)), readers(std::move(other.readers)), diedAt(std::move(other.diedAt)),
      fresh(std::move(other.fresh)), emitted(std::move(other.emitted)), object_(other.object_), capacity_(other.capacity_), room_(other.room_), memory_(other.memory_),
      status_(std::move(other.status_)), generation_(std::move(other.generation_)),
      freeRows_(std::move(other.freeRows_)), live_(other.live_), frozen_(other.frozen_), inMemory_(other.inMemory_),
      rows_(other.rows_), top_(other.top_), highWater_(other.highWater_), uncounted_(other.uncounted_),
      countPending_(other.countPending_),
      freshRows_(std::move(other.freshRows_)), spare_(std::move(other.spare_)), held_(std::move(other.held_)),
      version_(other.version_),
      fetched_(other.fetched_), mask_(std::move(other.mask_)), runPieces_(std::move(other.runPieces_)) {
    other.memory_ = nullptr;
}

Pool::~Pool() {
    if (!memory_) return;  // moved from
    memory_->release(created);
    memory_->release(ids);
    for (Buffer b : emitted) memory_->release(b);
    updatable.release(*memory_);
    alive.release(*memory_);
    state.release(*memory_);
    params.release(*memory_);
    exports.release(*memory_);
    folds.release(*memory_);
    for (Buffer b : {rows_.stack, rows_.generation, rows_.counters, rows_.readers, rows_.waiting, parentRows, frozenAt})
        if (b.valid()) memory_->release(b);
    for (const FreshRows& f : freshRows_) memory_->release(f.rows);
    for (Buffer b : spare_) memory_->release(b);
}

void Pool::grow(size_t n) {
    // Room for n rows in everything first, which may fail (the host's allocator: std::
    // bad_alloc) and changes no row count; then the resizes, which cannot. A failed growth
    // leaves the pool as it was, no column shorter than its rows.
    roomFor(n);
    if (inMemory_) {
        highWater_ = n;
        for (Buffer b : {rows_.stack, rows_.generation, rows_.readers, rows_.waiting, parentRows, frozenAt})
            if (b.valid()) memory_->resize(b, n);
    } else {
        status_.resize(n, Status::Free);
        generation_.resize(n, 0);
    }
    parent.resize(n);
    readers.resize(n, 0);
    diedAt.resize(n, 0);
    for (Buffer b : emitted) memory_->resize(b, n);
    for (Buffer b : {created, ids}) memory_->resize(b, n);
    updatable.grow(*memory_, n);
    alive.grow(*memory_, n);
    state.resize(*memory_, n);
    params.resize(*memory_, n);
    exports.resize(*memory_, n);
}

void Pool::roomFor(size_t n) {
    if (n <= rows()) return;
    try {
        // (Doubled, as a resize would — growth stays amortized — up to the capacity, the
        // most a pool holds: what reserveRows took room for is never exceeded.)
        const size_t room = std::max(n, std::min(2 * rows(), capacity_));
        forEachRowColumn([&](Buffer b) { memory_->reserve(b, room); });
        updatable.reserved(*memory_);
        alive.reserved(*memory_);
        if (!inMemory_) {
            if (status_.capacity() < n) status_.reserve(room);
            if (generation_.capacity() < n) generation_.reserve(room);
        }
        if (parent.capacity() < n) parent.reserve(room);
        if (readers.capacity() < n) readers.reserve(room);
        if (diedAt.capacity() < n) diedAt.reserve(room);
    } catch (...) {
        updatable.reserved(*memory_);  // (a mask column that moved before the failure)
        alive.reserved(*memory_);
        throw;
    }
}

void Pool::countsDownParent(Buffer parentReaders) {
    if (rows_.parents.valid()) rows_.parentReaders = parentReaders;
}

void Pool::keepRowsInMemory(bool child, bool read) {
    if (inMemory_) return;
    inMemory_ = true;
    rows_ = {memory_->create(Elem::U32, rows()), memory_->create(Elem::U32, rows()), updatable.column, alive.column,
             memory_->create(Elem::U32, kCounters), {}, {}, {}, {}};
    if (read) {
        rows_.readers = memory_->create(Elem::U32, rows());
        rows_.waiting = memory_->create(Elem::U8, rows());
        frozenAt = memory_->create(Elem::F64, rows());
    }
    if (child) parentRows = memory_->create(Elem::U32, rows());
    if (child && read) rows_.parents = parentRows;  // (and its parent's readers: countsDownParent)
    reserveRows();
    restoreInMemory();  // what the host has so far (nothing, before the first object)
}

size_t Pool::allocate(size_t n, Buffer out, size_t outFirst) {
    counted();
    if (uncounted_) throw std::logic_error("a pool's rows allocated before its last releases were counted");
    size_t room = top_ + (capacity_ > highWater_ ? capacity_ - highWater_ : 0);
    size_t kept = std::min(n, room);
    if (kept == 0) return 0;
    size_t fromStack = std::min(kept, top_), highWater = highWater_;
    if (kept > fromStack) grow(highWater_ + (kept - fromStack));  // once, for the whole batch
    memory_->allocateRows(rows_, top_, highWater, kept, out, outFirst);
    top_ -= fromStack;
    live_ += kept;
    ++version_;
    return kept;
}

void Pool::release(Buffer killed, size_t killedAt, uint32_t base, Buffer map, size_t mapFirst, size_t lists) {
    memory_->releaseRows(rows_, killed, killedAt, base, map, mapFirst);
    uncounted_ += lists;
    ++version_;
}

void Pool::releaseUnread(Buffer killed, size_t killedAt, uint32_t base, Buffer map, size_t mapFirst) {
    memory_->releaseUnread(rows_, killed, killedAt, base, map, mapFirst);
    ++uncounted_;
    ++version_;
}

// (Only where some row may wait, as the host last counted: a row frozen in this step
// waits for children that are freed in a later one — a step frees the children first.)
void Pool::releaseWaiting() {
    if (!rows_.waiting.valid() || (!countPending_ && frozen_ == 0)) return;
    memory_->releaseWaiting(rows_, highWater_);
    ++uncounted_;
    ++version_;
}

void Pool::countFromMemory() {
    if (uncounted_ > 0) countPending_ = true;
}

void Pool::counted() const {
    if (!countPending_) return;
    countPending_ = false;
    std::array<uint32_t, kCounters> counters{};
    memory_->read(rows_.counters, 0, kCounters, counters.data());
    top_ = counters[kCounterTop];
    frozen_ = counters[kCounterWaiting];
    live_ = highWater_ - top_ - frozen_;
    uncounted_ = 0;
}

void Pool::released(size_t count) {
    if (uncounted_ == 0) throw std::logic_error("a pool's release counted twice");
    --uncounted_;
    top_ += count;
    live_ -= count;
}

void Pool::createdRows(Buffer rows, size_t count) { freshRows_.push_back({rows, count}); }

void Pool::recycle(Buffer b) {
    if (auto it = std::find(held_.begin(), held_.end(), b); it != held_.end()) {
        held_.erase(it);
        return;
    }
    spare_.push_back(b);
}

// The smallest spare buffer that holds `n` rows, else the largest, grown: a step's kill
// list of the whole pool and a batch's few rows do not trade buffers, so that none grows
// step after step.
Buffer Pool::scratchRows(size_t n) {
    if (spare_.empty()) return memory_->create(Elem::U32, n);
    size_t best = 0;
    for (size_t i = 1; i < spare_.size(); ++i) {
        size_t rows = memory_->rows(spare_[i]), bestRows = memory_->rows(spare_[best]);
        bool fits = rows >= n, bestFits = bestRows >= n;
        if (fits != bestFits ? fits : (fits ? rows < bestRows : rows > bestRows)) best = i;
    }
    Buffer b = spare_[best];
    spare_.erase(spare_.begin() + static_cast<std::ptrdiff_t>(best));
    if (memory_->rows(b) < n) memory_->resize(b, n);
    return b;
}

void Pool::fetch() const {
    if (!inMemory_ || fetched_ == version_) return;
    size_t rows = highWater_;
    uint32_t top = 0;
    memory_->read(rows_.counters, kCounterTop, 1, &top);  // the memory's: counted or not
    generation_.resize(rows);
    freeRows_.resize(top);
    mask_.resize(rows);
    status_.assign(rows, Status::Free);
    memory_->read(rows_.generation, 0, rows, generation_.data());
    memory_->read(rows_.stack, 0, top, freeRows_.data());
    memory_->read(rows_.updatable, 0, rows, mask_.data());
    std::vector<uint8_t> isAlive(rows);
    memory_->read(rows_.alive, 0, rows, isAlive.data());
    for (size_t row = 0; row < rows; ++row)
        if (isAlive[row]) status_[row] = Status::Alive;
    if (rows_.waiting.valid() && rows > 0) {  // frozen for their readers
        std::vector<uint8_t> waiting(rows);
        memory_->read(rows_.waiting, 0, rows, waiting.data());
        for (size_t row = 0; row < rows; ++row)
            if (waiting[row]) status_[row] = Status::Frozen;
    }
    fetched_ = version_;
}

void Pool::syncMasks() {
    updatable.sync(*memory_);
    alive.sync(*memory_);
}

// The rows alive but not updatable are those created since the last step's start.
std::vector<uint32_t> Pool::freshRows() const {
    if (!inMemory_) return fresh;
    std::vector<uint32_t> out;
    for (uint32_t row = 0; row < rows(); ++row)
        if (status(row) == Status::Alive && !mask()[row]) out.push_back(row);
    return out;
}

void Pool::restoreMask(std::vector<uint8_t> mask) {
    updatable.restore(*memory_, std::move(mask));
    if (!inMemory_) return;
    fetched_ = 0;
    ++version_;
    std::vector<uint32_t> fresh = freshRows();
    if (fresh.empty()) return;
    Buffer list = scratchRows(fresh.size());
    memory_->write(list, 0, fresh.size(), fresh.data());
    createdRows(list, fresh.size());
}

void Pool::restore(std::span<const Status> status, std::span<const uint32_t> generation, std::span<const uint32_t> freeRows) {
    grow(status.size());
    status_.assign(status.begin(), status.end());  // (into the arrays reserved: nothing moves later)
    generation_.assign(generation.begin(), generation.end());
    freeRows_.assign(freeRows.begin(), freeRows.end());
    live_ = frozen_ = 0;
    std::vector<uint8_t> isAlive(status_.size());
    for (size_t row = 0; row < status_.size(); ++row) {
        live_ += status_[row] == Status::Alive;
        frozen_ += status_[row] == Status::Frozen;
        isAlive[row] = status_[row] == Status::Alive;
    }
    alive.restore(*memory_, std::move(isAlive));
    if (inMemory_) restoreInMemory();
}

// The rows restore() gave the host, into the memory. A frozen row is freed at once, after
// the free rows given and in row order, as a reload frees the frozen rows nobody reads
// (rt/reload.cpp) — but in a pool that children read: its readers are counted again
// first, and the reload frees the unread (uploadRows).
void Pool::restoreInMemory() {
    for (uint32_t row = 0; row < status_.size() && !rows_.waiting.valid(); ++row)
        if (status_[row] == Status::Frozen) {
            status_[row] = Status::Free;
            ++generation_[row];
            freeRows_.push_back(row);
            --frozen_;
        }
    for (const FreshRows& f : freshRows_) recycle(f.rows);
    freshRows_.clear();
    uncounted_ = 0;
    writeRows();
}

void Pool::uploadRows() {
    if (!inMemory_) return;
    fetch();
    writeRows();
}

// The host's copies into the memory: the stack and its top, generations, alive rows (and
// frozen ones, for a pool children read), readers and parents.
void Pool::writeRows() {
    highWater_ = status_.size();
    top_ = freeRows_.size();
    for (Buffer b : {rows_.stack, rows_.generation, rows_.readers, rows_.waiting, parentRows, frozenAt})
        if (b.valid()) memory_->resize(b, highWater_);
    if (top_) memory_->write(rows_.stack, 0, top_, freeRows_.data());
    if (highWater_) memory_->write(rows_.generation, 0, highWater_, generation_.data());
    std::vector<uint8_t> isAlive(highWater_), waiting(highWater_);
    std::vector<uint32_t> parents(highWater_, kSkipRow);
    uint32_t frozen = 0;
    for (size_t row = 0; row < highWater_; ++row) {
        isAlive[row] = status_[row] == Status::Alive;
        waiting[row] = status_[row] == Status::Frozen;
        frozen += waiting[row];
        if (status_[row] != Status::Free && parent[row].valid()) parents[row] = parent[row].row;
    }
    std::array<uint32_t, kCounters> counters{static_cast<uint32_t>(top_), frozen};
    memory_->write(rows_.counters, 0, kCounters, counters.data());
    if (highWater_ && rows_.waiting.valid()) {
        memory_->write(rows_.waiting, 0, highWater_, waiting.data());
        memory_->write(rows_.readers, 0, highWater_, readers.data());
        memory_->write(frozenAt, 0, highWater_, diedAt.data());
    }
    if (highWater_ && parentRows.valid()) memory_->write(parentRows, 0, highWater_, parents.data());
    alive.restore(*memory_, std::move(isAlive));
    ++version_;
    fetched_ = 0;  // the masks: read back when asked
}

}  // namespace psys::rt
