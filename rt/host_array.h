// A pool's host arrays (statuses, generations, the free stack, parents, readers, deaths):
// std::vectors whose large allocations are anonymous mappings of their own, so that a
// vector reserved for the pool's capacity takes address space and no memory (no page is
// touched before its rows are used; MAP_NORESERVE), and growing it inside a step moves
// and copies nothing (Pool::reserveRows; `psys_bench --hitches`, docs/performance.md).
// Small ones come from the heap, as any vector's. Where the host gives an allocator
// (HostAllocator: psys_options.allocator), every one comes from it instead.
#pragma once

#include <algorithm>
#include <cstddef>
#include <type_traits>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "rt/host_allocator.h"

#include <sys/mman.h>

namespace psys::rt {

template <class T>
struct MappedAllocator {
    using value_type = T;
    // (Arrays keep their allocator when moved or swapped: memory goes back where it came from.)
    using propagate_on_container_move_assignment = std::true_type;
    using propagate_on_container_swap = std::true_type;
    using propagate_on_container_copy_assignment = std::true_type;
    static constexpr size_t kMapped = size_t{1} << 20;  // bytes from which an allocation is a mapping

    HostAllocator host;

    MappedAllocator() = default;
    explicit MappedAllocator(const HostAllocator& h) : host(h) {}
    template <class U>
    MappedAllocator(const MappedAllocator<U>& other) : host(other.host) {}

    T* allocate(size_t n) {
        if (host) return static_cast<T*>(host.take(n * sizeof(T), std::max(alignof(T), alignof(std::max_align_t))));
        if (n * sizeof(T) < kMapped) return std::allocator<T>().allocate(n);
        void* p = ::mmap(nullptr, n * sizeof(T), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
        if (p == MAP_FAILED) throw std::bad_alloc();
        return static_cast<T*>(p);
    }
    void deallocate(T* p, size_t n) {
        if (host) return host.give(p, n * sizeof(T));
        if (n * sizeof(T) < kMapped) return std::allocator<T>().deallocate(p, n);
        ::munmap(p, n * sizeof(T));
    }
    template <class U>
    bool operator==(const MappedAllocator<U>& other) const {
        return host == other.host;
    }
};

template <class T>
using HostArray = std::vector<T, MappedAllocator<T>>;

// Room for `rows` in `v` where the machine gives the address space (else as it was: a
// reservation only spares a later growth its copy).
template <class T>
void reserveRoom(HostArray<T>& v, size_t rows) {
    try {
        v.reserve(rows);
    } catch (const std::bad_alloc&) {
    } catch (const std::length_error&) {
    }
}

// The pages of [data, data + bytes) given memory now (MADV_POPULATE_WRITE, else a write
// to each page of what is there): reserved rows filled later fault no page.
void populatePages(void* data, size_t bytes);

template <class T>
void populateRoom(HostArray<T>& v, size_t rows) {
    if (v.capacity() >= rows) populatePages(v.data(), rows * sizeof(T));
}

// The rows a pool of `rowBytes` a row can ever touch on this machine: its capacity, or as
// many as its physical memory holds (a reservation past them takes address space for rows
// that could never be used).
size_t reservableRows(size_t capacity, size_t rowBytes);

}  // namespace psys::rt
