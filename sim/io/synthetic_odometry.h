// Wheel odometry synthesised from reference poses, for logs that have corrected poses only (fr101,
// fr-campus, or a user's corrected log): `mml-carmen synth-odom`, `mml-eval --synthetic-odometry`
// and the built-in fr101 / fr-campus evaluation all use this one model.
//
// Noise model (AMCL's odometry noise form with α = 0.05 / 0.01): per scan pair
// Δ = ref[i-1] ⊖ ref[i], Δs = |Δ_xy|, Δθ = |wrap(Δ_θ)|; odometry increment = Δ + n with
// n_x, n_y ~ N(0, σ_t²), n_θ ~ N(0, σ_r²), σ_t = 0.05·Δs + 0.01·Δθ (m), σ_r = 0.05·Δθ + 0.01·Δs
// (rad), drawn from fw::RandomStream(seed, 4242). The odometry starts at ref[0]; a robot standing
// still gets no noise. Deterministic per seed.
#pragma once

#include <cstdint>
#include <vector>

#include "firmware/base/se2.h"

namespace sim {

std::vector<fw::Se2d> synthesize_odometry(const std::vector<fw::Se2d>& reference, std::uint64_t seed);

}  // namespace sim
