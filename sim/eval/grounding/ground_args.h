// Command line of mml-ground (and the options bench_ground uses).
#pragma once

#include <string>
#include <vector>

#include "sim/eval/grounding/grounding.h"

namespace sim::ground {

struct GroundArgs {
  GroundOptions opt;
  std::string out_dir = "build/bench";  // ground.json, ground.md, ground.svg
  bool help = false;
};

extern const char* const kGroundUsage;

// False with *err naming the bad argument.
bool parse_ground_args(const std::vector<std::string>& args, GroundArgs* out, std::string* err);

// Runs the measurement and writes <out_dir>/ground.{json,md,svg}. Returns the exit status.
int run_ground(const GroundArgs& a, const char* tool);

}  // namespace sim::ground
