// Monte Carlo localization — the thesis's baseline (App. A, Sec. 5.7.2): sample the odometry
// motion model, weight with a beam model on 18 beams (expected ranges by ray casting through the
// distance image) or a likelihood field, low-variance resampling, optional KLD-sampling and
// random-particle injection. Particles live in fixed arrays (kMaxParticles); the object is meant
// to be placed in static storage. Parallel over fw::WorkerPool in kChunks fixed chunks with one
// RandomStream each, so same seed ⇒ same result for any worker count.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/ring_buffer.h"
#include "firmware/base/rng.h"
#include "firmware/base/se2.h"
#include "firmware/base/status.h"
#include "firmware/base/worker_pool.h"
#include "firmware/baselines/mcl/map_view.h"
#include "firmware/baselines/mcl/mcl_options.h"
#include "hal/msg/laser_scan.h"

namespace fw {
namespace mcl {

struct Particle {
  float x = 0.0f, y = 0.0f, theta = 0.0f;
  float log_w = 0.0f;   // accumulated log weight since the last resampling (max-normalised)
  float step_lw = 0.0f; // this step's sensor log-likelihood
};

struct MclStepResult {
  Se2f pose;
  Eigen::Matrix3f cov = Eigen::Matrix3f::Identity();
  bool localized = false;
  bool resampled = false;
  std::uint32_t particles = 0;
  float best_distance_var = -1.0f;  // the thesis's constraint value (−1: window not full)
  float mean_beam_log_likelihood = 0.0f;  // weighted mean per-beam log-likelihood (collapse test)
  float neff = 0.0f;
  float mass_near_best = 0.0f;  // weight fraction within estimate_radius_m of the best particle
  std::uint32_t injected = 0;
};

class Mcl {
 public:
  Mcl() = default;
  Mcl(const Mcl&) = delete;
  Mcl& operator=(const Mcl&) = delete;

  // `pool` may be null (single-threaded). The map must outlive the filter.
  Status init(const MclOptions& options, const MapView& map, WorkerPool* pool);
  // Back to the state after init() (no particles; streams as freshly seeded; counters zero).
  void reset();
  // Uniform over the free cells (global localization).
  Status init_uniform();
  // Gaussian around a pose (hand-off from MML / tracking).
  Status init_gaussian(const Se2f& pose, const Eigen::Matrix3f& cov);
  // One filter step (motion + sensor update, resampling when due): `odom_delta` is the odometry
  // motion since the previous step (robot frame), `have_delta` false on the first step after an
  // init (no motion update). Always updates; the update gate (options().update_min_d / _a) is
  // applied by MclLocalizer, which accumulates the odometry of gated scans into the next delta.
  Status step(const hal::LaserScan& scan, const Se2f& odom_delta, bool have_delta, MclStepResult* out);

  std::size_t size() const { return n_; }
  const Particle* particles() const { return particles_; }
  const MclOptions& options() const { return options_; }
  // Sensor updates (step() calls) and resamplings since init() / reset().
  std::uint64_t updates() const { return updates_; }
  std::uint64_t resamples() const { return resamples_; }
  static std::size_t storage_bytes() { return sizeof(Mcl); }

 private:
  struct Beam {
    float range, angle;
  };
  static void motion_job(void* ctx, int worker, int num_workers);
  static void weight_job(void* ctx, int worker, int num_workers);
  void motion_chunk(std::size_t chunk);
  void weight_chunk(std::size_t chunk);
  void chunk_range(std::size_t chunk, std::size_t* b, std::size_t* e) const;
  void run_chunks(WorkerPool::JobFn fn);
  Status sample_free(RandomStream* rng, Particle* p);
  void resample(MclStepResult* out);
  std::uint32_t kld_bound(std::uint32_t bins) const;
  void estimate(std::size_t best, MclStepResult* out) const;

  MclOptions options_;
  MapView map_;
  WorkerPool* pool_ = nullptr;
  bool initialized_ = false;

  Particle particles_[kMaxParticles];
  Particle scratch_[kMaxParticles];
  double cdf_[kMaxParticles];
  std::uint64_t kld_keys_[2 * kMaxParticles];  // open-addressing set of occupied bins
  std::size_t n_ = 0;

  Beam beams_[kMaxBeams];
  std::size_t num_beams_ = 0;
  Se2f delta_;
  bool apply_motion_ = false;
  std::uint64_t step_count_ = 0;
  RandomStream main_rng_;
  double chunk_max_[kChunks];

  float w_slow_ = 0.0f, w_fast_ = 0.0f;
  bool have_best_prev_ = false;
  Se2f best_prev_;
  RingBuffer<float, kMaxConstraintWindow> best_dist_;
  std::uint64_t updates_ = 0, resamples_ = 0;
};

}  // namespace mcl
}  // namespace fw
