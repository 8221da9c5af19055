// GL debug output (KHR_debug, core since 4.3): the GL's own word on an error or on
// undefined behaviour, counted process-wide. The GPU tests ask for debug contexts and
// fail a test during which any such message arrived; PSYS_GL_DEBUG=1 asks for them in
// psysc, the viewer and the benchmarks too, and prints each message on stderr.
#pragma once

#include <cstdint>
#include <string>

namespace psys::gpu {

// Contexts the GPU backend makes from now on are debug contexts, with the callback below
// installed (also on a context it is handed, where the GL lets debug output on there).
// On by PSYS_GL_DEBUG=1.
void requestDebugOutput(bool on);
bool debugOutputRequested();

// Installs the callback on the current context and turns debug output on (synchronous:
// a message arrives inside the call that caused it). False where the GL has no KHR_debug.
bool installDebugOutput();

// Messages of type error or undefined behaviour received so far, and the latest one's text.
uint64_t glErrorMessages();
std::string lastGlErrorMessage();

}  // namespace psys::gpu
