// DistanceBatch: the bilinear distance-field samples (distance_sample.h) of up to kDistanceBatch
// end-points under one pose, computed for all of them at once — the inner loop of the pose
// refiners (firmware/mml/pose_refiner.cpp: ~70 000 samples per tracked scan in the tracker's alias
// check, 85 % of a tracking step).
//
// The arithmetic of a sample (~70 of the ~130 scalar instructions an end-point cost in the refiner)
// runs in vectorised loops over the batch — 4 lanes portable (SSE2, NEON), 8 with AVX2 on x86-64
// (chosen at run time, as particle_weights.h) — and only the tiled field's look-ups one point at a
// time. Each lane does DistanceSampler's IEEE operations in its order, no fused multiply-add (the
// build has -ffp-contract=off; AVX2 does not imply FMA), so every build gives the scalar sampler's
// bits (distance_batch_test) and a run gives the same output on every machine.
// Measured (mml-eval --localize --whole-runs 1, tracked-scan step p50): intel 1.95 → 1.33 ms, fr079
// 2.47 → 1.52 ms, aces 2.02 → 1.38 ms (README "Real time"). A branch-free scalar sampler was 25 %
// slower than the branchy one, and AVX2 gathers of every look-up no faster than scalar loads on the
// AMD EPYC measured: the look-ups stay scalar.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/se2.h"
#include "firmware/map/global_map.h"

namespace fw {

inline constexpr std::size_t kDistanceBatch = 64;

// Per end-point i < n: d, gx, gy exactly as DistanceSampler<float> at (x, y) = (tx + c·px − s·py,
// ty + s·px + c·py), jt = gx·(−s·px − c·py) + gy·(c·px − s·py) (the heading column of the
// point-to-line Jacobian, PointToLineSystem::add's expression), and use[i] = 1 when the sample is on
// the grid and d ≤ clip_m, else 0 (then d, gx, gy, jt are meaningless). Arrays of ≥ n entries.
struct DistanceBatch {
  alignas(32) float d[kDistanceBatch];
  alignas(32) float gx[kDistanceBatch];
  alignas(32) float gy[kDistanceBatch];
  alignas(32) float jt[kDistanceBatch];
  alignas(32) std::uint8_t use[kDistanceBatch];
};

// Which build runs: the best this CPU has (AVX2 where available, else the portable vectorised
// loops), the portable one, or DistanceSampler point by point (the reference the tests compare with).
enum class DistanceBatchBuild : std::uint8_t { kBest, kPortable, kScalar };

// n ≤ kDistanceBatch (larger n is cut to it).
void sample_distance_batch(const GlobalMap& map, const Point2f* points, std::size_t n, float tx, float ty, float c,
                           float s, float clip_m, DistanceBatch* out, DistanceBatchBuild build = DistanceBatchBuild::kBest);

// True when kBest runs the AVX2 build here.
bool wide_distance_batch_available();

}  // namespace fw
