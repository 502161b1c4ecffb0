// Localization in the map AntSLAM builds (issue 12, D_selfmap_*): the self-built map and a
// reference trajectory in ITS frame, so that `mml-eval --localize --log --map --reference` (and
// run_localize_evaluation's LocalizePlan::custom) can score the localizer there exactly as in the
// data set's reference map.
//
// Rule. The SLAM map has its own frame (the first scan's pose), the public reference poses (the
// GMapping-corrected poses the localize benchmark uses, chained with odometry to every scan:
// sim/io/reference_trajectory.h) another. The reference is moved into the SLAM map's frame by the
// least-squares 2-D rigid transform T (rotation + translation, no scale, no reflection; Umeyama /
// Horn closed form) that aligns the reference positions R_i to the AntSLAM positions P_i over ALL
// scans: T = argmin Σ_i |T·R_i − P_i|². No other correction is applied, so where the self-built map
// is distorted (P_i far from T·R_i) the localizer — which localizes in the map — shows that as error
// against the aligned reference. The residual of the alignment, RMS_i |T·R_i − P_i| (m), is reported
// as D_selfmap_frame_rms_m: the map's global distortion against the reference.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "firmware/base/se2.h"
#include "sim/eval/rbsm/rbsm_eval_lib.h"
#include "sim/io/carmen_log.h"

namespace sim {

struct RigidAlignment2d {
  fw::Se2d transform;     // T: maps `from` into the frame of `to` (p_to ≈ T.transform_point(p_from))
  double rms_m = 0;       // RMS of |T·from_i − to_i| over the pairs
  double max_m = 0;       // largest residual
  std::size_t pairs = 0;
};

// Least-squares rigid transform (positions only; headings ignored) of from[i] onto to[i] over the
// first min(from.size(), to.size()) pairs. 2-D Umeyama without scale: with centred positions a_i, b_i,
// θ = atan2(Σ a_i × b_i, Σ a_i · b_i), t = μ_to − R(θ) μ_from; a reflection is never returned. Fails
// with fewer than 2 pairs or when `from` has no spread (all positions equal: θ undefined).
bool align_rigid_2d(const std::vector<fw::Se2d>& from, const std::vector<fw::Se2d>& to, RigidAlignment2d* out,
                    std::string* error);

// The data set's public corrected poses at every scan of `log` (reference_at_every_scan): the
// reference of the self-built map (write_selfmap) and of the whole-trajectory check of bench_slam
// and mml-slam (D_slam_ate_m: align_rigid_2d of this onto a SLAM trajectory, its RMS residual). The
// relations metric scores pairs of nearby scans; a loop closed on a look-alike place bends the whole
// trajectory while most relations stay small, which the aligned residual shows. Fails when the data
// set has no corrected poses or they do not cover every scan.
bool reference_at_every_scan_of(const CarmenLog& log, const EvalDataset& dataset, std::vector<fw::Se2d>* out,
                                std::string* error);

struct SelfMapFiles {
  std::string map_yaml;   // ROS map of the SLAM poses (as mml-slam --map), the reference map's parameters
  std::string reference;  // "flaser_index ipc logger x y theta" rows: the data set's corrected poses moved by T
  std::string residual_csv;  // per scan: SLAM pose, aligned reference, |residual| (m, deg)
  RigidAlignment2d alignment;  // reference (all scans) → SLAM trajectory
};

// Writes <dir>/<name>.yaml/.pgm (map of `poses`, resolution and max range of the data set's global
// map, sim/map/global_maps.h), <dir>/<name>.residual.csv and <dir>/<name>.reference.txt: every corrected pose C_k of the data set
// as T ⊕ C_k, T from align_rigid_2d(reference_at_every_scan(log, C), poses). Chaining odometry is
// frame-equivariant, so mml-eval's reference from these rows is exactly T ⊕ (the benchmark's
// reference) at every scan, with the same reference error bounds.
bool write_selfmap(const CarmenLog& log, const EvalDataset& dataset, const std::vector<fw::Se2d>& poses,
                   const std::string& dir, const std::string& name, SelfMapFiles* out, std::string* error);

}  // namespace sim
