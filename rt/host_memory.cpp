// The host's memory (rt::HostMemory): columns as host arrays, which the interpreter and
// the JIT address directly; the memory's operations are rt::Memory's own (rt/memory.cpp).
#include "rt/memory.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>

#include <fmt/format.h>
#include <sys/mman.h>
#include <unistd.h>

#include "rt/host_array.h"

namespace psys::rt {

// One column: a 64-byte aligned array that grows by doubling, so that appending rows one
// at a time costs amortized O(1). A large column is its own anonymous mapping, grown with
// mremap: the kernel moves its pages instead of copying them, pages past the rows in use
// are never touched (so they take no memory), and no second copy exists while it grows —
// a pool of 10M rows holds what its rows need, not twice that at its peak. A pool's columns
// reserve their capacity's address space at once (HostMemory::reserve: MAP_NORESERVE, no
// page touched), so that a pool growing inside a step moves and copies nothing.
struct HostMemory::Column {
    static constexpr size_t kMapped = size_t{1} << 20;  // bytes from which a column is a mapping

    Elem elem;
    size_t rows = 0, capacity = 0;
    std::byte* data = nullptr;
    size_t mappedBytes = 0;  // 0: data is from aligned_alloc or the host's allocator
    HostAllocator host;      // set: data is the host's, hostBytes of it
    size_t hostBytes = 0;

    ~Column() { drop(); }
    void drop() {
        if (host) {
            if (data) host.give(data, hostBytes);
        } else if (mappedBytes) {
            ::munmap(data, mappedBytes);
        } else {
            std::free(data);
        }
    }
    size_t size() const { return elemSize(elem); }
    // Room for `wanted` rows; `exactly`: that many (a pool's capacity), else doubled.
    void reserve(size_t wanted, bool exactly = false) {
        if (wanted <= capacity) return;
        size_t grown = exactly ? wanted : std::max(wanted, capacity * 2);
        size_t bytes = (grown * size() + 63) / 64 * 64;
        if (host) {
            // (The host's memory cannot be remapped: a larger block and a copy.)
            auto* fresh = static_cast<std::byte*>(host.take(std::max<size_t>(bytes, 64), 64));
            if (data) std::memcpy(fresh, data, rows * size());
            drop();
            data = fresh;
            hostBytes = std::max<size_t>(bytes, 64);
            capacity = hostBytes / size();
            return;
        }
        if (bytes >= kMapped) {
            const size_t page = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
            bytes = (bytes + page - 1) / page * page;
            void* fresh = mappedBytes ? ::mremap(data, mappedBytes, bytes, MREMAP_MAYMOVE)
                                      : ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
            if (fresh == MAP_FAILED) throw std::bad_alloc();
            if (!mappedBytes) {
                if (data) std::memcpy(fresh, data, rows * size());
                std::free(data);
            }
            data = static_cast<std::byte*>(fresh);
            mappedBytes = bytes;
            capacity = bytes / size();
            return;
        }
        auto* fresh = static_cast<std::byte*>(std::aligned_alloc(64, std::max<size_t>(bytes, 64)));
        if (!fresh) throw std::bad_alloc();
        if (data) std::memcpy(fresh, data, rows * size());
        std::free(data);
        data = fresh;
        capacity = grown;
    }
    void resize(size_t n) {
        reserve(n);
        if (n > rows) std::memset(data + rows * size(), 0, (n - rows) * size());
        rows = n;
    }
};

HostMemory::HostMemory() = default;
HostMemory::~HostMemory() = default;

Buffer HostMemory::create(Elem elem, size_t rows) {
    auto column = std::make_unique<Column>();
    column->elem = elem;
    column->host = allocator();
    column->resize(rows);
    if (!free_.empty()) {
        uint32_t id = free_.back();
        free_.pop_back();
        columns_[id] = std::move(column);
        return {id};
    }
    columns_.push_back(std::move(column));
    return {static_cast<uint32_t>(columns_.size() - 1)};
}

void HostMemory::resize(Buffer b, size_t rows) { columns_.at(b.id)->resize(rows); }

void HostMemory::reserve(Buffer b, size_t rows) {
    Column& c = *columns_.at(b.id);
    if (c.host) return c.reserve(rows, true);  // (memory, not address space: the host hears of a failure)
    try {
        c.reserve(rows, true);
    } catch (const std::bad_alloc&) {  // (no address space for it: it grows when it must)
    }
}

void HostMemory::populate(Buffer b, size_t rows) {
    Column& c = *columns_.at(b.id);
    populatePages(c.data, std::min(rows, c.capacity) * c.size());
}

void* HostAllocator::take(size_t bytes, size_t alignment) const {
    void* p = allocate(user, bytes, alignment);
    if (!p) throw HostOutOfMemory(fmt::format("the host's allocator gave no memory for {} bytes", bytes));
    if (reinterpret_cast<uintptr_t>(p) % alignment != 0) {
        release(user, p, bytes);
        throw HostOutOfMemory(fmt::format("the host's allocator gave {} bytes at {}, not aligned to {} bytes as asked",
                                          bytes, fmt::ptr(p), alignment));
    }
    return p;
}

void populatePages(void* data, size_t bytes) {
    if (!data || bytes == 0) return;
    const auto page = static_cast<uintptr_t>(::sysconf(_SC_PAGESIZE));
    auto begin = reinterpret_cast<uintptr_t>(data) / page * page;
    auto end = reinterpret_cast<uintptr_t>(data) + bytes;
#ifdef MADV_POPULATE_WRITE
    if (::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_POPULATE_WRITE) == 0) return;
#endif
    // (A kernel before 5.14: each page written with what it holds.)
    for (uintptr_t p = std::max(begin, reinterpret_cast<uintptr_t>(data)); p < end; p = (p / page + 1) * page) {
        auto* byte = reinterpret_cast<volatile std::byte*>(p);
        *byte = *byte;
    }
}

