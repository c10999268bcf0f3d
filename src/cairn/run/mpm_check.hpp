// `cairn check` for the MPM and WLS engines: the grid, the particles of every body, what sets
// the time step, and the estimated steps and wall time from a few timed steps.
#pragma once

#include "cairn/config/config.hpp"

namespace cairn {

/// Print the report on stdout (lines starting with '#').
void describe_mpm(const Config& config);

}  // namespace cairn
