#include "firmware/track/pose_tracker.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <limits>

#include "firmware/base/sym2_eigen.h"
#include "firmware/map/distance_sample.h"
#include "firmware/mml/pose_uniqueness.h"
#include "firmware/track/dead_reckoning.h"
#include "firmware/track/fit_comparison.h"

namespace fw {
namespace track {

const char* verdict_name(ScanVerdict v) {
  switch (v) {
    case ScanVerdict::kSupported: return "supported";
    case ScanVerdict::kUninformative: return "uninformative";
    case ScanVerdict::kContradicting: return "contradicting";
    case ScanVerdict::kOutsideMap: return "outside-map";
    case ScanVerdict::kAmbiguous: return "ambiguous";
  }
  return "unknown";
}

const char* large_fault_name(LargeFault f) {
  switch (f) {
    case LargeFault::kNone: return "none";
    case LargeFault::kOdometryJump: return "odometry-jump";
    case LargeFault::kUnexplained: return "unexplained";
    case LargeFault::kInnovation: return "innovation";
    case LargeFault::kBetterRival: return "better-rival";
    case LargeFault::kOdometryWindow: return "odometry-window";
  }
  return "unknown";
}

namespace {
void set_large_fault(TrackStep* out, bool large, LargeFault why) {
  out->large_fault = large;
  out->large_fault_cause = large ? why : LargeFault::kNone;
}
}  // namespace

Status PoseTracker::init(const TrackOptions& options, const GlobalMap& map) {
  FW_RETURN_IF_ERROR(options.validate());
  if (!map.valid()) return Status::error(Errc::kInvalidArgument, "PoseTracker: global map is empty");
  options_ = options;
  map_ = map;
  k_ = ProtectionFactors::for_risk(options.integrity_risk);
  odometry_check_.configure(options.odometry_window, options.odom_scale_error);
  initialized_ = true;
  reset();
  return Status::ok();
}

void PoseTracker::reset() { stop(); }

void PoseTracker::stop() {
  active_ = false;
  pose_ = Se2f();
  cov_.setZero();
  prev_odom_ = odom_at_fuse_ = Se2f();
  pose_at_fuse_ = Se2f();
  predicted_since_fuse_ = 0;
  fuse_next_ = true;
  bias_xy_m_ = map_.geometry.resolution;
  bias_theta_rad_ = 0.0f;
  unsupported_ = faulty_ = outside_ = 0;
  unpinned_m_ = 0.0f;
  turn_since_fuse_rad_ = 0.0f;
  excess_xy_m_ = 0.0f;
  consistent_since_fault_ = 0;
  had_fault_ = false;
  contradicted_ = false;
  fit_fraction_ = 0.0f;
  fit_cells_ = 0;
  odometry_check_.clear();
  last_ = TrackStep();
}

void PoseTracker::start(const Se2f& pose, const Eigen::Matrix3f& cov, const Se2f& odom, bool confirm) {
  stop();
  active_ = initialized_;
  had_fault_ = contradicted_ = confirm;
  pose_ = pose;
  cov_ = cov * options_.init_cov_scale;
  const float fxy = options_.init_sigma_xy_floor_m * options_.init_sigma_xy_floor_m;
  const float ft = options_.init_sigma_theta_floor_rad * options_.init_sigma_theta_floor_rad;
  if (!cov_.allFinite()) cov_.setZero();
  cov_ = 0.5f * (cov_ + cov_.transpose()).eval();
  if (cov_(0, 0) < fxy) cov_(0, 0) = fxy;
  if (cov_(1, 1) < fxy) cov_(1, 1) = fxy;
  if (cov_(2, 2) < ft) cov_(2, 2) = ft;
  prev_odom_ = odom;
  odom_at_fuse_ = odom;
  pose_at_fuse_ = pose;
}

// x⁻ = x ⊕ Δ, P⁻ = F P Fᵀ + G Q Gᵀ with Q diagonal in the robot frame of the increment.
void PoseTracker::predict_to(const Se2f& odom) {
  const Se2f delta = prev_odom_.between(odom);
  prev_odom_ = odom;
  ++predicted_since_fuse_;
  const Eigen::Matrix3f q = odometry_increment_noise(delta, options_);
  const Eigen::Matrix3f f = pose_.jacobian_compose_first(delta);
  const Eigen::Matrix3f g = pose_.jacobian_compose_second();
  pose_ = pose_.compose(delta);
  cov_ = f * cov_ * f.transpose() + g * q * g.transpose();
  odometry_check_.advance(delta, q);
  cov_ = 0.5f * (cov_ + cov_.transpose()).eval();
}

namespace {
// The fit-drop test's statistic (judge_scan): the previous scan's inlier fraction p1 over its n1
// correlation cells against this alignment's, z = (p1 − p2) / se with the pooled proportion (0 when
// se is 0).
float fit_drop_statistic(float p1, std::uint32_t cells1, const ScanAlignment& a) {
  const float p2 = a.inlier_fraction();
  const float n1 = static_cast<float>(cells1), n2 = static_cast<float>(a.independent);
  const float pooled = (p1 * n1 + p2 * n2) / (n1 + n2);
  const float se = std::sqrt(pooled * (1.0f - pooled) * (1.0f / n1 + 1.0f / n2));
  return se > 0.0f ? (p1 - p2) / se : 0.0f;
}
bool outside_bound(const Eigen::Vector3f& e, const ProtectionLevel& pl) {
  return std::hypot(e(0), e(1)) > pl.xy_m || std::fabs(e(2)) > pl.theta_rad;
}
// A motion as large as the update thresholds (AMCL's update_min_d / update_min_a).
bool beyond_update_thresholds(const Se2f& motion, const TrackOptions& o) {
  return std::hypot(motion.x, motion.y) >= o.update_min_d_m || std::fabs(motion.theta) >= o.update_min_a_rad;
}
}  // namespace

// At most kAliasMaxPoints end-points, evenly subsampled into alias_points_ (beam order kept).
std::size_t PoseTracker::subsample_alias_points(const Point2f* points, std::size_t n) {
  if (n == 0) return 0;
  const std::size_t stride = (n + kAliasMaxPoints - 1) / kAliasMaxPoints;
  std::size_t m = 0;
  for (std::size_t i = 0; i < n && m < kAliasMaxPoints; i += stride) alias_points_[m++] = points[i];
  return m;
}

// Gauss-Newton from the prediction; while recovering from a fault with a prediction too uncertain for
// its capture range, also from the best pose of a correlative search over the prediction's window
// (correlative_search.h), kept only when it explains the scan clearly better.
ScanAlignment PoseTracker::align_from_prediction(const Point2f* points, std::size_t n, const Se2f& pred,
                                                 TrackStep* out) {
  const TrackOptions& o = options_;
  ScanAlignment a = align_scan(map_, points, n, pred, o.align);
  // Only while recovering from a fault: the covariance was widened by the size of a disagreement,
  // so the prediction may lie beyond Gauss-Newton's capture range. On a healthy track the AMCL-style
  // model's σ is large on long steps (fr101: 10° per 0.7 m) while the odometry is good, and a search
  // there costs time and can trade the right minimum for a coarse-grid neighbour.
  if (!o.search.enabled || n == 0 || !had_fault_ || consistent_since_fault_ >= o.recovery_steps) return a;
  const Sym2Eigen exy = sym2_eigen(cov_(0, 0), cov_(0, 1), cov_(1, 1));
  const float sxy = std::sqrt(std::fmax(exy.lambda_max, 0.0f));
  const float sth = std::sqrt(std::fmax(cov_(2, 2), 0.0f));
  if (!(sxy > o.search.trigger_sigma_xy_m || sth > o.search.trigger_sigma_theta_rad)) return a;
  CorrelativeWindow w;
  w.xy_m = std::fmin(o.search.window_sigmas * sxy, o.search.max_window_xy_m);
  w.theta_rad = std::fmin(o.search.window_sigmas * sth, o.search.max_window_theta_rad);
  CorrelativeSearchOptions so = o.search;
  if (search_cap_ > 0 && search_cap_ < so.max_candidates) so.max_candidates = search_cap_;
  const CorrelativeResult cr = correlative_search(map_, points, n, pred, w, so, search_scratch_, kSearchScratch);
  out->search_candidates = cr.candidates;
  if (cr.candidates == 0 || !(cr.score > cr.seed_score)) return a;
  const ScanAlignment b = align_scan(map_, points, n, cr.pose, o.align);
  const float sa = fit_score(map_, points, n, a.pose, o.search.clip_m);
  const float sb = fit_score(map_, points, n, b.pose, o.search.clip_m);
  if (sb > sa + o.search.min_score_gain) {
    out->search_moved = true;
    return b;
  }
  return a;
}

// The scan's own confidence region (track_options.h, fit_comparison.h), bounded by what the prediction
// already promised: where it reaches farther than the covariance's protection level `pl`, the excess
// is kept and added to the PL of this and of every following scan until the next scan that supports
// the pose (so the bound never shrinks on scans that say nothing; the covariance itself is left alone
// — widening it instead weakened the fusion and the innovation tests: aces availability 0.98 → 0.64).
// The cap is the prediction's PL *plus how far the update moved the pose from the prediction*: the
// truth lies within pred_pl of the prediction, so within pred_pl + |published − prediction| of the
// published pose (triangle inequality). Capping at pred_pl alone bounded the error about a point the
// tracker no longer publishes (aces scans 4807, 6560: fused corridor steps 0.14–0.17 m off with a PL
// 0.006–0.016 m short; both covered with the shift added).
void PoseTracker::update_confidence_excess(const Point2f* points, std::size_t n, const ScanAlignment& a,
                                           const StepWork& w, const ProtectionLevel& pl, TrackStep* out) {
  const TrackOptions& o = options_;
  ConfidenceExtentOptions co;
  co.clip_m = o.alias_clip_m;
  co.z = o.alias_z;
  co.max_xy_m = o.confidence_extent_xy ? o.alert_limit_m : 0.0f;
  co.max_rad = 0.0f;  // position only: in heading the paired test is weak (track_options.h)
  const std::size_t m = subsample_alias_points(points, n);
  const ConfidenceExtent ce = confidence_extent(map_, alias_points_, m, a.pose, a.information(0, 0),
                                                a.information(0, 1), a.information(1, 1), a.independent, co);
  out->confidence_xy_m = ce.xy_m;
  out->confidence_theta_rad = ce.theta_rad;
  // A scan not fused leaves the pose on the prediction, and the prediction carries the bound the
  // last scan published, this excess included: the cap below holds it. Capped at the covariance's
  // PL alone, the excess fell to 0 whenever the robot stopped (no fused scan), though nothing had
  // been learnt (fr079 scans 2155–2182: PL 0.18 → 0.11 m at the stop, error 0.11–0.15 m against
  // the reference; whole run, PL exceedance 0.0023 → 0.0004, availability unchanged). A fused
  // scan moves the pose, and its own shift from the prediction is what the cap adds (`moved`).
  const float carried_xy = out->fused ? 0.0f : excess_xy_m_;
  excess_xy_m_ = 0.0f;
  // The update's shift from the prediction, per axis (0 = the old cap).
  const float with_update = o.confidence_cap_with_update ? 1.0f : 0.0f;
  // Open along both axes up to the alert limit: the scan checks nothing of the odometry (track_options.h).
  const bool pins_nothing = o.confidence_cap_needs_a_pinned_axis && o.confidence_extent_xy &&
                            ce.axis_m[0] >= co.max_xy_m - 1e-4f && ce.axis_m[1] >= co.max_xy_m - 1e-4f;
  out->confidence_pins_nothing = pins_nothing;
  if (o.confidence_extent_xy) {
    const float moved = with_update * std::hypot(pose_.x - w.pred.x, pose_.y - w.pred.y);
    const float cap = pins_nothing ? INFINITY : w.pred_pl.xy_m + carried_xy + moved;
    const float bound = std::fmin(ce.xy_m + std::hypot(pose_.x - a.pose.x, pose_.y - a.pose.y) + bias_xy_m_, cap);
    excess_xy_m_ = std::fmax(bound - pl.xy_m, 0.0f);
  }
}

// One scan: (1) odometry prediction, (2) alignment, (3) the scan's verdict on the pose (fault
// detection), (4) alias check, (5) the update and the odometry-consistency test, (6) the track's
// state, (7) protection level and status.
TrackStep PoseTracker::step(const Point2f* points, std::size_t n, const Se2f& odom, bool predict) {
  TrackStep out;
  search_cap_ = next_search_cap_;
  next_search_cap_ = 0;
  if (!active_) {
    out.lost = true;
    last_ = out;
    return out;
  }
  const TrackOptions& o = options_;
  bool odom_jump = false;
  if (predict) {
    const Se2f d = prev_odom_.between(odom);
    odom_jump = !(std::hypot(d.x, d.y) <= o.max_odom_step_m && std::fabs(d.theta) <= o.max_odom_step_rad);
    unpinned_m_ += std::hypot(d.x, d.y);
    turn_since_fuse_rad_ += std::fabs(d.theta);
    predict_to(odom);
  }
  StepWork w;
  w.predicted = predict;
  w.pred = pose_;
  w.pred_pl = protection_level(cov_, k_, bias_xy_m_, bias_theta_rad_);
  w.p_post = cov_;
  const StepWork w0 = w;
  const TrackStep out0 = out;
  out.alignment = align_from_prediction(points, n, w.pred, &out);
  judge_scan(points, n, odom_jump, &w, &out);
  if (w.v == ScanVerdict::kContradicting && !out.heading_fault && !odom_jump && predict) {
    try_turn_hypothesis(points, n, w0, out0, &w, &out);
  }
  if (w.v == ScanVerdict::kSupported && o.alias_check) check_aliases(points, n, &w, &out);
  // A rival the scan fits significantly better, within what the prediction promises (its PL), is
  // the fix Gauss-Newton missed from a prediction some degrees off (the white wheels' 4° per step),
  // not a sign that the robot is elsewhere: the innovation test's own criterion (judge_scan). The
  // scan is aligned again from the rival and judged again, once; beyond the prediction's PL the
  // rival stays a contradiction (a large fault beyond the alert limits) — unless it lies at the
  // predicted position turned within the turn the wheels reported, the turn hypothesis
  // (try_turn_hypothesis; seed 808 #200: wheels that over-reported 31° of a 43° turn, the alias
  // check's turned rival was the truth).
  if (w.rival_better && o.refit_at_better_rival) {
    const Se2f r = out.alias_rival;
    const Eigen::Vector3f er(r.x - w.pred.x, r.y - w.pred.y, wrap_angle(r.theta - w.pred.theta));
    if (!outside_bound(er, w.pred_pl) || rival_within_reported_turn(er, w.pred_pl)) {
      const std::uint32_t searched = out.search_candidates;
      w = w0;
      out = out0;
      out.search_candidates = searched;
      out.refit_at_rival = true;
      out.alignment = align_scan(map_, points, n, r, o.align);
      judge_scan(points, n, odom_jump, &w, &out);
      if (w.v == ScanVerdict::kSupported) check_aliases(points, n, &w, &out);
    }
  }
  const Update u = propose_update(odom, predict, &w, &out);
  out.verdict = w.v;
  apply_verdict(odom, w, u, &out);
  // The fit-drop test compares consecutive scans (whatever their verdict): after a drop the next
  // scan is compared with the dropped one, so a place that fits worse faults once, not at every scan.
  if (out.alignment.inliers + out.alignment.contradicting >= o.min_points) {
    fit_fraction_ = out.alignment.inlier_fraction();
    fit_cells_ = out.alignment.independent;
  }
  publish(points, n, w, &out);
  last_ = out;
  return out;
}

// TrackOptions::repin_needs_confirmation. The innovation test passes a scan fix within the
// prediction's PL of the prediction (outside_bound), and the update moves the pose by the gain
// G = I − P_post·P_pred⁻¹ times the fix's error. So an undetected fault of the scan's fix (a moved
// rack, a repeated feature) shifts the fused pose by up to |G|·PL_pred: RAIM's protection level, the
// largest slope times the detection threshold (the classic RAIM PL, reviewed by Zhao, Song, Wang,
// Sensors 24(11) 3283, 2024), with the innovation gate as the
// threshold. Where that reaches the alert limit, nothing but this scan vouches for the pose along
// the axis it pins. The position only: that is where one feature may pin an axis (a rack's end along
// an aisle, a door frame along a corridor) and where moved furniture and repeated features put a
// fix's fault. Every wall seen sets the heading; a heading fault with the position right needs a map
// rotated locally, which the map bias b_θ bounds (README, assumption 2). Heading gains are near 1
// at every scan (the wheels' heading PL is ~5° after a few steps), so a heading clause would hold
// every scan for confirmation (PoseTrackerTest.TracksWithinProtectionLevel: 14 of 191 `localized`).
bool PoseTracker::undetected_fault_reaches_alert(const Eigen::Matrix3f& p_pred, const Eigen::Matrix3f& p_post,
                                                 const ProtectionLevel& pred_pl) const {
  const Eigen::Matrix3d inv = p_pred.cast<double>().inverse();
  if (!inv.allFinite() || !std::isfinite(pred_pl.xy_m) || !std::isfinite(pred_pl.theta_rad)) return true;
  const Eigen::Matrix3d g = Eigen::Matrix3d::Identity() - p_post.cast<double>() * inv;
  // σ_max of the position block: √λ_max(GᵀG).
  const Eigen::Matrix2d gxy = g.topLeftCorner<2, 2>();
  const Eigen::Matrix2d gtg = gxy.transpose() * gxy;
  const double s_xy = std::sqrt(std::fmax(sym2_eigen(gtg(0, 0), gtg(0, 1), gtg(1, 1)).lambda_max, 0.0f));
  const double shift_xy = s_xy * pred_pl.xy_m + std::hypot(g(0, 2), g(1, 2)) * pred_pl.theta_rad;
  return shift_xy > options_.alert_limit_m;
}

// The turn hypothesis's reach: at the predicted position (within its PL), turned by no more than
// the wheels reported turning since a scan last set the heading, plus the prediction's heading PL.
// An over-reported turn is part of a reported turn; a carry into a place that looks like the old
// one turned has no such turn (seed 707 #136: a twin aisle; a search unbounded by it, 13 wrong steps).
bool PoseTracker::rival_within_reported_turn(const Eigen::Vector3f& e, const ProtectionLevel& pred_pl) const {
  if (!options_.heading_fault_local_recovery) return false;
  return std::hypot(e(0), e(1)) <= pred_pl.xy_m && std::fabs(e(2)) <= turn_since_fuse_rad_ + pred_pl.theta_rad;
}

// (3b) The wheels misreported the turn (the corpus's turn-spin wheels, mit-killian's over-reported
// turns): the scan contradicts the prediction, and Gauss-Newton from a prediction 8–20° off stops
// short or slides (dev seed 5 #49: a fix 0.22 m off, then a wait of 30 m for MML while right). The
// hypothesis is tested directly: a correlative search at the predicted position (within its PL) over
// the headings the wheels' reported turn allows, aligned from its best pose and judged again. It is
// kept only as a heading-only fault — judge_scan's own test: the fix within the prediction's position
// PL, the scan fitting it significantly better than the prediction — and within the reported turn,
// else the first verdict stands.
void PoseTracker::try_turn_hypothesis(const Point2f* points, std::size_t n, const StepWork& w0,
                                      const TrackStep& out0, StepWork* w, TrackStep* out) {
  const TrackOptions& o = options_;
  if (!o.heading_fault_local_recovery || !o.search.enabled || n == 0) return;
  const float turn_rad = turn_since_fuse_rad_ + w0.pred_pl.theta_rad;
  if (turn_rad <= o.alert_limit_rad) return;  // no heading-only fault can pass judge_scan's test
  CorrelativeWindow win;
  win.xy_m = std::fmin(w0.pred_pl.xy_m, o.search.max_window_xy_m);
  // The whole turn the wheels allow, not the pre-search's 20° cap: two events within one scan step
  // over-reported 31° (seed 808 #200). The candidate budget coarsens the grid; Gauss-Newton refines.
  win.theta_rad = std::fmin(turn_rad, static_cast<float>(M_PI));
  // One candidate budget per scan (limit_next_search), shared with this step's pre-search.
  CorrelativeSearchOptions so = o.search;
  if (search_cap_ > 0 && search_cap_ < so.max_candidates) so.max_candidates = search_cap_;
  if (out->search_candidates >= so.max_candidates) return;
  so.max_candidates -= out->search_candidates;
  const CorrelativeResult cr = correlative_search(map_, points, n, w0.pred, win, so, search_scratch_, kSearchScratch);
  if (cr.candidates == 0 || !(cr.score > cr.seed_score)) return;
  StepWork w1 = w0;
  TrackStep out1 = out0;
  out1.search_candidates = out->search_candidates + cr.candidates;
  out1.turn_searched = true;
  out1.alignment = align_scan(map_, points, n, cr.pose, o.align);
  judge_scan(points, n, false, &w1, &out1);
  if (!out1.heading_fault || !rival_within_reported_turn(w1.e, w0.pred_pl)) return;
  *w = w1;
  *out = out1;
}

// (3) Verdict of this scan on the pose: outside the map, uninformative, a poor fit, or a fix that
// fails the innovation test against the prediction (a fault; large beyond the alert limits).
void PoseTracker::judge_scan(const Point2f* points, std::size_t n, bool odom_jump, StepWork* w, TrackStep* out) {
  const TrackOptions& o = options_;
  const ScanAlignment& a = out->alignment;
  if (odom_jump) {
    w->v = ScanVerdict::kContradicting;  // the pose cannot be carried across a non-physical increment
    set_large_fault(out, true, LargeFault::kOdometryJump);
    return;
  }
  if (a.points > 0 && a.unknown_fraction() > o.outside_map_fraction) {
    w->v = ScanVerdict::kOutsideMap;
    if (a.inliers + a.contradicting >= o.min_points) {
      out->known_part_contradicts = a.inlier_fraction() < o.min_inlier_fraction ||
                                    (o.fit_drop_z > 0.0f && fit_cells_ >= 2 && a.independent >= 2 &&
                                     fit_drop_statistic(fit_fraction_, fit_cells_, a) > o.fit_drop_z);
    }
    return;
  }
  // The map must explain most of what the laser sees, unknown end-points included: the outside-map
  // and inlier tests each allow half, so together a pose explaining a quarter of the scan passed
  // (aces kidnap 1628 → 2472: at the first scan after the carry the old place explained 66 of 177
  // end-points, 88 in unknown space, 23 on free cells, and the track said `localized` 27.5 m off).
  // A scan the map cannot explain is what a robot carried elsewhere sees: a fault of unknown size.
  // Few end-points on mapped cells make a scan uninformative about the fit, not about this: with
  // enough end-points in all, it is asked first (corpus seed 1313 #135: 8 of 39 explained, 12 on
  // free cells, 19 unknown, 37.9 m after a carry, coasting `localized` on the wheels).
  const bool unexplained = static_cast<float>(a.inliers) < o.min_explained_fraction * static_cast<float>(a.points);
  if (a.inliers + a.contradicting < o.min_points && !(unexplained && a.points >= o.min_points)) {
    w->v = ScanVerdict::kUninformative;
    return;
  }
  if (a.inliers + a.contradicting >= o.min_points && a.inlier_fraction() < o.min_inlier_fraction) {
    w->v = ScanVerdict::kContradicting;
    return;
  }
  if (unexplained) {
    w->v = ScanVerdict::kContradicting;
    out->unexplained = true;
    set_large_fault(out, true, LargeFault::kUnexplained);
    return;
  }
  // A sudden drop of the fit: two-proportion test of this scan's inlier fraction against the
  // previous scan's, each counted over its correlation cells (the alignment's independent
  // observations). A robot carried elsewhere whose first scan still fits near the old pose fits it
  // worse (fr079 kidnap 2143 → 3613: 1.00 of 46 cells, then 0.58 of 23, z 4.8; `localized` 15.3 m
  // off without this). On whole runs of the seven logs, 10 of 42,519 scans at right poses exceed
  // z 3.09 (people stepping close, a door opening). A fault, not a large one: the track needs
  // recovery_steps consistent scans, and no alias rival is ruled out meanwhile (contradicted_); as
  // a large fault it waited for MML after every such scan (fr-campus availability 0.49 → 0.36).
  if (o.fit_drop_z > 0.0f && fit_cells_ >= 2 && a.independent >= 2) {
    w->fit_drop_z = fit_drop_statistic(fit_fraction_, fit_cells_, a);
    if (w->fit_drop_z > o.fit_drop_z) {
      w->v = ScanVerdict::kContradicting;
      out->fit_drop = true;
      return;
    }
  }
  // Innovation of the scan fix against the prediction: d² = eᵀ S⁻¹ e with S = P⁻ + H⁻¹, computed as
  // S⁻¹ = H − H P⁺ H (P⁺ = (P⁻⁻¹ + H)⁻¹), which stays finite where H is singular (corridor axis).
  const Se2f& pred = w->pred;
  w->e = Eigen::Vector3f(a.pose.x - pred.x, a.pose.y - pred.y, wrap_angle(a.pose.theta - pred.theta));
  const Eigen::Matrix3d pinv = cov_.cast<double>().inverse();
  const Eigen::Matrix3d hd = a.information.cast<double>();
  const Eigen::Matrix3d post = (pinv + hd).inverse();
  const Eigen::Matrix3d sinv = hd - hd * post * hd;
  const Eigen::Vector3d ed = w->e.cast<double>();
  out->innovation_chi2 = static_cast<float>(ed.dot(sinv * ed));
  if (!std::isfinite(out->innovation_chi2) || !post.allFinite()) {
    w->v = ScanVerdict::kContradicting;
  } else if (out->innovation_chi2 > o.innovation_chi2 && outside_bound(w->e, w->pred_pl)) {
    // A significant innovation is a fault only when the scan fix lies outside what the prediction
    // promises (its protection level): within it, the published bound already covers the
    // disagreement, and the scan is fused (measurement models of real scans are never exact).
    w->innovation_fault = true;
    w->v = ScanVerdict::kContradicting;
    // Beyond an alert limit: the robot may be somewhere else (the aces kidnap into a twin corridor
    // showed as 0.27 m and 6° at the first scan: the target fits the map next to the prediction).
    const float exy = std::hypot(w->e(0), w->e(1));
    set_large_fault(out, exy > o.alert_limit_m || std::fabs(w->e(2)) > o.alert_limit_rad, LargeFault::kInnovation);
    if (out->large_fault && o.heading_fault_local_recovery && exy <= w->pred_pl.xy_m && exy <= o.alert_limit_m) {
      // Heading only (track_options.h): the scan must prefer its fix to the prediction significantly.
      const std::size_t m = subsample_alias_points(points, n);
      out->heading_fault = rival_significantly_better(map_, alias_points_, m, pred, a.pose, o.alias_clip_m,
                                                      a.independent, o.alias_z);
      set_large_fault(out, !out->heading_fault, LargeFault::kInnovation);
    }
  } else {
    w->p_post = post.cast<float>();
  }
}

// (4) Alias check at the scan fix: does the scan fit as well (or better) somewhere else nearby?
void PoseTracker::check_aliases(const Point2f* points, std::size_t n, StepWork* w, TrackStep* out) {
  const TrackOptions& o = options_;
  const ScanAlignment& a = out->alignment;
  mml::UniquenessOptions uo;
  uo.clip_m = o.alias_clip_m;
  uo.max_shift_m = o.alias_max_shift_m;
  uo.shift_step_m = o.alias_step_m;
  uo.min_separation_m = o.alias_min_separation_m;
  uo.margin = o.alias_margin;
  uo.rotation_step_rad = o.alias_rotation_step_rad;
  uo.max_rotation_rad = o.alias_max_rotation_rad;
  uo.min_separation_rad = o.alias_min_separation_rad;
  // The exemptions below (and the one-valley rule) rest on a track that was right at the last scan.
  const bool trusted = !contradicted_ && !(o.alias_trust_needs_steady_fit && w->fit_drop_z >= o.alias_credible_z);
  uo.valley_is_one_mode = o.alias_valley_is_one_mode && trusted;
  const std::size_t m = subsample_alias_points(points, n);
  const mml::UniquenessResult u = mml::check_pose_uniqueness(map_, alias_points_, m, a.pose, uo);
  out->alias_cost = u.cost;
  out->alias_rival_cost = u.rival_cost;
  out->alias_rival = u.rival;
  if (uo.valley_is_one_mode && o.alias_valley_drops_information && u.valley_extent_m > 0.0f) {
    w->valley = true;
    w->valley_axis = Eigen::Vector2f(u.valley_axis_x, u.valley_axis_y);
  }
  if (u.rival_cost < u.cost - o.alias_margin &&
      rival_significantly_better(map_, alias_points_, m, a.pose, u.rival, o.alias_clip_m, a.independent, o.alias_z)) {
    w->v = ScanVerdict::kContradicting;  // the scan says the robot is elsewhere
    w->rival_better = true;
    // The fault's size is where the scan puts the robot against where the track says it is: the
    // prediction (this scan is not fused, so the published pose is the prediction), not the fix
    // Gauss-Newton reached from it, which the scan may already have pulled most of the way (seed
    // 1111 #135: carried during a spin into a place like the old one turned 90°; the rival 8.5°
    // from the prediction, < 5° from the fix; a small fault, recovered locally, then 4 steps
    // `localized` 10 m off).
    set_large_fault(out,
                    std::hypot(u.rival.x - w->pred.x, u.rival.y - w->pred.y) > o.alert_limit_m ||
                        std::fabs(wrap_angle(u.rival.theta - w->pred.theta)) > o.alert_limit_rad,
                    LargeFault::kBetterRival);
  } else if (!u.unique) {
    w->v = ScanVerdict::kAmbiguous;  // fused (odometry keeps the mode), never `localized`
    const bool beyond = std::hypot(u.rival.x - a.pose.x, u.rival.y - a.pose.y) > o.alert_limit_m ||
                        std::fabs(wrap_angle(u.rival.theta - a.pose.theta)) > o.alert_limit_rad;
    // Is the rival a place the robot could be (track_options.h, alias_rival_must_be_credible)? Both
    // exemptions below rest on a track that was right at the last scan, so they hold only on a
    // trusted track — no contradicting scan since the last `recovery_steps` unique consistent scans
    // (aliased scans neither break nor restore that trust), and no drop of the fit on this scan at
    // alias_credible_z (alias_trust_needs_steady_fit: mit-killian carry 3914 → 3828) (mit-killian kidnap
    // 15955 → 16341: 47 m along the same corridor, seen as a heading fault, then 35 aliased scans
    // along the corridor and `localized` 45 m off without this). Not credible is a rival at the
    // fix's heading that is either (a) joined to the fix by poses that fit as well — one mode with
    // it (a corridor's walls fit wherever the robot stands along it; the scan leaves that axis to the
    // odometry) — or (b) outside the prediction's protection level, where a track that was right at
    // the last scan does not reach at the integrity risk (the bound the innovation test trusts). A
    // turned rival always is: walls that fit as well turned are a scan that does not pin the heading
    // here (intel kidnap 6735 → 7812: a place fitting 5–10° turned).
    const bool same_heading = std::fabs(wrap_angle(u.rival.theta - a.pose.theta)) < o.alias_min_separation_rad;
    const bool beyond_prediction = std::hypot(u.rival.x - w->pred.x, u.rival.y - w->pred.y) > w->pred_pl.xy_m;
    // Neither exemption covers a rival that fits better at alias_credible_z (track_options.h): the
    // prediction's bound says where a track that was right can be, not where a carried robot is
    // (mit-killian kidnap 3908 → 3827, 10.8 m back along the corridor: the first scan fit a rival
    // 1.1 m from the fix better, cost 0.36 against 0.54, paired test between z 1.64 and 3.09; exempt
    // as beyond the prediction, the track said `localized` 11.4 m off 8 scans later).
    const bool fits_better =
        u.rival_cost < u.cost - o.alias_margin &&
        rival_significantly_better(map_, alias_points_, m, a.pose, u.rival, o.alias_clip_m, a.independent,
                                   o.alias_credible_z);
    out->alias_rival_credible =
        !trusted || !same_heading || fits_better ||
        (!beyond_prediction && !mml::in_same_cost_valley(map_, alias_points_, m, a.pose, u.rival, o.alias_clip_m,
                                                         0.5f * o.alias_clip_m, o.alias_margin));
    out->alias_beyond_alert = beyond && (out->alias_rival_credible || !o.alias_rival_must_be_credible);
  }
}

// (5) The update this scan would make (x = x⁻ + P⁺ H e, information-form Kalman update linearised at
// the scan fix), once the robot moved; tested against the odometry over the last fused scans first.
PoseTracker::Update PoseTracker::propose_update(const Se2f& odom, bool predict, StepWork* w, TrackStep* out) {
  const TrackOptions& o = options_;
  const ScanAlignment& a = out->alignment;
  Update u;
  u.bias_xy = map_.geometry.resolution + a.rms_m;
  u.bias_theta = u.bias_xy / std::fmax(a.lever_m, 1.0f);
  u.pose = pose_;
  u.cov = cov_;
  if (w->v != ScanVerdict::kSupported && w->v != ScanVerdict::kAmbiguous) return u;
  // Moved: by the wheels, or by the scan. Wheels that slip or lag under-report a fast turn (fr079
  // scan 729: odometry 1.3°, the robot 5.7°); holding the prediction there because "the robot
  // stood still" published a pose 5° off. So a scan fix as far from the last fused pose as the
  // thresholds is the data saying the robot moved — on a trusted track only: while it recovers
  // from a fault its fixes are suspect (mit-killian scans 14894–14902: after a heading fault the
  // fixes of a standing robot wandered 4 cm / 0.3°, fusing them let the track lag the next fast
  // turn 5–10°), and the first scan after the fault is fused anyway (fuse_next_).
  const Se2f since = odom_at_fuse_.between(odom);
  const Se2f seen = pose_at_fuse_.between(a.pose);
  const bool trusted = !had_fault_ || consistent_since_fault_ >= o.recovery_steps;
  // Wheels with per-step noise (odom_trans_per_step_m / odom_rot_per_step_rad) drift unreported
  // while the robot stands: once that drift since the last fused scan (σ·√k over k predicted scans)
  // reaches the thresholds, the prediction has moved as far as a reported motion would have.
  const float k = static_cast<float>(predicted_since_fuse_);
  const bool drifted = predicted_since_fuse_ > 0 && (o.odom_trans_per_step_m * std::sqrt(k) >= o.update_min_d_m ||
                                                     o.odom_rot_per_step_rad * std::sqrt(k) >= o.update_min_a_rad);
  const bool moved = fuse_next_ || !predict || beyond_update_thresholds(since, o) ||
                     (trusted && beyond_update_thresholds(seen, o)) || drifted;
  Eigen::Matrix3f h = a.information;
  if (w->valley) {
    // alias_valley_drops_information: no information along the valley's axis (P H P). The axis is
    // the weak eigenvector of H's position block when the valley runs along it (within 30°): the
    // rival's refined position is a few centimetres off the line, and a tilted axis would leak the
    // strong across-corridor information into it (a corridor's 1 cm across, tilted 3°, pins the
    // axis to 20 cm per scan).
    const Sym2Eigen eig = sym2_eigen(a.information(0, 0), 0.5f * (a.information(0, 1) + a.information(1, 0)),
                                     a.information(1, 1));
    Eigen::Vector2f axis(eig.vmin_x, eig.vmin_y);
    if (std::fabs(axis.dot(w->valley_axis)) < 0.866f) axis = w->valley_axis;
    Eigen::Matrix3f proj = Eigen::Matrix3f::Identity();
    proj.topLeftCorner<2, 2>() -= axis * axis.transpose();
    const Eigen::Matrix3f hv = proj * a.information * proj;
    const Eigen::Matrix3d post = (cov_.cast<double>().inverse() + hv.cast<double>()).inverse();
    if (post.allFinite()) {
      w->p_post = post.cast<float>();
      h = hv;
      out->valley_dropped = true;
    }
  }
  const Eigen::Vector3f dx = w->p_post * (h * w->e);
  if (!dx.allFinite()) return u;
  if (!moved) {
    w->unfused = dx;
    return u;
  }
  u.fuse = true;
  u.pose = Se2f(w->pred.x + dx(0), w->pred.y + dx(1), wrap_angle(w->pred.theta + dx(2)));
  u.cov = 0.5f * (w->p_post + w->p_post.transpose());
  out->odometry_chi2 = odometry_check_.max_chi2(u.pose, u.cov, u.bias_xy, u.bias_theta);
  if (out->odometry_chi2 > o.innovation_chi2) {
    w->v = ScanVerdict::kContradicting;  // the scans hold the pose where the wheels say it is not
    set_large_fault(out, true, LargeFault::kOdometryWindow);  // a slow slide: its size is unknown, assume the worst
    u.fuse = false;
  }
  return u;
}

// (6) The track's state after the verdict: fused (and the map bias of this scan), or the counters of
// unsupported / faulty / outside scans and, after an innovation fault, a widened covariance.
void PoseTracker::apply_verdict(const Se2f& odom, const StepWork& w, const Update& u, TrackStep* out) {
  const ScanVerdict v = w.v;
  if (v == ScanVerdict::kSupported || v == ScanVerdict::kAmbiguous) {
    // TrackOptions::repin_needs_confirmation, measured before the prediction is replaced.
    // A re-pin: the published pose was beyond the alert limits, and this scan alone brings it back
    // (an undetected fault of it could carry the fused pose beyond them).
    const bool repins = u.fuse && w.predicted && options_.repin_needs_confirmation &&
                        (last_.pl.xy_m > options_.alert_limit_m || last_.pl.theta_rad > options_.alert_limit_rad) &&
                        undetected_fault_reaches_alert(cov_, u.cov, w.pred_pl);
    if (u.fuse) {
      pose_ = u.pose;
      cov_ = u.cov;
      odom_at_fuse_ = odom;
      pose_at_fuse_ = pose_;
      predicted_since_fuse_ = 0;
      turn_since_fuse_rad_ = 0.0f;
      fuse_next_ = false;
      out->fused = true;
      odometry_check_.push(pose_, cov_, u.bias_xy, u.bias_theta);
    }
    // The map's own error does not average out over scans: one cell of quantisation plus the
    // scan's residual RMS (how far the map's walls are from where this scan sees them).
    bias_xy_m_ = u.bias_xy;
    bias_theta_rad_ = u.bias_theta;
    unsupported_ = 0;
    faulty_ = 0;
    outside_ = 0;
    if (v == ScanVerdict::kAmbiguous) {
      had_fault_ = true;  // `localized` again only after recovery_steps unique scans
      consistent_since_fault_ = 0;
    } else {
      ++consistent_since_fault_;
      if (consistent_since_fault_ >= options_.recovery_steps) contradicted_ = false;
    }
    // TrackOptions::repin_needs_confirmation: this scan alone vouches for the pose along the axis
    // it pins; it does not count as one of its own confirmations.
    if (repins) {
      had_fault_ = true;
      consistent_since_fault_ = 0;
    }
    return;
  }
  ++unsupported_;
  if (v == ScanVerdict::kContradicting && w.innovation_fault) {
    // The scan fits the map well but not where the odometry says (wheel slip, a push, laser /
    // odometry latency): the prediction is what failed. The scan sees the fault only along the
    // axes it constrains; along a corridor the same odometry may be as wrong unseen. So the
    // covariance widens by the size of the disagreement in every direction, and the status is
    // not `localized` again until scans constrain every axis back under the alert limit.
    const float exy2 = w.e(0) * w.e(0) + w.e(1) * w.e(1);
    cov_(0, 0) += exy2;
    cov_(1, 1) += exy2;
    cov_(2, 2) += w.e(2) * w.e(2);
    cov_ = 0.5f * (cov_ + cov_.transpose()).eval();
    odometry_check_.widen(exy2, w.e(2) * w.e(2));
    fuse_next_ = true;
  }
  if (v == ScanVerdict::kContradicting) {
    ++faulty_;
    had_fault_ = true;
    contradicted_ = true;
    consistent_since_fault_ = 0;
  } else {
    faulty_ = 0;
  }
  // An outside-map scan whose end-points on the map contradict the pose fails the inlier test on
  // what it sees of the map: the same fault as a contradicting scan, for the recovery that follows
  // (without it, the next uninformative scan was `localized` on the wheels at once).
  if (v == ScanVerdict::kOutsideMap && out->known_part_contradicts) {
    had_fault_ = true;
    contradicted_ = true;
    consistent_since_fault_ = 0;
  }
  if (v == ScanVerdict::kOutsideMap) ++outside_; else outside_ = 0;
}

// (7) Protection level (with the confidence extent's excess), status and whether the track ends.
void PoseTracker::publish(const Point2f* points, std::size_t n, const StepWork& w, TrackStep* out) {
  const TrackOptions& o = options_;
  const ScanVerdict v = w.v;
  out->pose = pose_;
  out->cov = cov_;
  out->pl = protection_level(cov_, k_, bias_xy_m_, bias_theta_rad_);
  // Not on the scan a track starts on: that pose is MML's, isolated from a local map of many
  // scans that constrains what this one scan may leave open (a corridor's axis).
  if (o.confidence_extent_xy && w.predicted &&
      (v == ScanVerdict::kSupported || v == ScanVerdict::kAmbiguous)) {
    update_confidence_excess(points, n, out->alignment, w, out->pl, out);
  }
  out->pl.xy_m += excess_xy_m_;
  if (o.cover_unfused_update && !out->fused && (v == ScanVerdict::kSupported || v == ScanVerdict::kAmbiguous)) {
    out->pl.xy_m += std::hypot(w.unfused(0), w.unfused(1));
    out->pl.theta_rad += std::fabs(w.unfused(2));
  }
  if (v == ScanVerdict::kSupported && !out->valley_dropped) unpinned_m_ = 0.0f;
  if (o.odom_slip_per_100m > 0.0f &&
      1.0f - std::exp(-o.odom_slip_per_100m * 0.01f * unpinned_m_) > o.integrity_risk) {
    out->pl.xy_m += o.odom_slip_max_m;  // a declared slip could be in the pose unseen
  }
  out->pl.xy_m += o.odom_scale_error * unpinned_m_;  // the wheels' systematic error over those metres
  out->unsupported_steps = unsupported_;
  out->faulty_steps = faulty_;
  out->outside_steps = outside_;
  const bool within = out->pl.xy_m <= o.alert_limit_m && out->pl.theta_rad <= o.alert_limit_rad;
  const bool recovered = !had_fault_ || consistent_since_fault_ >= o.recovery_steps;
  out->status = hal::LocalizationStatus::kAmbiguous;
  if (v == ScanVerdict::kOutsideMap) {
    out->status = hal::LocalizationStatus::kOutsideMap;
    out->reason = hal::StatusReason::kOutsideMap;
  } else if (v == ScanVerdict::kContradicting || faulty_ > 0) {
    out->reason = hal::StatusReason::kTrackFault;
  } else if (v == ScanVerdict::kAmbiguous) {
    out->reason = hal::StatusReason::kTrackAlias;
  } else if (!within) {
    out->reason = hal::StatusReason::kTrackBeyondAlert;
  } else if (!recovered) {
    out->reason = hal::StatusReason::kTrackRecovering;
  } else {
    out->status = hal::LocalizationStatus::kLocalized;
    out->reason = hal::StatusReason::kNone;
  }
  out->lost = faulty_ >= o.max_faulty_steps || outside_ >= o.max_faulty_steps || !(out->pl.xy_m <= o.lost_limit_m) ||
              !pose_.vector().allFinite();
  if (out->lost) active_ = false;
}

}  // namespace track
}  // namespace fw
