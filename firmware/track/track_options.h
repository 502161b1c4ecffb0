// Options of the pose tracker and its integrity monitor (pose_tracker.h): one plain struct,
// validated once at start-up (Cartographer style). Defaults are stated in physical terms — a SICK
// class laser, wheel odometry of a differential-drive robot, a 5 cm map — not fitted to a log.
#pragma once

#include <cstdint>

#include "firmware/base/status.h"

namespace fw {
namespace track {

struct ScanAlignOptions {
  std::uint32_t max_points = 360;    // scan end-points used per alignment (evenly subsampled)
  float max_range_m = 30.0f;         // beams beyond this are not used (range noise grows with range)
  std::uint32_t iterations = 12;     // Gauss-Newton iterations
  // A point farther than this from every mapped wall is not explained by the map. The first half
  // of the iterations uses twice the value to pull in from a poor prediction.
  float outlier_m = 0.30f;
  float huber_m = 0.05f;             // Huber loss: residuals beyond this weigh less (robust)
  // Map errors of neighbouring end-points are correlated (same wall, same map cells): one
  // independent observation is counted per cell of this side that holds inliers (consecutive
  // beams in one cell count once), so the information does not grow with the beam density.
  // 1 m: with 0.25 m the heading σ from the information (≈ 0.004 rad) was 2.5× smaller than the
  // scan-to-scan dispersion of the scan fix of a robot standing still (intel, ±0.01 rad).
  float correlation_length_m = 1.0f;
  float min_sigma_m = 0.02f;         // floor of the per-point noise estimated from the residuals
  Status validate() const;
};

// Correlative pre-search of the tracker (correlative_search.h): run when the odometry prediction is
// too uncertain for Gauss-Newton alone; the window is window_sigmas × the prediction's σ, capped.
struct CorrelativeSearchOptions {
  bool enabled = true;
  // The search runs while the track recovers from a fault (its covariance widened) and the
  // prediction's σ exceeds either trigger: below them Gauss-Newton's capture range (twice the
  // outlier distance in its first iterations) covers the window.
  float trigger_sigma_xy_m = 0.10f;
  float trigger_sigma_theta_rad = 0.035f;  // 2°
  float window_sigmas = 3.0f;              // half-width of the window in prediction σ
  float max_window_xy_m = 1.0f;            // caps: beyond them the track is as good as lost
  float max_window_theta_rad = 0.35f;      // 20°
  float linear_step_m = 0.10f;             // coarse grid; Gauss-Newton refines from the best cell
  float angular_step_rad = 0.0175f;        // 1°
  float clip_m = 0.20f;                    // truncated score: ≥ the grid's worst offset at 10 m
  std::uint32_t max_points = 90;           // end-points scored per candidate (evenly subsampled)
  // Steps are coarsened (×1.25 both) until the window fits. A budget of the sensor step: the search
  // runs inside it, so candidates × max_points must fit the scan period with room for the rest of
  // the step. Measured on the 2-core build VM: about 1 µs per candidate at 90 points (fr079 scan 1864:
  // 14,553 candidates, 14.1 ms, a deadline miss at the former 20,000); 6000 keeps the search under
  // 6 ms of the 13.3 ms period. A slower onboard computer needs a smaller cap (scripts/bench.sh realtime).
  std::uint32_t max_candidates = 6000;
  // The searched alignment replaces the one from the prediction only when its mean truncated score
  // is higher by this much (a few end-points more on the walls, not quantisation noise).
  float min_score_gain = 0.02f;
  Status validate() const;
};

struct TrackOptions {
  ScanAlignOptions align;
  CorrelativeSearchOptions search;
  // Odometry noise (AMCL's α1..α4 and their defaults, 0.2): σ_trans = a_tt·|Δs| + a_tr·|Δθ|,
  // σ_rot = a_rr·|Δθ| + a_rt·|Δs|. Too tight a model makes good scans fail the innovation test
  // (availability), never a wrong pose pass it: the fit test does not depend on it.
  float odom_trans_per_m = 0.2f;
  float odom_trans_per_rad = 0.2f;
  float odom_rot_per_rad = 0.2f;
  float odom_rot_per_m = 0.2f;
  // Per-step odometry noise (extension, 0 by default): σ per scan step that does not follow the
  // motion, added in quadrature to the two σ above (σ² = (a·|Δs| + …)² + σ_step²). The AMCL model
  // gives a standing or slowly turning robot no noise at all; wheels whose error is per step (the
  // dissertation's simulated robot, Sec. 5.7.1: 4 cm on x and y and 4° per step whatever the motion)
  // then fail the innovation and odometry-consistency tests on every right track (large office
  // seed 3: a slow slide seen as a fault, the track lost, 10 % availability). Set it from the
  // robot's odometry spec, as the four α; mml-sim gives the tracker its simulated robot's.
  float odom_trans_per_step_m = 0.0f;
  float odom_rot_per_step_rad = 0.0f;
  // Declared wheel-slip faults (issue 56, ARAIM-style: a fault mode with a prior probability). A slip
  // (the wheels report motion the robot did not make) is seen only by a scan that pins the position
  // along the slip: along a corridor whose walls fit wherever the robot stands (the one-valley rule
  // leaves that axis to the wheels) or over scans that say nothing, it is not monitored. So once the
  // probability of at least one slip over the metres driven since a scan last pinned every direction,
  // 1 − exp(−rate × metres / 100), exceeds the integrity risk, the PL includes the largest slip.
  // From the platform's floor and wheels (an integrator's statement, like the α above); 0 = none
  // declared (the PL then assumes the noise model bounds the wheels). Corpus, slip-events profile
  // (2 per 100 m, 0.3–1 m): a warehouse aisle `localized` 0.87 m off for 17 steps without it.
  float odom_slip_per_100m = 0.0f;
  float odom_slip_max_m = 1.0f;
  // The wheels' systematic distance error (a wheel radius or base a few % off: UMBmark, Borenstein &
  // Feng 1996, finds uncalibrated differential drives a few % off, systematic, not noise). The α
  // model treats every step as independent noise, so over the metres the wheels alone carry the
  // pose (the same count as for slips) its σ grows as √n while a scale error grows as n: the corpus's
  // poorly calibrated base (+3 %, calibrated α) was `localized` 0.35 m off under a PL of 0.15 m along
  // a 12 m warehouse aisle. So the PL adds this fraction of those metres. 0 = the α model alone.
  float odom_scale_error = 0.05f;
  // Odometry increments beyond these between two scans are not physical (a jump, a reset of the
  // wheel counters): the pose cannot be carried across them.
  float max_odom_step_m = 2.0f;
  float max_odom_step_rad = 1.5f;
  // Scans are fused only after the robot moved this far or turned this much since the last fused
  // scan (LaMa / AMCL update thresholds): standing still neither drifts nor shrinks the covariance
  // by re-counting the same map error (under the α model; wheels with per-step noise drift while
  // standing, odom_trans_per_step_m). Every scan is still checked against the map.
  float update_min_d_m = 0.05f;
  float update_min_a_rad = 0.05f;
  // Integrity monitor (fault detection on the residuals, RAIM style).
  std::uint32_t min_points = 30;          // fewer in-map points: the scan is uninformative
  float min_inlier_fraction = 0.5f;       // of the points on mapped (known) cells
  // Of all end-points (unknown ones included) that must end on a wall for the scan to support the
  // pose; fewer is a large fault (the robot may have been carried). Measured on whole runs of the
  // seven logs: 3 of 42,537 scans at right poses below 0.5, the aces carry at 0.37. 0 = off.
  float min_explained_fraction = 0.5f;
  // A scan whose inlier fraction (known cells) falls below the previous scan's by more than
  // this many standard errors (two-proportion test over the correlation cells) contradicts the
  // pose: what a robot carried elsewhere sees first, when that scan still fits near the old pose.
  // 3.09 = one-sided 1e-3, the integrity risk. 0 = off.
  float fit_drop_z = 3.09f;
  // χ²(3) at 1 − 1e-3: scan fix vs odometry prediction; a fault only when the fix also lies outside
  // the prediction's protection level.
  float innovation_chi2 = 16.27f;
  // Odometry consistency over a window (odometry_consistency.h): each fused pose is tested against
  // the last `odometry_window` fused poses carried forward by the odometry and its noise model, at
  // the same χ² as the innovation. Catches a scan matcher that holds the pose back a little at every
  // scan while the wheels say the robot drives on. 0 = off; at most 32.
  std::uint32_t odometry_window = 16;
  float outside_map_fraction = 0.5f;      // end-points in unknown space beyond this: outside the map
  // Consecutive contradicting scans, or consecutive outside-map scans, before the track is given up
  // (global mode): one persistence for both (they were two equal fields; issue 56's fewer knobs).
  std::uint32_t max_faulty_steps = 5;
  // `outside-map` is said from the scan at the tracked or dead-reckoned pose only if no scan of the
  // track since MML last vouched for it failed to continue the scan before it (scan_continuity.h: a
  // carried robot does not see what it saw a scan ago; one driving into unmapped space does). After
  // such a scan the pose may be anywhere, so "mostly unknown there" says nothing about the robot:
  // `ambiguous` (track-fault) while tracked, `searching` once the track is given up. Off: any pose
  // decides (before 2026-12-01; the large office kidnap of scripts/run.sh said `outside-map` at 82
  // steps of a building mapped wall to wall).
  bool outside_map_needs_clean_exit = true;
  // Without a sign of a carry, the wheels bind MML (issue 56, measured on the generated corpus):
  // MML isolates a pose against the map, so where the map misrepresents the robot's place — a block
  // it lacks, a wing drawn turned — a look-alike elsewhere can be "isolated" while the robot never
  // left the place the wheels say (corpus seed 101: a warehouse aisle 34 m away after a drive through
  // an unmapped block; seed 202: a lab's 180° twin 28 m away after the track waited for MML). Unless
  // a scan of the track showed a sign of a carry (carry_seen_: a scan the map does not support that
  // does not continue the one before it), (a) a track given up for any reason leaves the wheels
  // binding MML's fixes (dead_reckoning.h; before: only after a clean outside-map exit), and (b) a
  // track waiting for MML after a large fault is replaced by MML's fix only where the scan prefers
  // MML's pose significantly, as a track that saw no fault. A carried robot shows the sign (the scan
  // continuity test) and MML is free as before. false = MML's fix replaces a waiting track, and
  // binds only after a clean exit.
  bool wheels_bind_mml_without_carry = true;
  // After a contradicting scan, this many consecutive consistent scans before `localized` again
  // (hysteresis: a fault seen is evidence that the odometry or the fit may be wrong unseen too).
  std::uint32_t recovery_steps = 5;
  // A re-pin — a scan that brings a published PL beyond the alert limits back within them, and whose
  // undetected fault could move the fused pose beyond the alert limit — is a new fix along the axis
  // it pins: the innovation test passes a fix within the prediction's PL, and the update moves the
  // pose by the gain times the fix's error, so where |G_xy|·PL_pred > alert limit (RAIM's slope ×
  // threshold; PoseTracker::undetected_fault_reaches_alert) only this scan vouches for the position
  // (the slope test alone holds every scan of a log whose scans are 0.7 m apart: fr101 0.87 → 0.00),
  // and it is confirmed as MML's fix is, by recovery_steps consistent scans (corpus
  // seed 909 #72: 10 m along an aisle, PL 1.94 m; one scan pinned the axis 0.44 m off, in agreement
  // with the drifted prediction, and four steps were `localized` 0.48-0.59 m off under a PL of
  // 0.43-0.49 m). Position only: a heading PL just over 5° pinned again by the walls is no new fix.
  bool repin_needs_confirmation = true;
  // Alias check (ambiguity along weak axes, firmware/mml/pose_uniqueness.h): every supported scan
  // is also refined from rivals seeded every `alias_step_m` up to `alias_max_shift_m` along the two
  // principal axes of its information. A rival > alias_min_separation_m away that fits better by
  // more than `alias_margin` (truncated cost, units of clip²) contradicts the pose — the scan says
  // the robot is elsewhere (a track that slid into a look-alike); one within the margin makes the
  // pose ambiguous: the data cannot tell the two apart, so the PL (one Gaussian mode) cannot cover
  // the error and the status is not `localized` until the scans are unique again for
  // `recovery_steps` scans. The PL is a single-mode bound; this check is what makes it one.
  bool alias_check = true;
  // A rival that fits significantly better and lies within the prediction's PL is the fix the
  // alignment missed, not a fault: the scan is aligned again from it (pose_tracker.cpp).
  bool refit_at_better_rival = true;
  // One valley, one mode (extension): on a trusted track (no contradiction since the last
  // recovery_steps unique scans, no fit drop at alias_credible_z), a rival at the fix's heading
  // joined to the fix by poses that fit as well (mml::in_same_cost_valley: a bare corridor whose
  // walls fit wherever the robot stands along it) is not a second mode but the scan's weak axis,
  // which the update leaves to the prediction (alias_valley_drops_information below) and the PL
  // covers through the prediction's growth and the scan's confidence extent (capped at the
  // prediction's PL plus the update's shift). Such a rival does not make the scan ambiguous; any
  // other rival does (check_pose_uniqueness reports the best of the others).
  // On by default since 2026-11-29 (README "Protection level"): with the drop below it is sound on
  // every measurement (mit-killian availability +0.006 with no new PL exceedance, the large office
  // seeds 1–5 0.770 → 0.836, the other six logs identical, 560 kidnap runs 0 wrong). It was off
  // for its cost: a side-by-side measurement had the valley paths raising mml-eval's step p99 past
  // one LMS scan period (mit-killian 11.2 → 15.4 ms). Measured again on today's code that is not
  // reproduced (mit-killian 9.1 → 9.3 ms), and `bench.sh realtime` with it on has 0 deadline misses
  // and a tracked-step p99 of 0.8–2.1 ms on the four office logs. Without the drop it let a
  // mit-killian corridor track 0.31 m off along the axis be `localized` under a PL of 0.26–0.28 m
  // (scans 15992–15993).
  // false = every rival counts (the large office: 56–71 `ambiguous` steps a run in its corridors).
  bool alias_valley_is_one_mode = true;
  // With the rule above (in effect whenever it is on): a scan whose fix has a one-mode valley gives
  // no information along the valley's axis (its rivals there fit as well, so what its Hessian
  // claims along that axis is the curvature of a flat floor, not evidence): that axis of H is
  // projected out before the update (H ← P H P, P = I − v vᵀ on the position), so the pose along it
  // stays on the prediction and its variance grows with the wheels, as the PL then says.
  // false = the full H (the rule as first measured).
  bool alias_valley_drops_information = true;
  float alias_max_shift_m = 3.0f;
  float alias_step_m = 0.4f;
  float alias_min_separation_m = 0.4f;
  float alias_clip_m = 0.15f;
  float alias_margin = 0.01f;
  // Rivals in heading as well (seeds turned ±3°, ±6°, … ±12°): a rival turned ≥ 2° that fits as
  // well makes the heading ambiguous, one that fits significantly better contradicts the pose
  // (fr-clinic scan 5548: a track held 6–7° off by clutter near the robot while the far walls fit
  // only at the true heading). 0 = translation rivals only.
  float alias_rotation_step_rad = 0.0524f;
  float alias_max_rotation_rad = 0.21f;
  float alias_min_separation_rad = 0.035f;
  // A better rival contradicts only when a paired test of the per-point costs says so at this z
  // (3.09: one-sided 1e-3), the end-points counted once per correlation cell.
  float alias_z = 3.09f;
  // An ambiguous scan's rival that fits better than the fix at this z (1.645: one-sided 5 %) is a
  // place the robot could be, whatever the prediction says (alias_rival_must_be_credible below):
  // proof needs alias_z, doubt does not. Measured on the whole mit-killian log: the 47 scans at
  // right poses this could turn all tested below z 1.0; the carry 3908 → 3827 above 1.64.
  float alias_credible_z = 1.645f;
  // A heading-only fault is recovered by the track itself: the scan fix lies inside the prediction's
  // horizontal protection level (the position is where the track promised it), turned beyond the
  // heading alert limit, and the paired test (alias_z) says the scan fits significantly better at the
  // fix than at the prediction. Wheels that over-report a turn (mit-killian: 23° where the robot
  // turned 5°) do that; a carried robot does not: carrying moves the position. Where Gauss-Newton
  // from a prediction 15–30° off stops short, the turn hypothesis is tested directly (a heading search
  // at the predicted position, or the alias check's turned rival there) and kept only if it passes
  // this test — reaching no farther than the turn the wheels reported since a scan last set the
  // heading (rival_within_reported_turn): a place that looks like the old one turned, reached by a
  // carry with no reported turn, stays a large fault (seed 707 #136). The fault widens the covariance
  // and needs `recovery_steps` consistent scans; MML still cross-checks. false = every heading fault
  // beyond the alert limit waits for MML. Turn-spin draws, 0 wrong in every variant: dev seed 5 7,683
  // `localized` without the rule, 8,200 with the test alone, 8,905 with the turn hypothesis; seed 808
  // 18,270 with the test alone, 20,082 with the hypothesis.
  // Off by default since seed 1111 #135: a robot carried during a spin of 13° a scan into a place
  // that looks like the old one turned 90° showed as a heading-only fault 8.5° beyond the
  // prediction, within the reported turn (and of the turn's own sign, as a wheel lagging a turn
  // makes it: real wheels do, mit-killian's and fr079's heading faults are all of that sign); 5
  // consistent scans later, 4 steps `localized` 10 m and 90° off. No local test tells that carry
  // from a wheel's turn error, so a heading fault beyond the alert limit waits for MML's word from
  // a local map that starts after it. Cost, whole runs: mit-killian 0.881 -> 0.742, aces 0.941 ->
  // 0.901, fr079 0.790 -> 0.771 availability; intel 0.940 -> 0.939 (firmware/track/README.md).
  bool heading_fault_local_recovery = false;
  // Confidence extent (fit_comparison.h): the protection level of a scan-supported pose covers at least
  // the farthest shift from the scan fix that the scan cannot reject (paired test at alias_z), plus
  // the published pose's distance from the fix and the map bias — where the information matrix
  // claims more than the data can tell apart (aces scan 5120: PL 0.13 m, error 0.25 m along a
  // corridor that fits as well there). Never beyond the prediction's own protection level: the
  // odometry still carries a featureless corridor. In position only: in heading the same test is
  // weak (intel: turns of 3–5° not rejected at steps the heading PL covers; availability 0.95 →
  // 0.61), and that option, never on by default, was removed with issue 56.
  bool confidence_extent_xy = true;
  // The confidence extent is capped at the prediction's PL plus the update's shift from the
  // prediction (the truth is within pred PL of the prediction, the published pose that far from it);
  // false = the old cap at the prediction's PL alone, which can be shorter than the error it bounds.
  bool confidence_cap_with_update = true;
  // That cap leans on the odometry (the truth is within the prediction's PL of the prediction), which
  // is right where the scan pins one axis and leaves the other open (a corridor: the scan checks the
  // odometry across it). A scan whose confidence extent reaches the alert limit along *both* axes
  // checks nothing: no shift up to the alert limit in any direction fits significantly worse. Then
  // the position rests on the odometry alone, which a carried robot's wheels do not see (intel seed 13,
  // carry 4658 → 6330: the first carried scan open 0.5 m both ways, inliers 180 → 129, 19 contradicting,
  // PL capped at the prediction's 0.23 + 0.05 m, `localized` 15 m off). true = no cap for such a
  // scan: its PL is at least the extent, i.e. beyond the alert limit, until a scan pins an axis again
  // (the excess carries over as for any unsupported step). false = the cap for every scan.
  bool confidence_cap_needs_a_pinned_axis = true;
  // A supported scan is fused only once the robot moved (update thresholds): a standing robot's
  // scans would re-count one view. Until then the published pose is the prediction, which may lie
  // up to the thresholds (5 cm, 2.9°) from what this scan's update would make it (x⁻ + P⁺He), and
  // the covariance's PL does not know it (intel scans 5490–5495, 12926–12931: a standing pose
  // 2.3° off its map pose, PL 2.2°). With this on, the PL of an unfused scan grows by the size of
  // that update, per axis: |true − published| ≤ |true − updated| + |updated − published|.
  bool cover_unfused_update = true;
  // Global cross-check (tracked_localizer.h): when the track stops being `localized` while still
  // tracked (an alias, a fault being recovered, scans that say nothing), MML searches in the
  // background from a fresh local map for at most this many scans; if it isolates a pose outside the
  // track's protection level, the track was in a look-alike and MML's fix replaces it. 0 = off.
  std::uint32_t cross_check_steps = 300;
  // An alias whose equally good rival lies beyond the alert limits (TrackStep::alias_beyond_alert)
  // asks for MML's confirmation like a large fault: the track may already follow the wrong one of
  // two look-alikes, and no local test can tell (intel kidnap 6735 → 7812: `localized` 10.8 m off
  // four scans after such an alias whenever MML's background search lost the race). It costs
  // availability where look-alikes are common and MML needs long to isolate again (README: large
  // office 0.78 → 0.19, mit-killian 0.88 → 0.72 before the rule below; 0.57 and 0.88 with it).
  // false = the old race.
  bool confirm_alias_beyond_alert = true;
  // ... and only when the rival is a place the robot could be (TrackStep::alias_rival_credible): a
  // rival at the fix's heading in the fix's own cost valley (a featureless corridor: one mode, its
  // axis left to the odometry) or outside the prediction's protection level (beyond where a track
  // that was right at the last scan reaches, the bound the innovation test trusts) is not. The large
  // office waited for MML after nearly every alias of its 80 m corridors: rivals 0.5–2.8 m along
  // the axis, the prediction's σ 6–14 cm. Both exemptions assume a track that was right, so they
  // hold only while no scan has contradicted it since the last `recovery_steps` unique scans
  // (pose_tracker.cpp, check_aliases: a kidnap along a mit-killian corridor seen as a heading fault).
  // The scan is still `ambiguous` and `recovery_steps` unique scans are still needed. Turned rivals
  // always count (intel kidnap: rivals 5–10° turned), and so do rivals that fit better than the fix at
  // alias_credible_z. false = every alias beyond the alert limits waits.
  bool alias_rival_must_be_credible = true;
  // Both exemptions rest on a track that was right at the last scan. A scan whose fit fell from the
  // last scan's at alias_credible_z (the fit-drop test's statistic, one-sided 5 %) does not carry that
  // trust: doubt, not proof, as for the rival above. Its rivals then count, and an alias beyond the
  // alert limits waits for MML (mit-killian, seed 13, carries from scans 3912–3916 back to 3828, 11 m
  // along the same corridor: inliers 177 → 127 of 177, z 2.7 < fit_drop_z, the rival 1.8 m along the
  // corridor not credible, `localized` 11.5 m off five unique scans later; localize_data_test.cpp).
  // false = only a contradiction (contradicted_) withdraws the trust.
  bool alias_trust_needs_steady_fit = true;
  // A track started from MML's fix is `localized` only after recovery_steps unique consistent scans,
  // as after a fault, and rules out no alias rival until then (check_aliases). One scan can be fit
  // at a wrong local minimum next to MML's pose; consecutive scans from moving poses rarely all are
  // (fr-clinic, kidnap stress seed 11 trial 5, MML at 30 m: the re-fix's first scan fit best 7.4° from
  // the truth with an RMS residual of 0.14 m and was published `localized` 0.50 m / 7.4° off; its
  // next scan was already ambiguous). false = MML's fix is `localized` on its first consistent scan.
  bool confirm_fix = true;
  // An operator's pose hint (SET_POSE_HINT, TrackedLocalizer::set_pose_hint) enters as MML's fix
  // would: the tracker confirms it on the scans before it and on its scan with every test of a fix
  // (confirm_fix, confirm_fix_on_past_scans), within a window of its uncertainty (search caps: 1 m,
  // 20°); a hint the scans contradict is refused. The tracker's tests are local: a hint in a room
  // that looks like the one the robot is in fits as well as the truth. true = the hinted track is
  // `localized` only once MML isolates the same pose (as after a large fault, reason
  // track-awaiting-mml): a wrong hint never makes a wrong `localized`, a right one is no faster than
  // MML. false = `localized` after the fix's confirmation (1–3 scans): fast, and safe only where
  // the map has no look-alike of the hinted place (bench ops measures both).
  bool hint_awaits_mml = true;
  // ... on the scans before the fix first (extension): MML isolated the pose from a local map of the
  // scans the robot has just seen, so those scans are already here. The recovery_steps scans before
  // the fix are replayed through the tracker from MML's pose carried back by the wheels' increments,
  // then the fix's own scan; the pose is `localized` at once only when the tracker ends `localized`
  // on it — the same count of consecutive consistent unique scans, the same tests, on data the robot
  // already has instead of data it waits for. Otherwise (a scan contradicts, an alias, too few scans
  // since the last reset) the track starts on the fix's scan and confirms forward as above. A carry
  // between those scans is invisible to the wheels, so the carried-back poses miss the map there and
  // the replay fails: forward confirmation. On by default since 2026-11-28 (README "MML's fix
  // confirmed on the scans before it"): 0.5–0.8 m less travel to the first fix on intel, fr079, aces.
  // It was off while one run of the 420-run kidnap stress (intel seed 13, carry 4658 → 6330) was
  // `localized` 15.1 m off for one scan — a carry whose first scan still fits the old place; the
  // tracker's weakness, not the replay's, closed by confidence_cap_needs_a_pinned_axis (that run
  // replayed in localize_data_test.cpp); the same 420 runs with both: 0 integrity failures.
  // false = forward confirmation only.
  bool confirm_fix_on_past_scans = true;
  // ... at most this many scans per step (≥ 2): the replay runs in the sensor context, whose every
  // step must end within one scan period, and recovery_steps + 1 tracker steps in one scan period
  // missed the 75 Hz deadline (bench.sh realtime: intel 14.0 ms, fr079 20.3 ms on the fix's scan).
  // The scans that arrive meanwhile join the replay, so it reaches the present after
  // ⌈(recovery_steps + 1 − past_scans_per_step) / (past_scans_per_step − 1)⌉ further scans (3: two;
  // forward confirmation needs recovery_steps), not `localized` until then. The replayed steps of one
  // scan share one pre-search budget (search.max_candidates): a confirmation starts with σθ ≥ 2.9°
  // (the start's floor), over the search's trigger, so each of them may search, and three full
  // searches in one period (≈ 17 ms on the slow 2-core VM) would miss it. A step's search gets what
  // the earlier steps of the scan left (its grid coarsens to fit, as at the cap); once it is spent the
  // replay goes on at the next scan (every scan still replays ≥ 1 step, so the lag never grows).
  // Searches that fit together (the usual ~800 candidates each) are unchanged.
  std::uint32_t past_scans_per_step = 3;
  // Protection level (protection_level.h): integrity risk per `localized` step and alert limits.
  float integrity_risk = 1e-3f;
  float alert_limit_m = 0.5f;             // PL beyond → not `localized` (the product's 0.5 m bound)
  float alert_limit_rad = 0.0872665f;     // 5°
  float lost_limit_m = 2.0f;              // PL beyond → the track is given up, global search
  // Start of tracking from a global fix: its covariance inflated by this factor, then floored.
  float init_cov_scale = 4.0f;
  float init_sigma_xy_floor_m = 0.10f;
  float init_sigma_theta_floor_rad = 0.05f;
  Status validate() const;
};

}  // namespace track
}  // namespace fw
