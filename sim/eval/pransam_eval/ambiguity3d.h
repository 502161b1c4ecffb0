// Ambiguity verdict for a 3-D registration answer (issue 17). EXTENSION of the dissertation: Ch. 4
// reports the best hypothesis once Ω ≥ Ω_thres; it has no notion of a second, distinct transform
// that explains the data as well. On real clouds such rivals exist: a nearly symmetric object (the
// milk carton) turned by 180° fits its own surface, and a cut of a room whose contact is mostly
// floor + one wall can slide along the line the two planes share. Reporting either as "the" pose is
// the dangerous case (wrong reported as good), so the answer is checked against its rivals after
// refinement and called AMBIGUOUS (not success, not wrong, a column of its own) when a distinct
// rival scores about as well.
//
// Score of a pose = the number k of scene points within 1 voxel of the model after the common
// point-to-plane refinement (icp3d.h), i.e. the refined Ω. Rivals, each refined the same way:
//  - the hypotheses the matcher kept besides its best (passed in by the caller, may be none);
//  - the best pose turned by 180° about each principal axis of the (moved) scene, about its centroid,
//    and by 180° about each principal axis of the model through the model's centroid (a
//    near-symmetric object's flips; the second kind also moves a part placed on the wrong end);
//  - the best pose moved by ±s along the weakest eigenvector of the contact's point-to-plane
//    information matrix (6×6, rotations scaled by the scene's RMS radius so both parts are metres),
//    s = 4 and 8 voxels: where the contact does not constrain the pose, refinement does not pull it
//    back, and the score says whether the data support the moved pose equally.
// A distinct rival that scores clearly BETTER than the answer (k_rival > k_best + z·√k_best) is
// adopted as the answer and the check is repeated from it (at most max_adoptions times): the data
// prefer it beyond the counting noise, so it is the better explanation, and it must itself pass the
// test. (On the office the slides along a floor + wall contact were exactly this case: the rival one
// slide away was the true pose, with 7–16 % more inliers.)
// Distinct = after refinement the rival's rotation differs from the best by more than rot_sep_deg
// (2× the 2° success threshold) or it moves the scene's centroid by more than trans_sep_voxels.
// About as well / clearly better, two rules (AmbiguityOptions::paired):
//  - paired (default): the two poses are scored on the SAME scene points, so the comparison is a
//    paired one: McNemar's test on each point's inlier/outlier outcome under both poses,
//    z = (b − c) / √(b + c), b = points inliers only under the answer, c = only under the rival.
//    Points that both poses explain (or both miss) say nothing about which is right; the unpaired
//    rule below lets them widen the margin all the same. About as well: z < z_crit (the data do not
//    prefer the answer significantly); clearly better: z < −z_crit. Like the unpaired rule it counts
//    each point as an independent outcome. A near-symmetric object whose flip keeps 95 % of the
//    inliers is told apart when the other 5 % go one way (milk: z ≥ 7.3 on all 100 draws); a truly
//    symmetric one is not (the discordant points split both ways). Optionally (cell_voxels > 0) the
//    points are pooled in cells of that side, d_j = b_j − c_j, z = Σ d_j / √(Σ d_j²) (the
//    cluster-robust form, for correlated neighbours): more conservative, since z ≤ √(cells); on the
//    office with 4-voxel cells 4 wrong slides that the truth beats by 6–8 % of the inliers stayed
//    ambiguous (z −2.0 … −3.0) instead of being replaced.
//  - unpaired (the first rule): k_rival ≥ k_best − z·√k_best, the inlier count treated as a counting
//    (Poisson) variable; it ignores that both counts come from the same points, so it calls
//    ambiguous what a paired test separates.
// Nothing here depends on the particular clouds; the constants are stated in voxels / in the
// success thresholds.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "sim/eval/pransam_eval/icp3d.h"

namespace sim::pransam_eval {

struct AmbiguityOptions {
  double rot_sep_deg = 4.0;        // 2 × kRotTolDeg
  double trans_sep_voxels = 3.0;   // "a few voxels"
  double z = 3.0;                  // z_crit (paired) / margin = z·√k_best (unpaired)
  bool paired = true;              // McNemar's paired test over cells (see above); false: the margin rule
  double cell_voxels = 0.0;        // paired test: 0 = every point a unit (McNemar); > 0 = cells of this side (voxels)
  std::vector<float> slide_voxels = {4.0f, 8.0f};
  bool flips = true, slides = true;
  // Rivals are refined on an evenly strided subset of at most this many scene points (cost), then
  // counted on the whole scene, so k and the margin are always whole-scene counts.
  std::size_t refine_points = 2000;
  int max_adoptions = 3;           // 0: never replace the answer, only judge it
};

struct PoseCandidate {
  Eigen::Matrix3f rotation = Eigen::Matrix3f::Identity();
  Eigen::Vector3f translation = Eigen::Vector3f::Zero();
};

enum class RivalKind { kNone, kKept, kFlip, kSlide };
const char* rival_kind_name(RivalKind k);

struct AmbiguityVerdict {
  bool ambiguous = false;
  double best_inliers = 0;        // k_best
  double margin = 0;              // z·√k_best
  double rival_inliers = -1;      // the most threatening distinct rival's k (−1: no distinct rival)
  double rival_z = 0;             // paired test: z of the answer against that rival (> 0: answer better)
  RivalKind rival = RivalKind::kNone;
  double rival_rot_deg = 0, rival_trans_m = 0;  // its distance from the best
  PoseCandidate rival_pose;
  int refinements = 0;            // ICP runs spent
  int adoptions = 0;              // times a clearly better rival replaced the answer
  PoseCandidate answer;           // the answer after adoptions (= best when none)
};

// Number of scene points within max_dist of the model under (r, t).
int count_inliers(const std::vector<Eigen::Vector3f>& scene, const PlaneModel& model, const Eigen::Matrix3f& r,
                  const Eigen::Vector3f& t, float max_dist);

// `best` is the refined answer (scene → model). `kept`: further hypotheses of the method (unrefined).
AmbiguityVerdict check_ambiguity(const std::vector<Eigen::Vector3f>& scene, const PlaneModel& model, float voxel,
                                 const PoseCandidate& best, const std::vector<PoseCandidate>& kept = {},
                                 const AmbiguityOptions& options = AmbiguityOptions());

}  // namespace sim::pransam_eval
