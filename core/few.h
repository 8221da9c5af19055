// Few<T, N>: a call's scratch of n elements, on the stack up to N and on the heap past
// it, so that a launch allocates nothing on whatever thread runs it — a thread's own
// vector (thread_local) did, the first time a thread pool's worker ran a launch, which a
// steady state may meet at any step (tests/capi/allocation_test.cpp). Past N it takes a
// vector of its own, or the caller's (`spill`, kept from call to call: it grows once).
// N stays small (a host's thread may have a small stack). Its elements start
// uninitialized; it is neither copied nor moved (its data may be its own array).
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <vector>

namespace psys::core {

template <class T, size_t N>
class Few {
public:
    explicit Few(size_t n) : size_(n) {
        if (n > N) {
            many_.resize(n);
            data_ = many_.data();
        }
    }
    Few(size_t n, std::vector<T>& spill) : size_(n) {
        if (n > N) {
            if (spill.size() < n) spill.resize(n);
            data_ = spill.data();
        }
    }
    Few(const Few&) = delete;
    Few& operator=(const Few&) = delete;

    T* data() { return data_; }
    const T* data() const { return data_; }
    size_t size() const { return size_; }
    T& operator[](size_t i) { return data_[i]; }
    const T& operator[](size_t i) const { return data_[i]; }
    std::span<T> span() { return {data_, size_}; }
    std::span<const T> span() const { return {data_, size_}; }

private:
    std::array<T, N> few_;
    std::vector<T> many_;
    T* data_ = few_.data();
    size_t size_;
};

}  // namespace psys::core
