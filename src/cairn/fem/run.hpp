// `cairn run` for an input with [fem]: the FEM time loop with the same output schedule as the
// MPM runs (history.csv, snapshots, checkpoints) and the same failure handling.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "cairn/sim/run.hpp"

namespace cairn::fem {

RunSummary run(const Config& config, const RunOptions& options);
/// Continue from an FEM checkpoint (see is_checkpoint in fem/output.hpp).
RunSummary restart(const std::filesystem::path& checkpoint, const std::vector<std::string>& overrides,
                   const RunOptions& options);

}  // namespace cairn::fem
