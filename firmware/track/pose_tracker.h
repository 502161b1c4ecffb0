// PoseTracker: tracking against the global map after a global fix, with an integrity monitor and a
// protection level (extension of the dissertation; its Sec. 5.8 names tracking after MML as future
// work). Per scan:
//   predict   x⁻ = x ⊕ Δodom, P⁻ = F P Fᵀ + G Q(Δ) Gᵀ (odometry noise grows with the motion);
//   align     the scan on the distance field from x⁻ (scan_alignment.h) → x_s, information H;
//   check     fault detection on the residuals: too few end-points explained by the map, or a scan
//             fix that disagrees with the prediction (χ² of the innovation), a fused pose that
//             disagrees with the odometry over the last fused scans (odometry_consistency.h), a rival pose along
//             a weak axis that explains the scan better (alias check), contradicts the pose; a
//             rival that explains it as well makes it ambiguous (not `localized`, still tracked);
//             most end-points in unknown space means outside the map; too few points says nothing;
//   update    only on a consistent scan, and only after the robot moved a little (no re-counting of
//             the same map error while standing still): P = (P⁻⁻¹ + H)⁻¹, x = x⁻ + P H (x_s − x⁻);
//   publish   the protection level (protection_level.h) and a status: `localized` only when this
//             scan does not contradict the pose, the last contradiction is `recovery_steps`
//             consistent scans old and PL ≤ alert limits.
// A scan that says nothing leaves the pose on the prediction and the PL grows with the odometry
// noise until the status drops; contradicting or outside-map scans drop it at once; persistent
// contradiction, persistent outside-map or a PL beyond the lost limit end the track (`lost`), and
// the owner goes back to global localization. Never allocates; deterministic.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "firmware/base/se2.h"
#include "firmware/base/status.h"
#include "firmware/map/global_map.h"
#include "firmware/track/odometry_consistency.h"
#include "firmware/track/correlative_search.h"
#include "firmware/track/protection_level.h"
#include "firmware/track/scan_alignment.h"
#include "firmware/track/track_options.h"
#include "hal/msg/pose_estimate.h"

