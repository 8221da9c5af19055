// `psysc --stats FILE`: what each object type costs per update, without and with the
// optimizer, and under each integration method.
#pragma once

#include <optional>
#include <string>

#include "core/integrators.h"

namespace psys::tools {

// `everyObject`: the method every object is compiled with (psysc --integrator), if any.
// Returns the process exit status.
int printStats(const std::string& file, std::optional<core::Integrator> everyObject, bool colour);

}  // namespace psys::tools
