// MmlLocalizer: MML global localization behind the fw::Localizer seam (dissertation Ch. 5).
// Per scan: RBSM scan-matching odometry integrates the scan into the local map (fragments) →
// pRANSAM (collect-all) matches the local map to the global map with the adaptive threshold →
// hypotheses become robot poses in the map (H ⊕ x_local) → Interpreter (filter, clustering,
// rating, constraints, Bollinger) → unknown-region test Ω' over the last τ_up observations
// (Eq. 5.37) → PoseEstimate (searching / ambiguous / localized / outside-map).
// Options: local map correction (Eq. 5.23–5.27, local_map_correction.h) moves the newest fragments
// onto the global map while the best cluster passes the rating test; the corrections live in the
// LocalMap's fragments (T_i), RBSM keeps tracking in its own uncorrected frame, and MML uses the
// robot pose in the corrected local map (C_N ⊕ RBSM pose, C_N the newest fragment's correction as
// a local-map transform). Local map reduction (Eq. 5.28–5.30, observation_reduction.h) matches only
// accepted observations plus the two newest instead of the fragments' points.
// All storage comes from the StartupArena given to init() or is a fixed member; step() allocates
// nothing. Place the object in static storage (it holds the interpreter's fixed arrays).
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/arena.h"
#include "firmware/base/perf_counter.h"
#include "firmware/base/worker_pool.h"
#include "firmware/map/global_map.h"
#include "firmware/map/unmapped_space.h"
#include "firmware/mml/interpretation.h"
#include "firmware/mml/local_map_correction.h"
#include "firmware/mml/mml_options.h"
#include "firmware/mml/observation_reduction.h"
#include "firmware/mml/pose_refiner.h"
#include "firmware/mml/pose_uniqueness.h"
#include "firmware/mml/rival_memory.h"
#include "firmware/pransam/matcher.h"
#include "firmware/local_map/local_map.h"
#include "firmware/rbsm/rbsm.h"
#include "firmware/rbsm/scan_matching_odometry.h"
#include "firmware/runtime/localizer.h"

namespace fw {
namespace mml {

struct MmlLocalizerConfig {
  MmlOptions mml;
  RbsmOptions rbsm;
  LocalMapOptions local_map;
  ScanMatchingOdometryOptions front_end;
  pransam::MatcherOptions matcher;
  pransam::MatchParams match;  // seed / iterations / threshold are overwritten per step from `mml`
  Status validate() const;
};

// Defaults for a SICK-class 2-D laser and a 5 cm global map.
MmlLocalizerConfig default_mml_config();

// Fills the matcher's global relation table R_B as MML does when the map image has none (Theorem 2,
// h = config.mml.table_triples). The one definition of that fill: mml-mapc --relation-table calls it
// too, so an offline table equals the start-up one.
Status fill_global_relation_table(const MmlLocalizerConfig& config, pransam::Matcher<2>* matcher);

// Observation points kept per step for Eq. 5.37.
constexpr std::size_t kUnknownPointsPerObservation = 48;

class MmlLocalizer final : public Localizer {
 public:
  // `table_section` (optional, may be null): a precomputed relation table section of the map image
  // (pransam relation_table_io.h) used when config.mml.precomputed_table is set.
  // `work` (optional): the working memory — RBSM's end-point grid and particles, the local map,
  // pRANSAM's R_A, scene index and worker buffers, the scene and hypothesis arrays — whose size
  // depends on the config alone. Several localizers of which one runs at a time (one per map:
  // firmware/app/map_set.h) give the same block; the map's parts stay in `arena`. Null = `arena`.
  Status init(const MmlLocalizerConfig& config, const GlobalMap& map, const std::uint8_t* table_section,
              std::size_t table_len, StartupArena& arena, WorkerPool* pool, StartupArena* work = nullptr);
  // Upper bound of what init() takes from `work` (alignment included).
  static std::size_t working_bytes(const MmlLocalizerConfig& config);
  // Another localizer has used the shared working memory since this one's last reset(): the next
  // reset() wipes all of it (RBSM's grid, R_A), not only what this one wrote. Call before reset().
  void mark_working_memory_foreign() {
    rbsm_.grid().mark_storage_foreign();
    matcher_.mark_working_memory_foreign();
  }
  const char* name() const override { return "mml"; }
  void reset() override;
  Status step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) override;
  // The hypothesis "the robot is in the map's unmapped space" (map/unmapped_space.h) beside the
  // mapped poses: while on, pRANSAM counts a point there as contact. Off by default (the
  // dissertation: unknown is a miss); mml-track holds it on until the robot is first located
  // (tracked_localizer.cpp). A no-op on a map without unmapped space.
  void set_unmapped_hypothesis(bool on) { matcher_.set_unmapped_active(on); }
  bool unmapped_hypothesis() const { return matcher_.unmapped_active(); }
  const UnmappedSpace& unmapped_space() const { return unmapped_; }