void HostMemory::release(Buffer b) {
    if (!b.valid() || b.id >= columns_.size() || !columns_[b.id]) return;
    columns_[b.id].reset();
    free_.push_back(b.id);
}

size_t HostMemory::rows(Buffer b) const { return columns_.at(b.id)->rows; }
Elem HostMemory::elem(Buffer b) const { return columns_.at(b.id)->elem; }

void HostMemory::read(Buffer b, size_t first, size_t count, void* out) const {
    const Column& c = *columns_.at(b.id);
    if (first + count > c.rows) throw std::out_of_range("HostMemory::read past the end of a buffer");
    if (count == 0) return;  // an empty buffer has no address
    std::memcpy(out, c.data + first * c.size(), count * c.size());
}

void HostMemory::write(Buffer b, size_t first, size_t count, const void* in) {
    Column& c = *columns_.at(b.id);
    if (first + count > c.rows) throw std::out_of_range("HostMemory::write past the end of a buffer");
    if (count == 0) return;
    std::memcpy(c.data + first * c.size(), in, count * c.size());
}

void HostMemory::copy(Buffer from, size_t fromFirst, Buffer to, size_t toFirst, size_t count) {
    Column &f = *columns_.at(from.id), &t = *columns_.at(to.id);
    if (f.elem != t.elem || fromFirst + count > f.rows || toFirst + count > t.rows)
        throw std::out_of_range("HostMemory::copy between mismatched buffers");
    if (count == 0) return;
    std::memmove(t.data + toFirst * t.size(), f.data + fromFirst * f.size(), count * f.size());
}

void HostMemory::scatter(Buffer from, size_t fromFirst, Buffer to, std::span<const uint32_t> rows) {
    Column &f = *columns_.at(from.id), &t = *columns_.at(to.id);
    if (f.elem != t.elem || fromFirst + rows.size() > f.rows)
        throw std::out_of_range("HostMemory::scatter between mismatched buffers");
    for (uint32_t row : rows)
        if (row != kSkipRow && row >= t.rows) throw std::out_of_range("HostMemory::scatter past the end of a buffer");
    // Typed moves for the element sizes columns have (a memcpy call per row costs more
    // than the move).
    auto move = [&](auto word) {
        using W = decltype(word);
        const auto* in = reinterpret_cast<const W*>(f.data) + fromFirst;
        auto* out = reinterpret_cast<W*>(t.data);
        for (size_t i = 0; i < rows.size(); ++i)
            if (rows[i] != kSkipRow) out[rows[i]] = in[i];
    };
    switch (f.size()) {
        case 1: move(uint8_t{}); break;
        case 4: move(uint32_t{}); break;
        case 8: move(uint64_t{}); break;
        default: {
            size_t n = f.size();
            for (size_t i = 0; i < rows.size(); ++i)
                if (rows[i] != kSkipRow) std::memcpy(t.data + rows[i] * n, f.data + (fromFirst + i) * n, n);
        }
    }
}

void HostMemory::gather(Buffer from, Buffer to, size_t toFirst, std::span<const uint32_t> rows) {
    Column &f = *columns_.at(from.id), &t = *columns_.at(to.id);
    if (f.elem != t.elem || toFirst + rows.size() > t.rows)
        throw std::out_of_range("HostMemory::gather between mismatched buffers");
    size_t n = f.size();
    for (size_t i = 0; i < rows.size(); ++i) {
        std::byte* out = t.data + (toFirst + i) * n;
        if (rows[i] == kSkipRow) {
            std::memset(out, 0, n);
            continue;
        }
        if (rows[i] >= f.rows) throw std::out_of_range("HostMemory::gather past the end of a buffer");
        std::memcpy(out, f.data + rows[i] * n, n);
    }
}

void* HostMemory::host(Buffer b) { return columns_.at(b.id)->data; }

size_t HostMemory::bytes() const {
    size_t total = 0;
    for (const auto& c : columns_)
        if (c) total += c->capacity * c->size();
    return total;
}

}  // namespace psys::rt
