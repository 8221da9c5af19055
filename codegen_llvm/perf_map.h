// Names for the JIT's machine code in profiles: perf reads /tmp/perf-<pid>.map (one line
// per function: start address, size, name, in hex) to name addresses that belong to no
// file. With PSYS_PERF_MAP=1 in the environment, every function the JIT links is written
// there as it is linked, so `perf record` / `perf report` on psysc, psys-view or a
// benchmark shows `fountain.drop.update.loop` where it would show a bare address.
#pragma once

#include <memory>
#include <string>

namespace llvm::orc {
class LLJIT;
}

namespace psys::codegen_llvm {

// Whether the environment asks for the map (PSYS_PERF_MAP set and not "0").
bool perfMapRequested();

// Registers the writer with `jit`'s linking layer: every function linked from now on is
// appended to `path` (default /tmp/perf-<pid>.map). Returns false, with the reason, when
// the layer is not JITLink's (no symbol sizes to write) or the file cannot be opened.
bool addPerfMap(llvm::orc::LLJIT& jit, std::string& error, std::string path = {});

}  // namespace psys::codegen_llvm
