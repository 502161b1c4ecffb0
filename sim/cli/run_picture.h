// run.svg and run.png of an mml-sim run: the map, ground truth, the estimate coloured by status,
// protection levels, integrity failures, the last hypotheses and the summary as notes.
#pragma once

#include <string>

#include "sim/cli/sim_runner.h"
#include "sim/io/ros_map.h"
#include "sim/world/world.h"

namespace sim {

// world: the synthetic world (its unknown areas are drawn), nullptr for a log; grid: nullptr
// without a map (the picture is then framed on the world). False with *err naming the file.
bool write_pictures(const SimConfig& cfg, const SimResult& r, const World* world, const OccupancyGrid* grid,
                    std::string* err);

}  // namespace sim
