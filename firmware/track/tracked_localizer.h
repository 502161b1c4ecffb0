// TrackedLocalizer ("mml-track"): the product's localization system. Global mode runs MML (Ch. 5)
// until it reports the pose isolated; that fix must then be confirmed by the tracker on the same
// scan (fit of the scan, protection level within the alert limits) before anything is published as
// `localized`. Tracking mode aligns every scan on the global map from the odometry prediction
// (pose_tracker.h) and publishes the pose with its protection level; when the integrity monitor
// gives the track up (kidnap, divergence, unmapped space) MML restarts with a fresh local map.
// Global cross-check (extension): whenever the tracked pose stops being `localized` (an alias along a
// weak axis, a fault being recovered), MML starts searching in the background from a fresh local map
// and keeps going for TrackOptions::cross_check_steps scans; if it isolates a pose outside the
// track's protection level, the track sat in a look-alike (a kidnap into a twin corridor with the
// wheels still is invisible to every local test) and MML's fix, confirmed by the tracker as any fix,
// replaces it. If MML isolates the tracked pose, the search stops.
// Confirmation after a large fault (extension): a contradiction beyond the alert limits (the robot
// may have been carried; see TrackStep::large_fault) restarts that search from a fresh local map and
// withholds `localized` until MML isolates the tracked pose (or replaces it): the tracker's tests are
// local and cannot see that a look-alike 35 m away fits as well as the place it came from. With
// TrackOptions::confirm_alias_beyond_alert (on by default; its cost in availability is measured
// there) an alias whose equally good rival lies beyond the alert limits is treated the same way, once
// per episode: the track may already follow the wrong one of two look-alikes — when that rival is a
// place the robot could be (TrackOptions::alias_rival_must_be_credible).
// Leaving the map (extension): a track given up outside the map, having left it as a driving robot
// would (no contradiction where its scans saw the map, each scan continuing the one before it,
// scan_continuity.h), leaves the robot where the wheels carry it (dead_reckoning.h); MML's fixes
// outside that pose's protection level are refused until the scans refute the wheels (an unmapped
// wing can look like a mapped room turned round), and MML's local map restarts when the scan fits
// the map again at that pose (the robot came back).
// PoseEstimate.mode says which one is active; protection_xy_m / protection_theta_rad are set on
// every `localized` pose. Never allocates in step(); both parts live in static storage.
#pragma once

#include <cstdint>

#include "firmware/base/ring_buffer.h"
#include "firmware/mml/mml_localizer.h"
#include "firmware/track/dead_reckoning.h"
#include "firmware/runtime/localizer.h"
#include "firmware/track/global_context.h"
#include "firmware/track/pose_tracker.h"
#include "firmware/track/scan_continuity.h"

namespace fw {
namespace track {

class TrackedLocalizer final : public Localizer {
 public:
  // Scans kept for confirming MML's fix on the scans before it (TrackOptions::confirm_fix_on_past_scans):
  // recovery_steps must not exceed this when that option is on (init() says so).
  static constexpr std::uint32_t kFixHistoryScans = 8;
  // `global` must be initialised and outlive this object. Every MML step and reset goes through
  // the global context (global_context.h): by default inline on every scan (the reference
  // schedule); mmlfw runs it threaded on the schedule of the execution-context table.
  Status init(const TrackOptions& options, const GlobalMap& map, mml::MmlLocalizer* global,
              const GlobalScheduleOptions& schedule = GlobalScheduleOptions());
  const char* name() const override { return "mml-track"; }
  void reset() override;
  Status step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) override;
  // An operator's hint (issue 60). A `localized` track that agrees with it (within its protection
  // level and the hint's 3σ, on the next scan) stays as it is (HintStatus kConfirmed). Otherwise,
  // on the next scan the track (or the search) in progress gives way to the hinted pose, which
  // enters as MML's fix does (start_from_fix: confirmed on the scans before
  // it and on its own, covariance from the hint's σ) — refused when the scans contradict it
  // (HintStatus kRefused, POSE reason fix-rejected). TrackOptions::hint_awaits_mml: the confirmed
  // track then waits for MML to isolate the same pose; an MML fix elsewhere replaces it.
  Status set_pose_hint(const hal::PoseHint& hint) override;
  hal::HintStatus hint_status() const override { return hint_status_; }
  std::uint32_t hints() const { return hints_; }
  std::uint32_t hints_refused() const { return hints_refused_; }

