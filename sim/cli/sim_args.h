// Command-line parsing of mml-sim (separate from main so tests can feed it malformed arguments).
#pragma once

#include <string>
#include <vector>

#include "sim/cli/sim_runner.h"

namespace sim {

enum class SimArgsAction { kRun, kHelp, kList };

// False with *err naming the offending argument and what was expected.
bool parse_sim_args(const std::vector<std::string>& args, SimConfig* cfg, SimArgsAction* action, std::string* err);
std::string sim_usage();
std::string sim_list();  // worlds and localizers

}  // namespace sim
