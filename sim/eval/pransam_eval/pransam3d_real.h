// pRANSAM 3-D on the real clouds of issue 17 (cloud_draws.h): one Matcher<3> sized once for the
// largest draw (start-up allocation, as on the robot), then per draw set_model(B) + match(A).
// Everything metric is stated in voxels of the draw, so one configuration serves the office (5 cm),
// the car (10 cm), the milk carton (5 mm) and the bunny.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim/eval/pransam_eval/cloud_draws.h"
#include "sim/eval/pransam_eval/cloud_outcome.h"

namespace sim::pransam_eval {

struct Pransam3dConfig {
  std::uint32_t max_iterations = 200000;  // I_max
  float omega_thres = 0.55f;     // reported when the best refined Ω reaches this
  float omega_stop = 1.0f;       // stop early at this Ω (1 = run I_max and keep the best)
  float extent_voxels = 24.0f;   // longest triangle side (relation table extent)
  float eps_hard_voxels = 0.5f;  // ε_h, ε_s in point-resolution units (SPEC: 0.5 / 1.0)
  float eps_soft_voxels = 1.0f;
  float field_voxels = 0.5f;     // contact field cell
  std::uint32_t refine_iterations = 10;
  float refine_min_quality = 0.35f;
  int workers = 2;               // T
  std::uint64_t seed = 1;
};

// Runs every draw on `pool_threads` pool threads (0 = inline). False with *error on a matcher error.
bool run_pransam3d(const std::vector<CloudDraw>& draws, const Pransam3dConfig& config, int pool_threads,
                   MethodRun* out, std::string* error, bool verbose = false);

}  // namespace sim::pransam_eval