  bool tracking() const { return tracker_.active(); }
  const PoseTracker& tracker() const { return tracker_; }
  mml::MmlLocalizer* global() { return mml_; }
  const mml::MmlLocalizer* global() const { return mml_; }
  GlobalContext& global_context() { return global_; }
  const GlobalContext& global_context() const { return global_; }
  // Since reset: fixes accepted (tracks started from a confirmed pose hint included), MML fixes the
  // tracker did not confirm, tracks given up.
  std::uint32_t fixes() const { return fixes_; }
  std::uint32_t fix_rejections() const { return fix_rejections_; }
  // Fixes confirmed on the scans before them (TrackOptions::confirm_fix_on_past_scans), of fixes().
  std::uint32_t fixes_on_past_scans() const { return fixes_on_past_scans_; }
  // Replays of a fix on the past scans that failed, each followed by forward confirmation on its scan.
  std::uint32_t fix_replays_failed() const { return fix_replays_failed_; }
  std::uint32_t tracks_lost() const { return tracks_lost_; }
  // MML fixes refused because the wheels, carrying a track given up outside the map, rule them out
  // (dead_reckoning.h); counted once per scan.
  std::uint32_t fixes_refused_by_wheels() const { return fixes_refused_by_wheels_; }
  const DeadReckoning& dead_reckoning() const { return dead_reckoning_; }
  std::uint32_t cross_check_switches() const { return cross_check_switches_; }  // tracks replaced by MML
  // MML isolated a pose outside a track that had seen no large fault, and the scan did not prefer
  // MML's pose significantly: neither is published `localized` until MML isolates the tracked pose.
  std::uint32_t cross_check_conflicts() const { return cross_check_conflicts_; }
  bool cross_checking() const { return cross_check_left_ > 0; }
  // A large fault (TrackStep::large_fault) was seen and MML has not yet isolated the tracked pose.
  bool awaiting_confirmation() const { return unconfirmed_; }
  // Why the track awaits MML's word (while awaiting_confirmation(); "none" otherwise): the large
  // fault's monitor (large_fault_name), "alias-beyond-alert", "hint" or "mml-conflict". A
  // diagnostic for the evaluation's withheld-while-right figures by cause.
  const char* wait_cause() const { return unconfirmed_ ? wait_cause_ : "none"; }
  std::uint32_t confirmations() const { return confirmations_; }  // tracked poses MML confirmed
  // The most correlative pre-search candidates of one scan's tracker steps, since reset (the replay
  // of confirm_fix_on_past_scans holds them to search.max_candidates; a failed replay's forward
  // start on the same scan may add one more search).
  std::uint32_t most_search_candidates_in_one_scan() const { return most_search_candidates_in_one_scan_; }

