// The benchmark effects written by hand in C++, the references the JIT is measured
// against (docs/performance.md):
//   - SoA: a structure of arrays and one fused update loop per step (`#pragma omp simd`,
//     restrict pointers), the design a performance-minded programmer would write;
//   - AoS: an array of 64-byte "generic particle" structs (position, velocity, colour,
//     age, size, lifetime, …), the design of the tutorials the thesis criticises.
// Both kill by swapping the last particle into the dead one's place and emit new
// particles at the end of the step (age 0, no sub-frame creation times): less exact than
// psys, and cheaper. The update loops are split over threads like psys's pools; killing
// and emitting are serial, as in psys.
#pragma once

#include <cstddef>
#include <memory>
#include <string>

namespace psys::bench {

class HandWritten {
public:
    virtual ~HandWritten() = default;
    virtual void step(float dt) = 0;
    virtual size_t live() const = 0;
    // Bytes each live particle reads and writes per step in the update loop.
    virtual size_t bytesPerUpdate() const = 0;
    void setThreads(unsigned threads) { threads_ = threads; }

protected:
    unsigned threads_ = 1;  // 0: every core
};

// `knob` is the effect's extern: the fountain's population, the fire's rate, the
// fireworks' sparks per rocket per second.
std::unique_ptr<HandWritten> makeHandWritten(const std::string& effect, bool structOfArrays, double knob,
                                             size_t capacity);

}  // namespace psys::bench
