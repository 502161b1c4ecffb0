#include "firmware/track/tracked_localizer.h"

#include <cmath>

#include "firmware/scan/scan_points.h"
#include "firmware/track/fit_comparison.h"
#include "firmware/track/scan_alignment.h"

namespace fw {
namespace track {

Status TrackedLocalizer::init(const TrackOptions& options, const GlobalMap& map, mml::MmlLocalizer* global,
                              const GlobalScheduleOptions& schedule) {
  if (global == nullptr) return Status::error(Errc::kInvalidArgument, "TrackedLocalizer: null global localizer");
  if (options.confirm_fix && options.confirm_fix_on_past_scans && options.recovery_steps > kFixHistoryScans) {
    return Status::error(Errc::kInvalidArgument,
                         "TrackOptions.recovery_steps = %u exceeds the %u scans kept for confirm_fix_on_past_scans",
                         options.recovery_steps, kFixHistoryScans);
  }
  FW_RETURN_IF_ERROR(tracker_.init(options, map));
  FW_RETURN_IF_ERROR(global_.init(global, schedule));
  mml_ = global;
  k_ = ProtectionFactors::for_risk(options.integrity_risk);
  reset();
  return Status::ok();
}

void TrackedLocalizer::reset() {
  tracker_.reset();
  global_.restart();
  fixes_ = fix_rejections_ = tracks_lost_ = cross_check_switches_ = confirmations_ = cross_check_conflicts_ = fixes_on_past_scans_ = 0;
  fix_replays_failed_ = 0;
  search_candidates_this_scan_ = most_search_candidates_in_one_scan_ = 0;
  fixes_refused_by_wheels_ = 0;
  cross_check_left_ = 0;
  unconfirmed_ = false;
  history_.clear();
  replay_lag_ = 0;
  dead_reckoning_.clear();
  left_map_cleanly_ = true;
  carry_seen_ = false;
  hint_pending_ = hint_track_ = hint_against_track_ = false;
  hint_status_ = hal::HintStatus::kNone;
  hints_ = hints_refused_ = 0;
}

Status TrackedLocalizer::set_pose_hint(const hal::PoseHint& hint) {
  if (mml_ == nullptr) return Status::error(Errc::kNotInitialized, "TrackedLocalizer: pose hint before init()");
  if (!std::isfinite(hint.x) || !std::isfinite(hint.y) || !std::isfinite(hint.theta) || !(hint.sigma_xy_m > 0.0f) ||
      !(hint.sigma_theta_rad > 0.0f) || !std::isfinite(hint.sigma_xy_m) || !std::isfinite(hint.sigma_theta_rad)) {
    return Status::error(Errc::kInvalidArgument, "TrackedLocalizer: pose hint (%g, %g, %g, sigma %g m %g rad) not finite "
                         "or without a positive uncertainty", static_cast<double>(hint.x), static_cast<double>(hint.y),
                         static_cast<double>(hint.theta), static_cast<double>(hint.sigma_xy_m),
                         static_cast<double>(hint.sigma_theta_rad));
  }
  hint_ = hint;
  hint_pending_ = true;
  hint_status_ = hal::HintStatus::kPending;
  // A confirmed track is checked against the hint on the next scan first (hint_agrees): a hint that
  // agrees with it changes nothing.
  hint_against_track_ = tracker_.active() && replay_lag_ == 0 && !unconfirmed_ && !hint_track_;
  return Status::ok();
}

// The hint, within its 3σ and the track's protection level of a `localized` track: it agrees.
bool TrackedLocalizer::hint_agrees(const hal::PoseEstimate& out) const {
  if (out.status != hal::LocalizationStatus::kLocalized) return false;
  const float d = std::hypot(out.x - hint_.x, out.y - hint_.y);
  const float dth = std::fabs(wrap_angle(out.theta - hint_.theta));
  return d <= out.protection_xy_m + 3.0f * hint_.sigma_xy_m &&
         dth <= out.protection_theta_rad + 3.0f * hint_.sigma_theta_rad;
}

// The operator says where the robot is: whatever runs gives way, and the hint enters as MML's fix
// does (start_from_fix), so it passes the same checks. With hint_awaits_mml, MML's search (going on,
// or restarted when the hint contradicts a track) must then isolate the same pose.
void TrackedLocalizer::start_from_hint(const Se2f& wheel, std::size_t n, hal::PoseEstimate* out) {
  hint_pending_ = false;
  ++hints_;
  const bool had_track = tracker_.active();
  tracker_.stop();
  replay_lag_ = 0;
  dead_reckoning_.clear();
  hint_track_ = true;
  if (had_track) {
    // The operator contradicts a track: the robot may have been carried. MML's local map starts
    // now (it holds no scan from before the doubt), as after a large fault.
    await_mml_confirmation("hint");
  } else {
    // MML was searching: its scans are as good as before the hint; it goes on, and its fix must
    // land on the hinted pose (cross_check) for the hint to count.
    cross_check_left_ = tracker_.options().cross_check_steps;
  }
  unconfirmed_ = hint_needs_mml();
  wait_cause_ = "hint";
  hal::PoseEstimate g;
  g.x = hint_.x;
  g.y = hint_.y;
  g.theta = wrap_angle(hint_.theta);
  g.cov[0] = g.cov[4] = hint_.sigma_xy_m * hint_.sigma_xy_m;
  g.cov[8] = hint_.sigma_theta_rad * hint_.sigma_theta_rad;
  g.status = hal::LocalizationStatus::kLocalized;
  if (!start_from_fix(g, wheel, n, out)) {
    ++hints_refused_;
    hint_track_ = false;
    unconfirmed_ = false;
    hint_status_ = hal::HintStatus::kRefused;
  }
}

void TrackedLocalizer::follow_hint(const hal::PoseEstimate& out) {
  if (!hint_track_) return;
  if (out.status == hal::LocalizationStatus::kLocalized) {
    hint_status_ = hal::HintStatus::kConfirmed;
    hint_track_ = false;
  } else if (!tracker_.active() && replay_lag_ == 0) {
    // Refused on its scan after a replay, or given up before it was ever `localized`.
    hint_status_ = hint_status_ == hal::HintStatus::kPending ? hal::HintStatus::kRefused : hal::HintStatus::kLost;
    if (hint_status_ == hal::HintStatus::kRefused) ++hints_refused_;
    hint_track_ = false;
  } else if (replay_lag_ == 0) {  // past its confirmation (a replay on the scans before it still runs)
    hint_status_ = unconfirmed_ ? hal::HintStatus::kAwaitingMml : hal::HintStatus::kTracking;
  }
}

// End-points within the tracker's range, evenly subsampled to at most align.max_points (beam order
// kept). In place: the k-th kept point comes from index k·count/cap ≥ k, never one already overwritten.
std::size_t TrackedLocalizer::scan_points(const hal::LaserScan& scan) {
  ScanPointsOptions so;
  so.max_range = tracker_.options().align.max_range_m;
  ScanPointsResult sr;
  if (!scan_to_points(scan, so, pts_, hal::LaserScan::kMaxBeams, &sr).is_ok()) return 0;
  const std::size_t cap = tracker_.options().align.max_points;
  if (sr.count <= cap) return sr.count;
  for (std::size_t k = 0; k < cap; ++k) pts_[k] = pts_[k * sr.count / cap];
  return cap;
}

void TrackedLocalizer::publish_track(const TrackStep& ts, hal::PoseEstimate* out) const {
  out->x = ts.pose.x;
  out->y = ts.pose.y;
  out->theta = ts.pose.theta;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out->cov[r * 3 + c] = ts.cov(r, c);
  out->status = ts.status;
  out->reason = ts.reason;
  out->mode = hal::LocalizationMode::kTracking;
  out->hypothesis_count = 1;
  out->cluster_count = 1;
  out->rating = ts.alignment.inlier_fraction();
  out->protection_xy_m = ts.pl.xy_m;
  out->protection_theta_rad = ts.pl.theta_rad;
  out->unsupported_steps = static_cast<std::uint16_t>(ts.unsupported_steps > 65535 ? 65535 : ts.unsupported_steps);
}

// The track stays, but it is `localized` again only on MML's word, from a local map that starts
// now (so it holds no scan from before the doubt), checked over cross_check_steps scans.
void TrackedLocalizer::await_mml_confirmation(const char* cause) {
  unconfirmed_ = true;
  wait_cause_ = cause;
  global_.reset();
  cross_check_left_ = tracker_.options().cross_check_steps;
}

// Does this scan (pts_) continue the one before it, moved by an increment the wheels allow
// (ScanContinuity::explained_fraction_within, σ from the tracker's odometry noise model)?
bool TrackedLocalizer::continues_previous_scan(const RememberedScan& previous, const Se2f& wheel, std::size_t n) {
  const TrackOptions& o = tracker_.options();
  const Se2f increment = previous.wheel.between(wheel);
  const Eigen::Matrix3f q = odometry_increment_noise(increment, o);
  return continuity_.explained_fraction_within(previous.pts, previous.n, pts_, n, increment,
                                               std::sqrt(std::fmax(q(0, 0), q(1, 1))), std::sqrt(q(2, 2)),
                                               o.align.outlier_m) >= o.min_explained_fraction;
}

// Since the track's last supported scan: did the scans leave the map as a robot driving out of it
// would (left_map_cleanly_, for the wheels' binding), and did any show a sign of a carry
// (carry_seen_, for the outside-map status)? An `outside-map` of the track after such a sign is
// published as a contradicted track instead.
void TrackedLocalizer::note_how_the_map_was_left(const TrackStep& ts, const Se2f& wheel, std::size_t n,
                                                 hal::PoseEstimate* out) {
  // A driving robot's exit: no known part contradicted (TrackStep::known_part_contradicts).
  if (ts.verdict == ScanVerdict::kSupported) left_map_cleanly_ = true;
  if (ts.known_part_contradicts || ts.large_fault) left_map_cleanly_ = false;
  const RememberedScan* previous = history_.size() >= 2 ? &history_[history_.size() - 2] : nullptr;
  // Does a scan the map does not support continue the one before it? (Supported scans need no
  // such test: the map vouches for them; nor does a track whose carry is already seen, unless the
  // exit itself is judged.)
  const bool asks = ts.verdict == ScanVerdict::kOutsideMap ||
                    (ts.verdict != ScanVerdict::kSupported && !carry_seen_ &&
                     tracker_.options().outside_map_needs_clean_exit);
  if (asks && previous != nullptr && !continues_previous_scan(*previous, wheel, n)) {
    // The scan is not what the robot saw a scan ago: it may have been carried.
    carry_seen_ = true;
    if (ts.verdict == ScanVerdict::kOutsideMap) left_map_cleanly_ = false;
  }
  if (out->status == hal::LocalizationStatus::kOutsideMap && carry_seen_ &&
      tracker_.options().outside_map_needs_clean_exit) {
    // Mostly unknown at the tracked pose, but the robot may have been carried: the old pose's
    // scan on unknown cells says the pose is wrong, not that the map was left.
    out->status = hal::LocalizationStatus::kAmbiguous;
    out->reason = hal::StatusReason::kTrackFault;
  }
}

Status TrackedLocalizer::step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) {
  if (mml_ == nullptr) return Status::error(Errc::kNotInitialized, "TrackedLocalizer: step() before init()");
  if (out == nullptr) return Status::error(Errc::kInvalidArgument, "TrackedLocalizer: null output");
  const Status s = step_scan(scan, odom, out);
  if (hint_pending_ && hint_against_track_) {
    // The hint was checked against this scan's confirmed track: agreeing, nothing changes; else it
    // starts on the next scan (start_from_hint).
    hint_against_track_ = false;
    if (hint_agrees(*out)) {
      hint_pending_ = false;
      ++hints_;
      hint_status_ = hal::HintStatus::kConfirmed;
    }
  }
  follow_hint(*out);
  return s;
}

Status TrackedLocalizer::step_scan(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) {
  const hal::CompleteReasonOnExit reason_on_exit{out};  // every estimate says why it is not `localized`
  if (!std::isfinite(odom.x) || !std::isfinite(odom.y) || !std::isfinite(odom.theta)) {
    return Status::error(Errc::kInvalidArgument, "TrackedLocalizer: non-finite odometry at scan %u", scan.scan_id);
  }
  global_.tick();
  // Until a fix has been confirmed since start-up (or reset), the robot may stand in space the map
  // lacks and see a copy of a mapped place there: MML keeps that hypothesis beside the mapped ones
  // (corpus seed 505 #56: switched on in a block erased from the map, MML isolated the twin
  // cross-aisle 36 m away). Once located, the wheels bind MML's later fixes
  // (wheels_bind_mml_without_carry, dead_reckoning.h). Held after every carry sign too, it cost aces
  // (whose map has 250–320 m² unknown blocks beside its corridors) availability 0.90 → 0.66:
  // a carry into a room the map lacks is outside the assumptions (README).
  global_.set_unmapped_hypothesis(fixes_ == 0);
  search_candidates_this_scan_ = 0;
  const Se2f wheel(odom.x, odom.y, odom.theta);
  const std::size_t n = scan_points(scan);
  {  // the continuity test reads the previous scan, the replay of confirm_fix_on_past_scans all of them
    history_.push_overwrite(RememberedScan());
    RememberedScan& r = history_[history_.size() - 1];
    for (std::size_t k = 0; k < n; ++k) r.pts[k] = pts_[k];
    r.n = n;
    r.wheel = wheel;
  }
  if (hint_pending_ && !hint_against_track_) {
    *out = hal::PoseEstimate();
    out->timestamp_ns = scan.timestamp_ns;
    out->scan_id = scan.scan_id;
    start_from_hint(wheel, n, out);
    return Status::ok();
  }
  if (replay_lag_ > 0) {  // MML's fix is being confirmed on the scans before it: this one joins them
    ++replay_lag_;
    *out = hal::PoseEstimate();
    out->timestamp_ns = scan.timestamp_ns;
    out->scan_id = scan.scan_id;
    replay_past_scans(wheel, n, out);
    return Status::ok();
  }
  if (tracker_.active()) {
    const TrackStep ts = step_tracker(pts_, n, wheel);
    *out = hal::PoseEstimate();
    out->timestamp_ns = scan.timestamp_ns;
    out->scan_id = scan.scan_id;
    publish_track(ts, out);
    note_how_the_map_was_left(ts, wheel, n, out);
    if (ts.large_fault && !ts.lost && tracker_.options().cross_check_steps > 0) {
      // The robot may have been carried anywhere (a kidnap into a twin corridor fits every local
      // test): the pose needs MML's word again, from a local map that starts after the fault.
      await_mml_confirmation(large_fault_name(ts.large_fault_cause));
    }
    if (tracker_.options().confirm_alias_beyond_alert && ts.alias_beyond_alert && !ts.large_fault && !ts.lost &&
        !unconfirmed_ && tracker_.options().cross_check_steps > 0) {
      // Two look-alikes farther apart than the alert limits fit this scan equally: once the track
      // has passed through such a scan, which of them it follows is beyond every local test (intel
      // kidnap 6737 → 7812: the scans of the new place fit 11 m away from it, the track went
      // alias → recovering → `localized` 10.8 m off before the background search had isolated
      // anything; first with RBSM's motion prior on, then in the default chain, track_options.h).
      // Like a large fault, only MML's word makes it `localized` again; its local map
      // starts here, so it holds no scan from before the doubt. Once per episode: resetting it on
      // every such scan of a long corridor would keep MML from ever isolating anything.
      await_mml_confirmation("alias-beyond-alert");
    }
    if (!ts.lost) return cross_check(scan, odom, wheel, n, ts, out);
    {
      // The track is given up: global localization from a fresh local map, starting with this scan.
      ++tracks_lost_;
      cross_check_left_ = 0;
      global_.reset();
      // Given up outside the map, having left it cleanly, the robot is where the wheels carry it
      // (dead_reckoning.h). After a contradiction, or an exit whose scans contradicted the map
      // where they saw it or did not continue the scan before them, it may have been carried
      // anywhere, and the chain binds nothing (aces kidnaps 3501 → 922 and 1129 → 4609, seed 19:
      // the first scans after the carry were 63 % and 53 % unknown at the old pose; in the
      // first the end-points on the map fitted 0.59, a fit drop, in the second 0.79, but the scan
      // was unlike the one before it; bound by the wheels, both right re-fixes came late or never).
      // TrackOptions::wheels_bind_mml_without_carry: also any other loss the scans did not show
      // to be a carry.
      const bool binding = ts.verdict == ScanVerdict::kOutsideMap
                               ? left_map_cleanly_
                               : tracker_.options().wheels_bind_mml_without_carry && !carry_seen_;
      dead_reckoning_.start(ts.pose, ts.cov, wheel, binding, !carry_seen_);
      hal::PoseEstimate g;
      FW_RETURN_IF_ERROR(global_.step(scan, odom, &g));
      const bool outside = ts.verdict == ScanVerdict::kOutsideMap &&
                           (!carry_seen_ || !tracker_.options().outside_map_needs_clean_exit);
      out->status = outside ? hal::LocalizationStatus::kOutsideMap : hal::LocalizationStatus::kSearching;
      out->reason = hal::reason_of_status(out->status);
      out->mode = hal::LocalizationMode::kGlobal;
      out->protection_xy_m = out->protection_theta_rad = 0.0f;
    }
    return Status::ok();
  }
  // MML says the pose is isolated: the tracker must confirm it on this scan before it is published.
  // Live schedule (results of earlier scans): the result first, then this scan for MML only if the
  // search goes on. A fix the tracker confirms ends the search: MML's next job starts from a fresh
  // local map (a lost track and every cross-check reset it first), so a job on this scan would be
  // thrown away, and on the 2-core board it would share the cores with the confirming step, the
  // sensor context's longest (aces replay: 10.5 ms, which stretched that global step to 16 ms).
  // The wheels carry the last track's pose on; this scan judged there (dead_reckoning.h).
  dead_reckoning_.advance(wheel, tracker_.options());
  const DeadReckoningVerdict dr = dead_reckoning_.judge(tracker_.map(), pts_, n, tracker_.options());
  // Back on the map by the wheels, and the scan fits there: MML's local map starts again, so it
  // holds only scans the map may explain (its scans of an unmapped wing match only by accident,
  // and they kept it from re-fixing in the mapped room after it).
  if (dead_reckoning_.reentered()) global_.reset();
  const bool delayed = global_.results_delayed();
  const Status got = delayed ? global_.collect(scan, odom, out) : global_.step(scan, odom, out);
  if (!delayed) FW_RETURN_IF_ERROR(got);
  out->mode = hal::LocalizationMode::kGlobal;
  out->protection_xy_m = out->protection_theta_rad = 0.0f;
  // While MML searches it has no pose it trusts, so "outside the map" needs another source
  // (mml_track_preset turns MML's own unknown-region rules off: they said `outside-map` at 937 steps
  // of a fr-clinic whole run, inside its mapped corridors): the tracker's outside-map test on this
  // scan at the dead-reckoned pose, else `searching` — but only from a pose the wheels carried from
  // a track that saw no sign of a carry (TrackOptions::outside_map_needs_clean_exit,
  // DeadReckoning::trusted, carry_seen_): a robot that drove off the map is where the wheels say
  // (its entry into unmapped space may well be a large fault: intel's erased region); after a scan
  // that did not continue the one before it the robot may be anywhere, that pose means nothing, and
  // a scan unknown there is no evidence of unmapped space (the large office kidnap of
  // scripts/run.sh: 82 `outside-map` steps in a building mapped wall to wall).
  // A chain that binds says so over MML's `ambiguous` too: MML's candidates are places on the map,
  // and the wheels, unrefuted, put the robot off it.
  const bool mml_unsure = out->status == hal::LocalizationStatus::kSearching ||
                          (out->status == hal::LocalizationStatus::kAmbiguous && dead_reckoning_.binding());
  const bool pose_speaks = dead_reckoning_.trusted() || !tracker_.options().outside_map_needs_clean_exit;
  if (got.is_ok() && mml_unsure && pose_speaks && dr == DeadReckoningVerdict::kOutside) {
    out->status = hal::LocalizationStatus::kOutsideMap;
    out->reason = hal::StatusReason::kOutsideMap;
  }
  if (got.is_ok() && out->status == hal::LocalizationStatus::kLocalized &&
      !dead_reckoning_.admits(Se2f(out->x, out->y, out->theta), k_, tracker_.options())) {
    // The wheels rule MML's fix out and no scan has refuted them: MML sees only the map, and an
    // unmapped place can resemble a mapped one (dead_reckoning.h).
    ++fixes_refused_by_wheels_;
    const bool outside = dr == DeadReckoningVerdict::kOutside;
    out->status = outside ? hal::LocalizationStatus::kOutsideMap : hal::LocalizationStatus::kAmbiguous;
    out->reason = outside ? hal::StatusReason::kOutsideMap : hal::StatusReason::kFixRejected;
  } else if (got.is_ok() && out->status == hal::LocalizationStatus::kLocalized) {
    const hal::PoseEstimate g = *out;
    if (start_from_fix(g, wheel, n, out) || !delayed) return Status::ok();
  }
  if (delayed) {
    hal::PoseEstimate unused;
    FW_RETURN_IF_ERROR(global_.offer(scan, odom, &unused));
  }
  return got;
}

bool TrackedLocalizer::start_from_fix(const hal::PoseEstimate& g, const Se2f& wheel, std::size_t n,
                                      hal::PoseEstimate* out) {
  Eigen::Matrix3f cov;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) cov(r, c) = g.cov[r * 3 + c];
  const Se2f fix(g.x, g.y, g.theta);
  const TrackOptions& o = tracker_.options();
  const std::size_t k = o.recovery_steps;
  left_map_cleanly_ = true;  // a new track: no scan of it has contradicted it yet
  carry_seen_ = false;
  if (o.confirm_fix && o.confirm_fix_on_past_scans && k > 0 && history_.size() >= k + 1) {
    // TrackOptions::confirm_fix_on_past_scans. The tracker starts recovery_steps scans back, at MML's
    // pose carried back by the wheels (pose_{t−k} = fix ⊕ (wheel_t ⊖ wheel_{t−k})), as it would
    // start on a fix there (MML's covariance, confirmation pending), and steps through the
    // remembered scans, this one and those that arrive meanwhile with their odometry.
    const RememberedScan& r0 = history_[history_.size() - 1 - k];
    replay_fix_ = fix;
    replay_fix_wheel_ = wheel;
    replay_cov_ = cov;
    replay_lag_ = static_cast<std::uint32_t>(k + 1);
    replay_first_ = true;
    tracker_.start(fix.compose(wheel.between(r0.wheel)), cov, r0.wheel, /*confirm=*/true);
    return replay_past_scans(wheel, n, out);
  }
  return start_forward(fix, cov, wheel, n, out);
}

