// RBSM — resampling-based scan matching (dissertation Ch. 2, Alg. 1; SPEC §1).
//
// Per match: the particle set is moved by the motion (Alg. 1 l. 2–4), then repeatedly every
// particle is re-sampled from N(x_j, Σ) (l. 10), weighted by the bounded nearest-neighbour
// end-point likelihood w_j ∝ Σ_i δ_ij (Eq. 2.8–2.10), optionally improved by a deterministic
// hill-climbing step (l. 12), and the set is resampled ∝ w (low-variance resampling, l. 16–19),
// until M_eff = 1/Σ w_j² ≥ Δ·M (l. 7, 20) or the iteration cap; Σ ← δ·Σ each round (l. 21). The
// best particle over all rounds is x̂_t (Eq. 2.7); integrate() adds its points to the map (Eq. 2.5–2.6).
//
// Extension of Alg. 1 (issue 15, `refine`, on by default; refine = motion_prior = false is pure
// Alg. 1): x̂_t is polished by a few Gauss–Newton steps of a point-to-line cost against the
// end-point map: each scan point is paired with the line fitted to the occupied cells around it
// (their centroid and principal axis), residual = distance from that line. The particles stop at
// the M_eff rule on a binary grid (their spread is a few cells, the best particle is the best of a
// cloud); the continuous step removes that quantisation. Guard rails: refinement that moves farther
// than refine_max_shift_* (another basin) or finds too few surfaces is discarded (x̂_t of Alg. 1
// stays).
// Second extension (issue 15, `motion_prior`, off by default: firmware/rbsm/README.md says why):
// Eq. 2.8 is flat along a featureless corridor, so the set diffuses metres along it and x̂_t jumps
// inside it; in the first round of each match the weights are multiplied by a wide Gaussian prior
// on the position around the odometry guess (σ = 0.5 m + 0.2·|u|), pruning what the wheels rule out.
//
// Fast without changing what is computed: the bounded NN likelihood is a lookup (EndpointGrid),
// particles are structure-of-arrays, sin/cos are per particle, the weighting loop runs beams outer
// and particles inner (all particles of a beam hit the same few cache lines), weights are integer
// sums (exact, order-independent). Determinism: particles are split into kPartitions fixed
// partitions, each with its own fw::RandomStream; workers of the optional fw::WorkerPool take whole
// partitions, so 1 or N workers give bit-identical results. All storage comes from the arena at
// init; match() and integrate() allocate nothing.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/arena.h"
#include "firmware/base/rng.h"
#include "firmware/base/se2.h"
#include "firmware/base/status.h"
#include "firmware/base/worker_pool.h"
#include "firmware/rbsm/endpoint_grid.h"
#include "firmware/rbsm/scan_matcher.h"
#include "hal/msg/laser_scan.h"

namespace fw {

struct RbsmOptions {
  static constexpr std::uint32_t kMaxParticles = 8192;
  static constexpr std::uint32_t kMaxPoints = hal::LaserScan::kMaxBeams;
  // Fixed work/RNG partitions: independent of the worker count, so results are too.
  static constexpr std::uint32_t kPartitions = 8;

  std::uint32_t num_particles = 1000;  // M (thesis: 1000)
  float sigma_xy2_cells2 = 4.0f;       // Σ0: σ_xx² = σ_yy² in cells² (Eq. 2.11)
  float sigma_psi2_deg2 = 3.0f;        // Σ0: σ_ψψ² in deg²
  float accept_ratio = 0.8f;           // Δ: stop when M_eff ≥ Δ·M (Alg. 1 l. 7)
  float shrink = 0.5f;                 // δ: Σ ← δ·Σ per round (Alg. 1 l. 21), 0 < δ < 1
  std::uint32_t max_iterations = 20;   // cap on resampling rounds
  // Rounds before the M_eff rule may stop; 1 = Alg. 1's rule alone. On an accumulated end-point
  // map the summed weights (Eq. 2.8) are so flat that M_eff ≥ Δ·M already holds after round 1
  // (1.1 rounds/match on average), i.e. the best of one Gaussian cloud; 3 rounds measured on the
  // real logs: fr079 relations error 0.39 m → 0.06 m, intel 6.7 → 5.6 cm (sim/eval/rbsm).
  std::uint32_t min_iterations = 3;
  std::uint32_t min_points = 10;       // fewer valid points → status, no match
  float max_range = 0.0f;              // ignore points farther than this (m); 0 = keep all
  bool hill_climbing = false;          // Alg. 1 l. 12 (deterministic local correction)
  std::uint32_t hill_climb_steps = 3;
  // Noisy-sensor weighting (Eq. 2.12–2.16): w ∝ Σ exp(−hᵀC⁻¹h) instead of Eq. 2.9.
  bool mahalanobis = false;
  float range_sigma = 0.01f;           // m, sensor range noise (P_p)
  float bearing_sigma_deg = 0.1f;      // deg, sensor bearing noise (P_p)
  float map_point_sigma_cells = 0.29f; // map point std (P_q), ≈ cell/√12
  std::uint64_t seed = 1;
  EndpointGridOptions grid;
  // Extension of Alg. 1: point-to-line Gauss–Newton refinement of x̂_t (see the header comment).
  bool refine = true;
  std::uint32_t refine_iterations = 8;
  std::uint32_t refine_radius_cells = 3;   // cells around a point that define its surface (fr079
                                           // short relations: 1 → 4.5 cm, 2 → 3.8, 3 → 3.1, 4 → 3.2)
  std::uint32_t refine_min_cells = 3;      // fewer occupied cells: no surface
  float refine_max_line_ratio = 0.3f;      // λmin/λmax above this: a blob or a corner, no normal
  float refine_gate_cells = 1.5f;          // |residual| beyond this is not the same surface
  float refine_huber_cells = 0.5f;         // Huber loss threshold
  float refine_min_fraction = 0.2f;        // at least this share of the points must find a surface
  float refine_max_shift_cells = 2.0f;     // discard a refinement moving farther than this …
  float refine_max_shift_deg = 2.0f;       // … or turning more than this
  float refine_min_eigen_ratio = 0.05f;    // directions weaker than this × the strongest stay put
  float refine_max_score_loss = 1.0f;      // reject when Σδ (Eq. 2.8) drops by more than this share
  // Extension of Alg. 1: odometry motion prior on the position (see the header comment). In the
  // first round of each match every sampled particle's weight is multiplied by
  // exp(−½ d²/σ²), d its distance from the initial guess (last estimate ⊕ odometry) and
  // σ = prior_sigma_xy_m + prior_sigma_xy_per_m·|u| (u the odometry motion since the last match).
  bool motion_prior = false;
  float prior_sigma_xy_m = 0.5f;
  float prior_sigma_xy_per_m = 0.2f;
  // Weigh the particles with the AVX2 build of the same loop where the CPU has it (x86-64;
  // particle_weights.h): same weights bit for bit, ~40 % less CPU. false = the portable build.
  bool wide_simd = true;

