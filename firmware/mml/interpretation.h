// MML hypothesis interpretation (dissertation Sec. 5.3): filter (Eq. 5.3) → hierarchical K-means
// clustering (5.3.1) → rating r' and r (Eq. 5.4–5.7) → the three localization constraints
// (Eq. 5.8–5.17) with the soft rule (Eq. 5.22) → adaptive matching threshold by Bollinger bands
// (Eq. 5.18–5.21) → unknown-region test on Ω' (Eq. 5.37, contact values supplied by the caller
// because they need the local map and the global map).
// Pure computation on fixed storage: no map, no matcher, so it is unit-tested on synthetic sets.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/ring_buffer.h"
#include "firmware/base/se2.h"
#include "firmware/base/status.h"
#include "firmware/mml/mml_options.h"
#include "hal/msg/pose_estimate.h"

namespace fw {
namespace mml {

// One pose hypothesis from pRANSAM, reduced to the plane and expressed as the robot pose in the map
// (H ⊕ robot pose in the local map; pransam::Hypothesis is the transform H it comes from), so clusters and Eq. 5.8–5.14 live in robot-pose space.
// roll/pitch are the rotations of the matched triangle frames about x and y (0 for a proper 2-D
// match, π for a flipped one, Eq. 5.3).
struct PoseHypothesis {
  float x = 0.0f, y = 0.0f, theta = 0.0f;  // robot pose in the map
  float quality = 0.0f;                    // Ω ∈ [0, 1] (Eq. 4.7)
  float roll = 0.0f, pitch = 0.0f;
};

struct Cluster {
  std::uint32_t begin = 0, end = 0;   // range in the interpreter's (permuted) hypothesis array
  float x = 0.0f, y = 0.0f, theta = 0.0f;  // mean (circular mean for θ)
  float sxx = 0.0f, syy = 0.0f, sxy = 0.0f, srr = 0.0f;  // variances (m², rad²)
  float mean_quality = 0.0f;
  float rating_raw = 0.0f;  // r' (Eq. 5.6)
  float rating = 0.0f;      // r  (Eq. 5.7)
  std::uint32_t size() const { return end - begin; }
};

struct InterpretInput {
  const PoseHypothesis* hypotheses = nullptr;
  std::size_t count = 0;
  Se2f odom_delta;       // robot motion since the previous interpretation (odometry, robot frame)
  bool have_odom_delta = false;  // false on the first step after reset
};

struct InterpretResult {
  hal::LocalizationStatus status = hal::LocalizationStatus::kSearching;
  Se2f pose;                                  // best-cluster pose (map ← local map)
  Eigen::Matrix3f cov = Eigen::Matrix3f::Identity();
  std::uint32_t hypotheses_in = 0, hypotheses_valid = 0, cluster_count = 0;
  float best_rating = 0.0f;
  float d2 = -1.0f;          // Mahalanobis distance of Eq. 5.14 (−1: not available)
  float sigma_med = -1.0f;   // Eq. 5.16 (−1: too few samples)
  bool c_rating = false, c_mahalanobis = false, c_median = false, soft = false;
  std::uint32_t pooled_support = 0;  // best-cluster members pooled over the consistent run (extension)
  float omega_thres_next = 0.7f;  // matching threshold for the next pRANSAM call (Eq. 5.21)
  float omega_unknown = -1.0f;    // Ω' of Eq. 5.37 (−1: not evaluated)
  bool have_pose = false;
};

class Interpreter {
 public:
  Status init(const MmlOptions& options);
  void reset();

  // One localization step. Hypotheses are copied (fixed capacity kMaxHypotheses; the excess is
  // counted, not stored).
  Status interpret(const InterpretInput& in, InterpretResult* out);

  // Eq. 5.37: the caller reports Ω', the mean contact fraction of the points of the last
  // `observations` (≤ τ_up) observations under the current best hypothesis. Call after
  // interpret(). Sets out->status to outside-map when Ω' collapsed below the option threshold.
  void report_unknown(float omega_prime, std::uint32_t observations, InterpretResult* out);

  // Replaces x_prev of Eq. 5.8 (the localizer refines the published pose against the map).
  void set_previous_pose(const Se2f& pose) { prev_pose_ = pose; }
  // Leaves the soft mode of Eq. 5.22: the next `localized` needs the hard criterion again.
  void drop_soft() { soft_active_ = false; }
  float omega_thres() const { return omega_thres_; }
  const Cluster* clusters() const { return clusters_; }
  std::size_t cluster_count() const { return num_clusters_; }
  const PoseHypothesis* hypotheses() const { return hyps_; }
  bool localized_before() const { return soft_active_; }
  const MmlOptions& options() const { return options_; }

  // Exposed for tests.
  static float circular_mean(const float* angles, std::size_t n);

 private:
  void filter(const InterpretInput& in, InterpretResult* out);
  void cluster_all();
  void compute_stats(Cluster* c) const;
  bool split(const Cluster& c, bool by_rotation, Cluster* a, Cluster* b);
  void rate();
  void update_threshold();
  Eigen::Matrix3f cluster_cov(const Cluster& c) const;

  MmlOptions options_;
  bool initialized_ = false;

  PoseHypothesis hyps_[kMaxHypotheses];
  std::uint8_t labels_[kMaxHypotheses];
  std::size_t num_hyps_ = 0;
  Cluster clusters_[kMaxClusters];
  std::size_t num_clusters_ = 0;
  Cluster stack_[kMaxClusters];

  // Previous best cluster (x_prev, P_prev of Eq. 5.8–5.9).
  bool have_prev_ = false;
  Se2f prev_pose_;
  Eigen::Matrix3f prev_cov_ = Eigen::Matrix3f::Identity();

  RingBuffer<float, kMaxMedianWindow> d2_window_;
  RingBuffer<float, kMaxThresholdWindow> step_quality_window_;  // per-step mean Ω (Eq. 5.18)
  RingBuffer<float, kMaxThresholdWindow> thres_window_;         // Ω_thres(t) (Eq. 5.19–5.20)
  float omega_thres_ = 0.7f;
  bool soft_active_ = false;
  std::uint32_t blind_steps_ = 0;
  std::uint32_t consistent_streak_ = 0;  // consecutive steps meeting d² and σ_med (entry confirmation)
  std::uint32_t pooled_support_ = 0;     // best-cluster members pooled over consistent steps
};

}  // namespace mml
}  // namespace fw
