// The second reference of a log replay: where a `localized` step is beyond a limit (integrity or its
// protection level) against the log reference, the map is asked for the pose that explains the scan
// best near that reference (sim/eval/mml_eval/reference_map_check.h, the rule of mml-eval's whole-log
// figures). The summary then counts the step only if it holds against both references, and counts
// the rest apart: the chained reference is off by degrees where the odometry sample attached to a
// scan is out of step with the laser (aces, intel, mit-killian in fast turns).
#pragma once

#include <vector>

#include "firmware/map/global_map.h"
#include "sim/cli/log_frames.h"
#include "sim/cli/sim_runner.h"

namespace sim {

// Fills StepRecord::map_* for the `localized` steps with a truth that are beyond a limit against it.
// frames[k].scan.scan_id == k (log frames); steps of other scans are left alone. Returns the number
// of steps checked.
std::size_t check_steps_against_map(const fw::GlobalMap& map, const std::vector<Frame>& frames,
                                    std::vector<StepRecord>* steps);

// Marks StepRecord::in_unknown (left out of the availability) where the truth's scan is in an
// unmapped area (sim/eval/mml_eval/unmapped_scan.h, the rule of mml-eval's figures): a log replay has
// no drawn unknown areas. Returns the number of steps marked.
std::size_t mark_unmapped_steps(const fw::GlobalMap& map, const std::vector<Frame>& frames,
                                std::vector<StepRecord>* steps);

}  // namespace sim
