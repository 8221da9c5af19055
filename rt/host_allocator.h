// The host's allocator (psys_options.allocator): where a system's particle memory comes
// from when the host says so. Read by the host memory's columns (rt/host_memory.cpp) and
// the pools' host arrays (rt/host_array.h), kept by every Memory (Memory::allocator).
#pragma once

#include <cstddef>
#include <new>
#include <string>
#include <utility>

namespace psys::rt {

// The host's allocator for a system's particle memory (its columns and its pools' host
// arrays): memory of `bytes` aligned to `alignment`, null when there is none; `release`
// takes back what `allocate` gave, with its size. Unset (both null): the library's own —
// the heap, and anonymous mappings for large arrays. What a compilation or a system's
// bookkeeping takes comes from the heap either way (docs/embedding.md, "Allocator").
struct HostAllocator {
    void* (*allocate)(void* user, size_t bytes, size_t alignment) = nullptr;
    void (*release)(void* user, void* memory, size_t bytes) = nullptr;
    void* user = nullptr;

    explicit operator bool() const { return allocate != nullptr; }
    bool operator==(const HostAllocator&) const = default;
    // `bytes` from the host, aligned to `alignment`: std::bad_alloc where it gives none.
    void* take(size_t bytes, size_t alignment) const;
    void give(void* memory, size_t bytes) const { release(user, memory, bytes); }
};

// What HostAllocator::take throws: std::bad_alloc, saying what the host's allocator did.
struct HostOutOfMemory : std::bad_alloc {
    explicit HostOutOfMemory(std::string m) : message(std::move(m)) {}
    const char* what() const noexcept override { return message.c_str(); }
    std::string message;
};

}  // namespace psys::rt