  // For visualisation / evaluation.
  const Interpreter& interpreter() const { return interp_; }
  const InterpretResult& last() const { return last_; }
  std::size_t local_map_points() const { return num_scene_; }
  // Points handed to pRANSAM in the last step (0 when it did not match).
  std::size_t matched_points() const { return matched_points_; }
  const RefineResult& last_refine() const { return last_refine_; }
  // Uniqueness test of the last step that would have entered `localized` (pose_uniqueness.h).
  const UniquenessResult& last_uniqueness() const { return last_unique_; }
  std::uint32_t uniqueness_rejections() const { return unique_rejections_; }
  // Rival memory (rival_memory.h): the check of the last step that would have entered `localized`,
  // entries held, and how often a remembered rival kept the status `ambiguous`.
  const RivalCheck& last_rival_check() const { return last_rival_; }
  std::size_t rivals_remembered() const { return rivals_.size(); }
  std::uint32_t rival_rejections() const { return rival_rejections_; }
  // Candidates isolated later, once the growing local map contradicted the rivals that held them back.
  std::uint32_t pending_isolations() const { return pending_isolations_; }
  // Stage timing (timed only in deadline mode, by its clock): front end + scene (before pRANSAM),
  // pRANSAM, and everything after it (interpretation, published pose, the integrity checks). They
  // describe the CPU, not the search: reset() keeps them (a live search is reset on every doubt).
  const PerfCounter& front_end_perf() const { return perf_front_end_; }
  const PerfCounter& match_perf() const { return perf_match_; }
  const PerfCounter& after_match_perf() const { return perf_after_match_; }
  std::uint32_t front_end_failures() const { return front_end_failures_; }
  bool using_precomputed_table() const { return matcher_.has_precomputed_table(); }
  const LocalMap& local_map() const { return local_map_; }
  // Local map correction: fragment corrections applied since reset, the last attempt.
  std::uint32_t corrections_applied() const { return corrections_applied_; }
  const CorrectionResult& last_correction() const { return last_correction_; }
  // Local map reduction: observations accepted since reset / currently kept.
  std::uint32_t observations_accepted() const { return observations_accepted_; }
  std::size_t observations_kept() const { return red_count_; }
  // Anytime mode (issue 14; pRANSAM deadline mode, Sec. 4.4.3): pRANSAM's iterations end
  // pransam_share of `step_budget_ns` after the step began (the rest is left for the front end
  // before and the interpretation after it). clock null = off (every step runs I_max: the
  // reproducible default). Kept across reset().
  void set_deadline_mode(const hal::Clock* clock, std::uint64_t step_budget_ns, float pransam_share = 0.6f) {
    deadline_clock_ = clock;
    deadline_budget_ns_ = step_budget_ns;
    deadline_share_ = pransam_share;
  }
  // The budget of the next steps, the mode unchanged (the global context's measured window).
  void set_deadline_budget(std::uint64_t step_budget_ns) { deadline_budget_ns_ = step_budget_ns; }
  std::uint64_t deadline_stops() const { return deadline_stops_; }  // pRANSAM runs cut by the deadline
  // pRANSAM's rounds in the last step when its deadline stopped it, else 0 (issue 60: recorded in
  // the black box with the global result).
  std::uint32_t last_deadline_rounds() const { return last_deadline_rounds_; }
  // Replay of a recorded step (issue 60): the next step's pRANSAM stops after `rounds` rounds as
  // its deadline did on the robot (0 = runs as configured). Overwritten by the next call.
  void force_deadline_rounds(std::uint32_t rounds) { forced_deadline_rounds_ = rounds; }

