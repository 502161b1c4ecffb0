// The MCL configurations the product ships (start-up builder firmware/app/system.h), shared by the
// firmware and the host tools so that what runs on the robot is what was measured.
#pragma once

#include <cstdint>

#include "firmware/baselines/mcl/mcl_options.h"

namespace fw {
namespace mcl {

// The thesis's baseline for global localization: beam model on 18 beams; `particles` 15k–120k.
inline MclOptions mcl_baseline_options(std::uint32_t particles, std::uint64_t seed) {
  MclOptions o;
  o.num_particles = particles;
  o.model = SensorModel::kBeam;
  o.num_beams = 18;
  o.seed = seed;
  return o;
}

// Tracking filter after the MML → MCL hand-off (few particles, likelihood field, many beams).
// 1000 particles × 30 beams: with 500 × 60 the cloud slid 0.5 m during an in-place turn in intel's
// centre room and in an aces corridor (bench of 2026-11-22); 2000 × 60 fixed both at 3.5 ms.
inline MclOptions mcl_tracking_options(std::uint64_t seed) {
  MclOptions o;
  o.num_particles = 1000;
  o.model = SensorModel::kLikelihoodField;
  o.num_beams = 30;
  o.lf_sigma_m = 0.08f;
  o.alpha1 = o.alpha3 = 0.05f;
  o.alpha2 = o.alpha4 = 0.02f;
  o.resample_neff_ratio = 0.5f;
  o.seed = seed;
  return o;
}

}  // namespace mcl
}  // namespace fw