bool TrackedLocalizer::start_forward(const Se2f& fix, const Eigen::Matrix3f& cov, const Se2f& wheel, std::size_t n,
                                     hal::PoseEstimate* out) {
  const bool confirm = tracker_.options().confirm_fix;
  tracker_.start(fix, cov, wheel, confirm);
  limit_search_to_what_this_scan_left();  // after a failed replay on this scan
  const TrackStep ts = step_tracker(pts_, n, wheel, /*predict=*/false);
  // The scan must support MML's pose; with confirm_fix every test but the hysteresis must pass
  // (the scan is consistent, unique, within the alert limits), and the track then recovers.
  const bool accepted = confirm ? ts.reason == hal::StatusReason::kTrackRecovering
                                : ts.status == hal::LocalizationStatus::kLocalized;
  if (accepted && !ts.lost) {
    ++fixes_;
    unconfirmed_ = hint_needs_mml();  // MML has just isolated this pose (unless it is a hint's)
    wait_cause_ = "hint";
    publish_track(ts, out);
    if (unconfirmed_) {
      out->status = hal::LocalizationStatus::kAmbiguous;
      out->reason = hal::StatusReason::kTrackAwaitingMml;
    }
    return true;
  }
  ++fix_rejections_;
  tracker_.stop();
  out->status = hal::LocalizationStatus::kAmbiguous;
  out->reason = hal::StatusReason::kFixRejected;
  out->mode = hal::LocalizationMode::kGlobal;
  out->protection_xy_m = out->protection_theta_rad = 0.0f;
  return false;
}

