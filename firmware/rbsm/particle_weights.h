// Summed end-point weights of many particles at once (Eq. 2.8 with the quantised δ of Eq. 2.9):
// the inner loop of RBSM (Alg. 1 l. 11), 80 % of its CPU time.
//
// Beams outer, particles inner. Per chunk of particles the window-relative sub-cell coordinates are
// precomputed; pass 1 (branch-free float/int arithmetic, vectorised) turns each point into a lookup
// index (the zero sentinel when outside the window), pass 2 gathers and accumulates.
//
// Two builds of the same loop: the portable one (SSE2 on x86-64, NEON on aarch64) and, on x86-64,
// one compiled for AVX2 (8 lanes instead of 4), chosen at run time when the CPU has AVX2 (fr079:
// 2.34 → 1.37 ms CPU per scan). Both use only IEEE multiplies, adds, compares and truncations —
// no fused multiply-add (AVX2 does not imply FMA, so nothing is contracted) — so they give the same
// weights bit for bit (particle_weights_test) and results do not depend on the machine.
#pragma once

#include <cstdint>

#include "firmware/rbsm/endpoint_grid.h"

namespace fw {

// Particles [begin, end) as structure of arrays (positions, cos/sin of the heading); weights out.
struct ParticleBlock {
  const float* x = nullptr;
  const float* y = nullptr;
  const float* cos = nullptr;
  const float* sin = nullptr;
  std::uint32_t* weights = nullptr;
  std::uint32_t begin = 0, end = 0;
};

// True when this CPU runs the AVX2 build (x86-64 with AVX2); false elsewhere.
bool wide_particle_weights_available();

// weights[j] = Σ_i δ(T_j · p_i) over the scan points (px, py), T_j = particle j. `allow_wide` = false
// forces the portable build (tests, or a user pinning the arithmetic path). Never allocates.
void weigh_particles(const EndpointGrid::LookupView& view, const float* px, const float* py, std::uint32_t num_points,
                     const ParticleBlock& block, bool allow_wide);

}  // namespace fw
