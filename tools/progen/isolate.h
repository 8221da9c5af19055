// A case run in a child process of its own, so that a crash or a hang in a backend is a
// finding, not the end of the run: the child runs it and writes the finding to a pipe;
// one that dies of a signal is a crash, one that outlives `seconds` a timeout. The parent
// never starts a backend (no GL context, no JIT, no threads: forking is safe).
#pragma once

#include <optional>

#include "tools/progen/runner.h"

namespace psys::progen {

std::optional<Finding> runIsolated(const Case& c, const RunOptions& options, unsigned seconds);

// A crash found with several backends, run again with the interpreter and each of them
// alone: the finding names the one that crashes (or every one, when the interpreter does).
Finding attributeCrash(const Case& c, const RunOptions& options, const Finding& crash, unsigned seconds);

// The smallest case found, by deleting lines of the program (each with the same line of
// the edit), events and frames, that still gives a finding of the same kind on the same
// backend; at most `budget` runs.
Case shrink(const Case& c, const RunOptions& options, const Finding& found, unsigned seconds, int budget);

}  // namespace psys::progen