 private:
  std::size_t scan_points(const hal::LaserScan& scan);
  void publish_track(const TrackStep& ts, hal::PoseEstimate* out) const;
  void note_how_the_map_was_left(const TrackStep& ts, const Se2f& wheel, std::size_t n, hal::PoseEstimate* out);
  void await_mml_confirmation(const char* cause);
  // MML's fix in `g` → tracker started on it: true when accepted on this scan or while its replay
  // on the scans before it catches up (replay_past_scans); false (tracker reset) if rejected.
  bool start_from_fix(const hal::PoseEstimate& g, const Se2f& wheel, std::size_t n, hal::PoseEstimate* out);
  // The fix started on the scan it was isolated on: true when the tracker accepts it (published in
  // `out`); false with the tracker stopped and `out` saying the fix was rejected.
  bool start_forward(const Se2f& fix, const Eigen::Matrix3f& cov, const Se2f& wheel, std::size_t n,
                     hal::PoseEstimate* out);
  // TrackOptions::confirm_fix_on_past_scans: the replay of the remembered scans, at most
  // past_scans_per_step per call. true while it catches up or once the track is `localized` on the
  // newest scan; when it ends otherwise, forward confirmation from the fix (start_forward's result).
  bool replay_past_scans(const Se2f& wheel, std::size_t n, hal::PoseEstimate* out);
  void limit_search_to_what_this_scan_left();
  // tracker_.step, counting this scan's correlative pre-search candidates.
  TrackStep step_tracker(const Point2f* pts, std::size_t n, const Se2f& wheel, bool predict = true);
  std::uint32_t search_candidates_this_scan_ = 0, most_search_candidates_in_one_scan_ = 0;
  Status step_scan(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out);
  // The pending hint replaces what runs and starts as a fix (set_pose_hint).
  void start_from_hint(const Se2f& wheel, std::size_t n, hal::PoseEstimate* out);
  // After a step: where the hinted track stands (HintStatus).
  void follow_hint(const hal::PoseEstimate& out);
  bool hint_needs_mml() const { return hint_track_ && tracker_.options().hint_awaits_mml; }
  bool hint_agrees(const hal::PoseEstimate& out) const;
  bool hint_pending_ = false, hint_track_ = false, hint_against_track_ = false;
  hal::PoseHint hint_;
  hal::HintStatus hint_status_ = hal::HintStatus::kNone;
  std::uint32_t hints_ = 0, hints_refused_ = 0;
  Status cross_check(const hal::LaserScan& scan, const hal::Odometry& odom, const Se2f& wheel, std::size_t n,
                     const TrackStep& ts, hal::PoseEstimate* out);
  mml::MmlLocalizer* mml_ = nullptr;
  GlobalContext global_;
  PoseTracker tracker_;
  Point2f pts_[hal::LaserScan::kMaxBeams];
  // The last scans as the tracker uses them, this step's the newest: the previous one for the
  // continuity test (scan_continuity.h), all of them for confirm_fix_on_past_scans.
  struct RememberedScan {
    Point2f pts[hal::LaserScan::kMaxBeams];
    std::size_t n = 0;
    Se2f wheel;
  };
  RingBuffer<RememberedScan, kFixHistoryScans + 1> history_;
  // This scan (pts_, n) continues `previous` moved by an increment the wheels allow (scan_continuity.h).
  bool continues_previous_scan(const RememberedScan& previous, const Se2f& wheel, std::size_t n);
  // The replay in progress: the newest replay_lag_ scans of history_ are still to be stepped (0 =
  // none); MML's fix, the wheels at its scan and its covariance, for forward confirmation.
  std::uint32_t replay_lag_ = 0;
  bool replay_first_ = false;
  Se2f replay_fix_, replay_fix_wheel_;
  Eigen::Matrix3f replay_cov_ = Eigen::Matrix3f::Zero();
  std::uint32_t fixes_ = 0, fix_rejections_ = 0, tracks_lost_ = 0, cross_check_switches_ = 0;
  std::uint32_t cross_check_left_ = 0;  // scans the background search still runs (0 = idle)
  std::uint32_t confirmations_ = 0, cross_check_conflicts_ = 0, fixes_on_past_scans_ = 0, fix_replays_failed_ = 0;
  bool unconfirmed_ = false;
  const char* wait_cause_ = "none";  // a string literal (wait_cause())
  // Since the last track was given up (reset() clears it): its last pose carried by the wheels, for
  // the outside-map status while MML searches and, after a track given up outside the map, as the
  // rival MML's fixes must agree with (dead_reckoning.h).
  DeadReckoning dead_reckoning_;
  // No scan since the track's last supported one contradicted it where it saw the map, or was
  // unlike the scan before it (scan_continuity.h).
  bool left_map_cleanly_ = true;
  // A scan of this track that did not continue the one before it (scan_continuity.h): the robot
  // may have been carried, so the track's pose (and the wheels' from it) says nothing about where
  // the robot is until MML confirms it or a new track starts (TrackOptions::outside_map_needs_clean_exit).
  // A robot driving into unmapped space sees what it saw a scan ago; a carried one does not.
  bool carry_seen_ = false;
  ScanContinuity continuity_;
  ProtectionFactors k_;
  std::uint32_t fixes_refused_by_wheels_ = 0;
};

}  // namespace track
}  // namespace fw