TrackStep TrackedLocalizer::step_tracker(const Point2f* pts, std::size_t n, const Se2f& wheel, bool predict) {
  const TrackStep ts = tracker_.step(pts, n, wheel, predict);
  search_candidates_this_scan_ += ts.search_candidates;
  if (search_candidates_this_scan_ > most_search_candidates_in_one_scan_) {
    most_search_candidates_in_one_scan_ = search_candidates_this_scan_;
  }
  return ts;
}

// One pre-search budget (search.max_candidates) per scan period, whichever steps of the tracker
// this scan runs: the next step's search gets what the earlier ones left (at least one candidate,
// the prediction itself).
void TrackedLocalizer::limit_search_to_what_this_scan_left() {
  const std::uint32_t cap = tracker_.options().search.max_candidates;
  const std::uint32_t spent = search_candidates_this_scan_;
  if (spent > 0) tracker_.limit_next_search(spent < cap ? cap - spent : 1);
}

// Nothing is published `localized` on the way; only the end on the newest scan counts. While the
// replay lags, the estimate is the replayed pose carried to this scan by the wheels, not `localized`.
bool TrackedLocalizer::replay_past_scans(const Se2f& wheel, std::size_t n, hal::PoseEstimate* out) {
  TrackStep ts;
  Se2f replayed_wheel = wheel;
  // One pre-search budget per scan period (TrackOptions::past_scans_per_step): each step's search
  // gets what this scan's earlier steps left; once it is spent the replay goes on at the next scan.
  const std::uint32_t cap = tracker_.options().search.max_candidates;
  for (std::uint32_t b = 0; b < tracker_.options().past_scans_per_step && replay_lag_ > 0; ++b) {
    if (b > 0 && search_candidates_this_scan_ >= cap) break;
    limit_search_to_what_this_scan_left();
    const RememberedScan& r = history_[history_.size() - replay_lag_];
    ts = step_tracker(r.pts, r.n, r.wheel, /*predict=*/!replay_first_);
    replayed_wheel = r.wheel;
    replay_first_ = false;
    --replay_lag_;
    if (ts.lost) break;
  }
  if (!ts.lost && replay_lag_ > 0) {
    publish_track(ts, out);
    const Se2f now = ts.pose.compose(replayed_wheel.between(wheel));
    out->x = now.x;
    out->y = now.y;
    out->theta = now.theta;
    out->status = hal::LocalizationStatus::kAmbiguous;
    out->reason = hal::StatusReason::kTrackRecovering;
    out->protection_xy_m = out->protection_theta_rad = 0.0f;
    return true;
  }
  const bool confirmed = !ts.lost && replay_lag_ == 0 && ts.status == hal::LocalizationStatus::kLocalized;
  replay_lag_ = 0;
  if (confirmed) {
    ++fixes_;
    ++fixes_on_past_scans_;
    unconfirmed_ = hint_needs_mml();
    wait_cause_ = "hint";
    publish_track(ts, out);
    if (unconfirmed_) {
      out->status = hal::LocalizationStatus::kAmbiguous;
      out->reason = hal::StatusReason::kTrackAwaitingMml;
    }
    return true;
  }
  // Forward confirmation from MML's fix, carried to this scan by the wheels.
  ++fix_replays_failed_;
  tracker_.stop();
  return start_forward(replay_fix_.compose(replay_fix_wheel_.between(wheel)), replay_cov_, wheel, n, out);
}