namespace fw {
namespace track {

enum class ScanVerdict : std::uint8_t {
  kSupported = 0,      // consistent with the pose (fused, or checked while standing still)
  kUninformative = 1,  // too few end-points on the map to say anything
  kContradicting = 2,  // poor fit or inconsistent with the odometry prediction
  kOutsideMap = 3,     // most end-points in unknown space
  kAmbiguous = 4,      // fits, but as well at a rival pose along a weak axis (alias check)
};
const char* verdict_name(ScanVerdict v);

// Which monitor found a fault beyond the alert limits (TrackStep::large_fault): what the silence
// that follows is charged to (the corpus's withheld-while-right figures by cause).
enum class LargeFault : std::uint8_t {
  kNone = 0,
  kOdometryJump = 1,    // a non-physical odometry increment
  kUnexplained = 2,     // the map explains under min_explained_fraction of the scan
  kInnovation = 3,      // the scan fix beyond the prediction's PL and beyond the alert limits
  kBetterRival = 4,     // the alias check's rival fits significantly better, beyond the alert limits
  kOdometryWindow = 5,  // the fused poses disagree with the wheels over the window
};
const char* large_fault_name(LargeFault f);

struct TrackStep {
  Se2f pose;
  Eigen::Matrix3f cov = Eigen::Matrix3f::Zero();
  ProtectionLevel pl;
  hal::LocalizationStatus status = hal::LocalizationStatus::kSearching;
  hal::StatusReason reason = hal::StatusReason::kSearching;  // why not `localized` (kNone when it is)
  ScanVerdict verdict = ScanVerdict::kUninformative;
  bool fused = false;
  bool lost = false;            // the track is given up: go back to global localization
  // A contradiction larger than the alert limits (an odometry jump, a scan fix or a better rival
  // beyond them, the odometry disagreeing over the window): the robot may have been carried
  // anywhere, so local evidence alone can no longer make the pose `localized` (tracked_localizer.h).
  bool large_fault = false;
  LargeFault large_fault_cause = LargeFault::kNone;  // which monitor (kNone when !large_fault)
  // The map explains fewer than TrackOptions::min_explained_fraction of the scan's end-points.
  bool unexplained = false;
  // The scan fits the map significantly worse than the previous one (TrackOptions::fit_drop_z).
  bool fit_drop = false;
  // An outside-map scan whose end-points on the map contradict the pose by the tracker's fit tests
  // (inlier fraction below min_inlier_fraction, or a fit drop against the previous scan): a robot
  // that drove out of the map still sees the mapped walls behind it where the map has them; one
  // carried away from a place near the map's edge does not (tracked_localizer.h).
  bool known_part_contradicts = false;
  // A fault in heading only, recovered by the track (TrackOptions::heading_fault_local_recovery).
  bool heading_fault = false;
  // The alias check found a rival that fits this scan as well as the fix and lies beyond the alert
  // limits: the track may already follow the wrong one of two look-alikes (a kidnap into a place
  // that fits near the old pose), which no later local test can tell (tracked_localizer.h).
  bool alias_beyond_alert = false;
  // Confidence extent of the scan fix (fit_comparison.h; 0 when not computed).
  float confidence_xy_m = 0.0f, confidence_theta_rad = 0.0f;
  bool confidence_pins_nothing = false;  // open to the alert limit along both axes (no prediction cap)
  std::uint32_t unsupported_steps = 0, faulty_steps = 0, outside_steps = 0;
  float innovation_chi2 = 0.0f;
  float odometry_chi2 = 0.0f;   // odometry consistency over the window (0 = not tested)
  float alias_cost = 0.0f, alias_rival_cost = 1.0f;  // alias check (1 = not run)
  Se2f alias_rival;               // the alias check's best rival (when alias_rival_cost < 1)
  // The rival of an ambiguous scan is a place the robot could be: turned, or at the fix's heading
  // inside the prediction's protection level and behind a barrier (not in the fix's cost valley).
  bool alias_rival_credible = false;
  // The fused update left the alias check's one-mode valley axis to the prediction
  // (TrackOptions::alias_valley_drops_information).
  bool valley_dropped = false;
  std::uint32_t search_candidates = 0;  // correlative pre-search (0 = not run: prediction tight)
  bool search_moved = false;            // the alignment started from the search's best pose
  bool refit_at_rival = false;          // re-aligned from a better rival within the prediction's PL
  bool turn_searched = false;           // the turn hypothesis was searched at the predicted position
  ScanAlignment alignment;
};

class PoseTracker {
 public:
  Status init(const TrackOptions& options, const GlobalMap& map);
  // A fresh start (a new trial): no track.
  void reset();
  // Ends the track (back to global localization).
  void stop();
  bool active() const { return active_; }
  // Starts a track at a global fix (`cov` = the fix's covariance, inflated and floored per options).
  // `confirm`: the pose is not `localized` until recovery_steps unique consistent scans have followed
  // (as after a fault), and no alias rival is ruled out until then (TrackOptions::confirm_fix).
  void start(const Se2f& pose, const Eigen::Matrix3f& cov, const Se2f& odom, bool confirm = false);
  // One scan: `points` in the sensor frame (beam order), `odom` the wheel odometry pose at the scan.
  // `predict` = false checks/fuses the scan at the current pose without an odometry step (the scan
  // the track was started on). Returns the published view; `lost` ends the track (active() false).
  TrackStep step(const Point2f* points, std::size_t n, const Se2f& odom, bool predict = true);
  // The next step's correlative pre-search may score at most this many candidates (≥ 1; the
  // options' max_candidates when larger): a budget shared by several steps in one scan period.
  void limit_next_search(std::uint32_t max_candidates) { next_search_cap_ = max_candidates; }
  const TrackStep& last() const { return last_; }
  const TrackOptions& options() const { return options_; }
  const GlobalMap& map() const { return map_; }