 private:
  // The stages of step() (mml_localizer.cpp), in order.
  Status front_end_stage(const hal::LaserScan& scan, const hal::Odometry& odom, Se2f* rbsm_pose, Se2f* local_pose,
                         bool* used);
  void remember_observation(const hal::LaserScan& scan, const Se2f& local_pose);
  Status local_map_stage(const Se2f& rbsm_pose, bool* enough);
  std::size_t global_match_stage(const Se2f& local_pose, std::uint64_t step_begin_ns, float* omega_thres);
  Status interpretation_stage(std::size_t nh, float omega_thres, const Se2f& odom_delta);
  void published_pose_stage(const Se2f& odom_delta, const Se2f& local_pose);
  bool isolation_confirmed(const Se2f& local_pose);
  bool refined_pose_unique(const Point2f* pts, std::size_t m, const RefineOptions& ro);
  void recheck_pending(const Se2f& local_pose, const Point2f* pts, std::size_t m);
  void publish(hal::PoseEstimate* out);
  Status gather_local_map();
  Status gather_reduced_map();
  // Reduction storage: a ring of accepted observations, each in its fragment's frame.
  struct ReducedObservation {
    std::uint32_t fragment_id = 0;
    std::uint32_t n = 0;
    Point2f* pts = nullptr;  // arena, reduction_observation_points
  };
  void capture_observation(const Se2f& rbsm_pose);
  void accept_observation(const ReducedObservation& ob);
  void append_observation(const ReducedObservation& ob, std::size_t stride, std::size_t* k);
  void correct_local_map(const Se2f& mml_pose);
  Se2f corrected_pose(const Se2f& rbsm_pose) const;
  float unknown_contact(const Se2f& h_map_from_local) const;

  MmlLocalizerConfig config_;
  GlobalMap map_;
  bool initialized_ = false;

  Rbsm rbsm_;
  LocalMap local_map_;
  ScanMatchingOdometry front_end_;
  pransam::Matcher<2> matcher_;
  UnmappedSpace unmapped_;  // labels in the start-up arena
  Interpreter interp_;
  InterpretResult last_;

  Point2f* scene_ = nullptr;  // local map points in the local (scan-matcher) frame, arena
  std::size_t num_scene_ = 0;
  std::size_t matched_points_ = 0;
  std::size_t scene_capacity_ = 0;
  PoseHypothesis* hyps_ = nullptr;  // arena, kMaxHypotheses

  // Eq. 5.37: the last τ_up observations (subsampled scan points in the local frame).
  struct Observation {
    Point2f pts[kUnknownPointsPerObservation];
    std::uint32_t n = 0;
  };
  RingBuffer<Observation, kMaxUnknownWindow> observations_;
  Point2f scan_pts_[hal::LaserScan::kMaxBeams];
  std::size_t num_scan_pts_ = 0;

  bool have_h_ = false;
  Se2f last_h_;  // map ← local of the best hypothesis
  std::uint64_t steps_ = 0;
  std::uint32_t front_end_failures_ = 0;
  std::uint32_t no_match_steps_ = 0;
  // Published pose tracking (pose_refiner.h).
  bool have_wheel_ = false;
  Se2f prev_wheel_;
  bool tracked_valid_ = false;
  Se2f tracked_pose_;
  std::uint32_t tracked_bad_steps_ = 0, tracked_unlocalized_steps_ = 0;
  Point2f refine_pts_[1081];
  RefineResult last_refine_;
  UniquenessResult last_unique_;
  std::uint32_t unique_rejections_ = 0;
  RivalMemory rivals_;
  RivalCheck last_rival_;
  std::uint32_t rival_rejections_ = 0;
  // A candidate held back only by open rivals (map ← local map), re-checked as the local map grows.
  bool pending_ = false;
  Se2f pending_h_;
  Eigen::Matrix3f pending_cov_ = Eigen::Matrix3f::Identity();
  std::uint32_t pending_steps_ = 0;
  std::uint32_t pending_isolations_ = 0;
  hal::PoseEstimate last_out_;
  PerfCounter perf_front_end_{"mml.front_end"};
  PerfCounter perf_match_{"mml.pransam"};
  PerfCounter perf_after_match_{"mml.after_match"};
  const hal::Clock* deadline_clock_ = nullptr;
  std::uint64_t deadline_budget_ns_ = 0;
  float deadline_share_ = 0.6f;
  std::uint64_t deadline_stops_ = 0;
  std::uint32_t last_deadline_rounds_ = 0, forced_deadline_rounds_ = 0;

  // Local map correction (Eq. 5.23–5.27).
  Point2f corr_pts_[kMaxCorrectionPoints];
  bool have_newest_ = false;
  std::uint32_t newest_id_ = 0;
  std::uint32_t corrections_applied_ = 0;
  CorrectionResult last_correction_;

  // Local map reduction (Eq. 5.28–5.30).
  ReductionRule rule_{2.0f, 4.0f, 20};
  ReducedObservation red_[kMaxReducedObservations];
  std::size_t red_head_ = 0, red_count_ = 0;
  ReducedObservation pending_prev_, pending_cur_;  // observations t−1 and t (decided one step later)
  bool have_prev_obs_ = false, have_cur_obs_ = false;
  std::uint32_t observations_accepted_ = 0;
  bool localized_prev_ = false, localized_before_prev_ = false;  // published status at t−1, t−2
};

}  // namespace mml
}  // namespace fw