  Status validate() const;
};

class Rbsm final : public ScanMatcher {
 public:
  static std::size_t required_arena_bytes(const RbsmOptions& options);

  // Validates the options once, carves storage from the arena. `pool` (optional) splits the
  // sampling/weighting over its workers; results do not depend on it.
  Status init(const RbsmOptions& options, StartupArena& arena, WorkerPool* pool = nullptr);
  const RbsmOptions& options() const { return options_; }

  const char* name() const override { return "rbsm"; }
  void reset() override;
  Status match(const Point2f* points, std::size_t count, const Se2f& initial_guess, ScanMatchResult* out) override;
  Status integrate(const Point2f* points, std::size_t count, const Se2f& pose, Point2f* new_cells = nullptr,
                   std::size_t capacity = 0, std::size_t* num_new = nullptr) override;

  // Next match starts with all particles at its initial guess (pairwise experiments); otherwise
  // the particle set of the previous match is moved by (last estimate ⊖ initial guess).
  void forget_tracking() { tracking_ = false; }
  void set_worker_pool(WorkerPool* pool) { pool_ = pool; }

  const EndpointGrid& grid() const { return grid_; }
  EndpointGrid& grid() { return grid_; }
  std::uint32_t num_particles() const { return options_.num_particles; }
  Se2f particle(std::uint32_t i) const { return Se2f(x_[i], y_[i], psi_[i]); }
  // Score (Σ δ, in units of 1/255) of one pose against the current map, for tests and tools.
  std::uint32_t score_pose(const Se2f& pose);

 private:
  struct Job;
  static void job_entry(void* context, int worker, int num_workers);
  void run_partition(std::uint32_t partition, float sig_xy, float sig_psi);
  void weigh_block(std::uint32_t begin, std::uint32_t end);
  std::uint32_t weigh_single(float x, float y, float c, float s) const;
  std::uint32_t weigh_mahalanobis(float x, float y, float psi, float c, float s) const;
  void hill_climb(std::uint32_t j, float step_xy, float step_psi);
  void resample(std::uint64_t total);
  void move_particles(const Se2f& guess);  // Alg. 1 l. 2–4 (and this match's motion prior)
  // Extension of Alg. 1: point-to-line Gauss–Newton from `start`; false (and *out = start) when
  // discarded. *used: points paired with a surface at the last step.
  bool refine(const Se2f& start, Se2f* out, std::uint32_t* used) const;
  // Extension of Alg. 1: w_j ← w_j · exp(−½ d_j²/σ²) over [begin, end) (motion_prior).
  void apply_motion_prior(std::uint32_t begin, std::uint32_t end);

  RbsmOptions options_;
  EndpointGrid grid_;
  WorkerPool* pool_ = nullptr;
  bool initialized_ = false;

  // Particle set χ (structure of arrays) and the sampled set of the current round.
  float* x_ = nullptr;
  float* y_ = nullptr;
  float* psi_ = nullptr;
  float* sx_ = nullptr;
  float* sy_ = nullptr;
  float* spsi_ = nullptr;
  float* cos_ = nullptr;
  float* sin_ = nullptr;
  std::uint32_t* w_ = nullptr;

  // Points of the scan being matched (sensor frame), with per-point covariance for Eq. 2.14.
  std::uint32_t num_points_ = 0;
  float px_[RbsmOptions::kMaxPoints] = {};
  float py_[RbsmOptions::kMaxPoints] = {};
  float pcov_[RbsmOptions::kMaxPoints][3] = {};  // P_p (xx, xy, yy) in the sensor frame
  EndpointGrid::LookupView view_{};
  std::uint32_t round_ = 0;                    // resampling round of the current match (1-based)
  Se2f prior_center_;                          // the match's initial guess
  float prior_inv_var_xy_ = 0.0f;              // 1/σ² of the motion prior; 0 = none this match
  float cur_sig_xy_ = 0.0f, cur_sig_psi_ = 0.0f;  // current Σ (m, rad) for Eq. 2.14's P_B

  RandomStream streams_[RbsmOptions::kPartitions];
  RandomStream resample_stream_;
  std::uint32_t part_best_w_[RbsmOptions::kPartitions] = {};
  std::uint32_t part_best_j_[RbsmOptions::kPartitions] = {};

  bool tracking_ = false;
  Se2f last_estimate_;
};

}  // namespace fw
