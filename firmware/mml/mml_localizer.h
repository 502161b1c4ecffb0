// MmlLocalizer: MML global localization behind the fw::Localizer seam (dissertation Ch. 5).
// Per scan: RBSM scan-matching odometry integrates the scan into the local map (fragments) →
// pRANSAM (collect-all) matches the local map to the global map with the adaptive threshold →
// hypotheses become robot poses in the map (H ⊕ x_local) → Interpreter (filter, clustering,
// rating, constraints, Bollinger) → unknown-region test Ω' over the last τ_up observations
// (Eq. 5.37) → PoseEstimate (searching / ambiguous / localized / outside-map).
// All storage comes from the StartupArena given to init() or is a fixed member; step() allocates
// nothing. Place the object in static storage (it holds the interpreter's fixed arrays).
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/arena.h"
#include "firmware/base/perf_counter.h"
#include "firmware/base/worker_pool.h"
#include "firmware/map/global_map.h"
#include "firmware/mml/interpretation.h"
#include "firmware/mml/mml_options.h"
#include "firmware/mml/pose_refiner.h"
#include "firmware/pransam/matcher.h"
#include "firmware/rbsm/local_map.h"
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

// Observation points kept per step for Eq. 5.37.
constexpr std::size_t kUnknownPointsPerObservation = 48;

class MmlLocalizer final : public Localizer {
 public:
  // `table_section` (optional, may be null): a precomputed relation table section of the map image
  // (pransam relation_table_io.h) used when config.mml.precomputed_table is set.
  Status init(const MmlLocalizerConfig& config, const GlobalMap& map, const std::uint8_t* table_section,
              std::size_t table_len, StartupArena& arena, WorkerPool* pool);
  const char* name() const override { return "mml"; }
  void reset() override;
  Status step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) override;

  // For visualisation / evaluation.
  const Interpreter& interpreter() const { return interp_; }
  const InterpretResult& last() const { return last_; }
  std::size_t local_map_points() const { return num_scene_; }
  const RefineResult& last_refine() const { return last_refine_; }
  const PerfCounter& match_perf() const { return perf_match_; }
  std::uint32_t front_end_failures() const { return front_end_failures_; }
  bool using_precomputed_table() const { return matcher_.has_precomputed_table(); }

 private:
  Status gather_local_map();
  float unknown_contact(const Se2f& h_map_from_local) const;

  MmlLocalizerConfig config_;
  GlobalMap map_;
  bool initialized_ = false;

  Rbsm rbsm_;
  LocalMap local_map_;
  ScanMatchingOdometry front_end_;
  pransam::Matcher<2> matcher_;
  Interpreter interp_;
  InterpretResult last_;

  Point2f* scene_ = nullptr;  // local map points in the local (scan-matcher) frame, arena
  std::size_t num_scene_ = 0;
  std::size_t scene_capacity_ = 0;
  Hypothesis* hyps_ = nullptr;  // arena, kMaxHypotheses

  // Eq. 5.37: the last τ_up observations (subsampled scan points in the local frame).
  struct Observation {
    Point2f pts[kUnknownPointsPerObservation];
    std::uint32_t n = 0;
  };
  RingBuffer<Observation, kMaxUnknownWindow> observations_;
  Point2f scan_pts_[hal::LaserScan::kMaxBeams];
  std::size_t num_scan_pts_ = 0;

  bool have_odom_ = false;
  Se2f prev_odom_;
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
  hal::PoseEstimate last_out_;
  PerfCounter perf_match_{"mml.pransam"};
};

}  // namespace mml
}  // namespace fw
