// psys_gpu_bench --host-cache: what sharing the CPU's caches with a software GPU costs the
// host's thread. On llvmpipe the "GPU" is worker threads on the host's own cores: a
// dispatch over 10⁷ particles streams hundreds of megabytes through the caches the host
// thread's code and data live in, so the same host work between two dispatches runs cold.
// This measures that alone, with no psys in it: a thread does a fixed piece of work (a
// small tree walked, 400 KB copied, a few allocations: the kind of work a step's
// bookkeeping does), then wakes one worker a core, each streaming its share of a buffer,
// and blocks until they finish — as llvmpipe's glDispatchCompute does — for buffers from
// none to past the last-level cache. A real GPU has its own memory and caches.
#pragma once

#include <iosfwd>

namespace psys::bench {

// Prints the table; `rounds` rounds a size (the mean counts). Returns 0.
int hostCacheFigures(std::ostream& out, int rounds);

}  // namespace psys::bench