Status TrackedLocalizer::cross_check(const hal::LaserScan& scan, const hal::Odometry& odom, const Se2f& wheel,
                                     std::size_t n, const TrackStep& ts, hal::PoseEstimate* out) {
  const std::uint32_t budget = tracker_.options().cross_check_steps;
  if (budget == 0) return Status::ok();
  if (unconfirmed_) {  // until MML agrees
    out->status = hal::LocalizationStatus::kAmbiguous;
    out->reason = hal::StatusReason::kTrackAwaitingMml;
  }
  if (ts.status != hal::LocalizationStatus::kLocalized || unconfirmed_) {
    if (cross_check_left_ == 0) global_.reset();  // a fresh local map from this scan on
    cross_check_left_ = budget;                 // runs on for `budget` scans after the last doubt
  }
  if (cross_check_left_ == 0) return Status::ok();
  --cross_check_left_;
  hal::PoseEstimate g;
  FW_RETURN_IF_ERROR(global_.step(scan, odom, &g));
  if (g.status != hal::LocalizationStatus::kLocalized) return Status::ok();
  cross_check_left_ = 0;
  const float d = std::hypot(g.x - ts.pose.x, g.y - ts.pose.y);
  const float dth = std::fabs(wrap_angle(g.theta - ts.pose.theta));
  if (d <= ts.pl.xy_m && dth <= ts.pl.theta_rad) {  // MML isolates the tracked pose
    if (unconfirmed_) {
      unconfirmed_ = false;
      carry_seen_ = false;  // MML has isolated the tracked pose: wherever the robot was carried, it is here
      ++confirmations_;
      out->status = ts.status;  // the tracker's own verdict on this scan stands again
      out->reason = ts.reason;
    }
    return Status::ok();
  }
  // MML isolates a pose the track does not contain. After a large fault (a possible kidnap) the
  // track was waiting for exactly this: MML's fix replaces it. A track that saw no such fault is
  // replaced only when the scan itself prefers MML's pose significantly (the paired test of the
  // alias check): a corridor that looks the same turned 180° (aces scan 6281: MML isolated the
  // track's mirror image, 4.7 m and 180° away, and the track was right) fits both, and then neither
  // pose is `localized` until MML isolates the tracked pose from a fresh local map.
  // A waiting track whose scans showed no sign of a carry is held to the same test
  // (TrackOptions::wheels_bind_mml_without_carry): the robot is where the wheels carried it.
  // A hinted track not yet `localized` is the operator's word against MML's: MML's fix replaces it.
  if (!hint_track_ && (!unconfirmed_ || (tracker_.options().wheels_bind_mml_without_carry && !carry_seen_))) {
    const TrackOptions& o = tracker_.options();
    const Se2f mml_pose(g.x, g.y, g.theta);
    const bool scan_prefers_mml = rival_significantly_better(tracker_.map(), pts_, n, ts.pose, mml_pose, o.alias_clip_m,
                                                             ts.alignment.independent, o.alias_z);
    if (!scan_prefers_mml) {
      ++cross_check_conflicts_;
      unconfirmed_ = true;
      wait_cause_ = "mml-conflict";
      out->status = hal::LocalizationStatus::kAmbiguous;
      out->reason = hal::StatusReason::kTrackAwaitingMml;
      global_.reset();
      cross_check_left_ = o.cross_check_steps;
      return Status::ok();
    }
  }
  // The track sat in a look-alike (or the hint named one).
  if (hint_track_) {
    hint_track_ = false;
    hint_status_ = hal::HintStatus::kRefused;
    ++hints_refused_;
  }
  ++cross_check_switches_;
  ++tracks_lost_;
  *out = hal::PoseEstimate();
  out->timestamp_ns = scan.timestamp_ns;
  out->scan_id = scan.scan_id;
  out->status = hal::LocalizationStatus::kAmbiguous;
  out->mode = hal::LocalizationMode::kGlobal;
  start_from_fix(g, wheel, n, out);
  return Status::ok();
}

}  // namespace track
}  // namespace fw