 private:
  // Working state of one step() between its stages (pose_tracker.cpp).
  struct StepWork {
    ScanVerdict v = ScanVerdict::kSupported;
    bool predicted = true;   // an odometry step (false: the scan a track starts on)
    bool innovation_fault = false;
    Se2f pred;                                       // the odometry prediction
    ProtectionLevel pred_pl;                         // its protection level
    Eigen::Matrix3f p_post = Eigen::Matrix3f::Zero();  // posterior covariance if fused
    Eigen::Vector3f e = Eigen::Vector3f::Zero();     // scan fix − prediction
    Eigen::Vector3f unfused = Eigen::Vector3f::Zero();  // the update a scan not fused would make
    float fit_drop_z = 0.0f;  // the fit-drop test's statistic against the previous scan (0 = not tested)
    // The alias check's one-mode valley (alias_valley_is_one_mode): the unit axis along which the
    // scan fits alike; its information along it is dropped before the update.
    bool valley = false;
    Eigen::Vector2f valley_axis = Eigen::Vector2f::Zero();
    bool rival_better = false;  // the alias check's rival fits this scan significantly better
  };
  struct Update {
    bool fuse = false;
    Se2f pose;
    Eigen::Matrix3f cov = Eigen::Matrix3f::Zero();
    float bias_xy = 0.0f, bias_theta = 0.0f;  // the map bias this scan shows
  };
  void predict_to(const Se2f& odom);
  void judge_scan(const Point2f* points, std::size_t n, bool odom_jump, StepWork* w, TrackStep* out);
  void try_turn_hypothesis(const Point2f* points, std::size_t n, const StepWork& w0, const TrackStep& out0,
                           StepWork* w, TrackStep* out);
  void check_aliases(const Point2f* points, std::size_t n, StepWork* w, TrackStep* out);
  bool rival_within_reported_turn(const Eigen::Vector3f& e, const ProtectionLevel& pred_pl) const;
  bool undetected_fault_reaches_alert(const Eigen::Matrix3f& p_pred, const Eigen::Matrix3f& p_post,
                                      const ProtectionLevel& pred_pl) const;
  Update propose_update(const Se2f& odom, bool predict, StepWork* w, TrackStep* out);
  void apply_verdict(const Se2f& odom, const StepWork& w, const Update& u, TrackStep* out);
  void publish(const Point2f* points, std::size_t n, const StepWork& w, TrackStep* out);
  std::size_t subsample_alias_points(const Point2f* points, std::size_t n);
  void update_confidence_excess(const Point2f* points, std::size_t n, const ScanAlignment& a, const StepWork& w,
                                const ProtectionLevel& pl, TrackStep* out);
  ScanAlignment align_from_prediction(const Point2f* points, std::size_t n, const Se2f& pred, TrackStep* out);
  static constexpr std::size_t kSearchScratch = 2 * 1081;
  Point2f search_scratch_[kSearchScratch];
  // The alias check refines ~30 rivals: it uses at most this many end-points (evenly subsampled),
  // which halves its cost at the 360 points of the alignment and keeps one point = 1/180 of the cost.
  static constexpr std::size_t kAliasMaxPoints = 180;
  Point2f alias_points_[kAliasMaxPoints];
  OdometryConsistency odometry_check_;
  TrackOptions options_;
  GlobalMap map_;
  // Protection level beyond the covariance's, from the last supporting scan's confidence extent.
  float excess_xy_m_ = 0.0f;
  ProtectionFactors k_;
  std::uint32_t next_search_cap_ = 0;  // limit_next_search (0 = the options' cap)
  std::uint32_t search_cap_ = 0;       // this step's
  bool initialized_ = false;
  bool active_ = false;
  Se2f pose_;
  Eigen::Matrix3f cov_ = Eigen::Matrix3f::Zero();
  Se2f prev_odom_;
  Se2f odom_at_fuse_;      // odometry at the last fused scan (update thresholds)
  std::uint32_t predicted_since_fuse_ = 0;  // predictions since the last fused scan (per-step noise)
  Se2f pose_at_fuse_;      // the track's pose after the last fused scan (update thresholds)
  // The next supported scan is fused whatever the update thresholds say: at the start, and after an
  // innovation fault widened the covariance (the pose held since the last update is not trusted).
  bool fuse_next_ = true;
  float bias_xy_m_ = 0.0f, bias_theta_rad_ = 0.0f;  // of the last supported scan
  std::uint32_t unsupported_ = 0, faulty_ = 0, outside_ = 0;
  // Metres the wheels carried the pose since a supported scan last pinned every direction of it
  // (no one-valley drop): how far a declared wheel slip could go unseen (odom_slip_per_100m).
  float unpinned_m_ = 0.0f;
  // Turn the wheels reported (sum of |Δθ|) since the last fused scan: the most a wheel turn error
  // can have turned the prediction since a scan last set the heading (rival_within_reported_turn).
  float turn_since_fuse_rad_ = 0.0f;
  std::uint32_t consistent_since_fault_ = 0;  // consistent scans since the last contradicting one
  bool had_fault_ = false;
  // A contradicting scan since the last recovery_steps unique consistent scans (ambiguous scans do
  // not count either way): the track may be wrong, so no alias rival is ruled out (check_aliases).
  bool contradicted_ = false;
  // Fit of the previous scan with enough points on known cells (inlier fraction, correlation
  // cells), the reference of the fit-drop test (judge_scan); fit_cells_ = 0 until there is one.
  float fit_fraction_ = 0.0f;
  std::uint32_t fit_cells_ = 0;
  TrackStep last_;
};

}  // namespace track
}  // namespace fw
