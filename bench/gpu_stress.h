// psys_gpu_bench --stress: the hostile shapes of a system, on the GLSL backend (with its
// host side) and on the interpreter, on the wall: a burst chain (each new object emits
// the next in its first update: a wave of one object at a time, up to a pool's
// capacity, in one step) and many object types of one object each (a launch or more
// per type per step, and four or more programs a type to compile).
#pragma once

#include <iosfwd>

namespace psys::bench {

// Prints a table of the two shapes' times; 0, or 1 where a system would not run.
int stressFigures(std::ostream& out, int frames);

}  // namespace psys::bench
