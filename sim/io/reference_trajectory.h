// Reference (ground-truth-like) trajectory at every raw scan of a log.
//
// The *.corrected-poses.txt files (../shared/data/README.md) give GMapping-corrected poses C_k for a
// subset of raw scans i_k (keyed by flaser_index, because the corrected logs' timestamps are
// unusable), in the corrected log's own map frame. For every raw scan i we chain the raw odometry
// O_i (CarmenScan::odom: FLASER odom triple, ROBOTLASER1 robot pose) from the corrected poses on both
// sides — relative odometry motions are frame-independent, so chaining maps the odometry increments
// into the corrected frame:
//   forward  F_i = C_k     ⊕ (O_{i_k}     ⊖ O_i)     (⊖a ⊕ b written a.between(b))
//   backward B_i = C_{k+1} ⊕ (O_{i_{k+1}} ⊖ O_i)
//   R_i = (1-w) F_i + w B_i,  w = (i - i_k) / (i_{k+1} - i_k)   (θ blended on the circle)
// Before the first / after the last corrected pose only the one-sided chain exists.
// At corrected scans R_i = C_k exactly.
//
// Error bound. Let ε(n) bound the odometry pose error accumulated over n scans (monotone) and e_C
// the error of the corrected poses. F_i is off by at most e_C + ε(d), B_i by e_C + ε(D-d) (d = i-i_k,
// D = i_{k+1}-i_k), so |R_i - truth| ≤ e_C + (1-w)ε(d) + wε(D-d). For linear drift this is
// e_C + 2w(1-w)ε(D) ≤ e_C + ε(D)/2, i.e. the drift over at most HALF the gap (a constant odometry
// bias even cancels to first order in the blend); for random-walk drift (ε(n) ∝ √n) it is
// e_C + ((1-w)√w + w√(1-w))ε(D) ≤ e_C + 0.71ε(D). The closure residual r_k = |F_{i_{k+1}} ⊖ C_{k+1}|
// (per gap: reference_gap_stats) is the observable estimate of ε(D) (it also contains the corrected
// poses' own relative error). ReferencePose::bound = ((1-w)√w + w√(1-w))·r_k (bound_theta: the same
// weight times the rotational closure residual), which covers linear,
// convex and √n growth; e_C is not included (unknown; GMapping maps of these logs are consistent to a
// few cm — see the relations figures in sim/io/data_test.cpp). One-sided extrapolation before the
// first / after the last corrected pose has no bound (inf).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "firmware/base/se2.h"
#include "sim/io/carmen_log.h"
#include "sim/io/relations.h"

namespace sim {

struct CorrectedPose {
  size_t flaser_index = 0;
  double ipc_timestamp = 0, logger_timestamp = 0;
  fw::Se2d pose;
};

// Reads "flaser_index ipc_timestamp logger_timestamp x y theta" rows ('#' comments skipped); indices
// must be strictly increasing and at most 1e9, timestamps and poses within the bounds of carmen_log.h.
// Errors name "path:line".
bool read_corrected_poses(const std::string& path, std::vector<CorrectedPose>* out, std::string* error);

// Ground truth at every raw scan (raw.scans order): chain odometry from the nearest corrected poses
// (see above). Corrected poses whose flaser_index is beyond the log are ignored. Empty when there
// are no usable corrected poses.
std::vector<fw::Se2d> reference_at_every_scan(const CarmenLog& raw, const std::vector<CorrectedPose>& corrected);

struct ReferencePose {
  fw::Se2d pose;
  double bound = 0;  // estimated translational error bound (m), see header comment; inf when extrapolated
  double bound_theta = 0;  // the same for the heading (rad), from the rotational closure residual
  bool exact = false;  // a corrected pose was given for this scan
};
std::vector<ReferencePose> reference_with_bounds(const CarmenLog& raw, const std::vector<CorrectedPose>& corrected);

struct ReferenceGapStats {
  size_t gaps = 0;
  double max_gap_scans = 0, mean_gap_scans = 0;
  double mean_closure_m = 0, max_closure_m = 0;      // |translation of F_{i_{k+1}} ⊖ C_{k+1}|
  double mean_closure_deg = 0, max_closure_deg = 0;  // rotational closure residual
};
ReferenceGapStats reference_gap_stats(const CarmenLog& raw, const std::vector<CorrectedPose>& corrected);

// Poses at the relation timestamps laid out along a breadth-first spanning tree of the relation graph
// (x_{t2} = x_{t1} ⊕ δ), for logs without a corrected log (fr-clinic, whose 2820 relations are
// mutually consistent up to their 6-decimal print precision: every relation is then satisfied to
// < 1e-4 m). Each timestamp must be a scan
// ipc_timestamp of `raw` (within 1e-4 s). Disconnected components are placed, in scan order, by the
// raw odometry from the nearest already placed scan. The first relation scan is the origin. Feed the
// result to reference_at_every_scan(). Inconsistent relation sets (intel, fr079, aces) keep the
// spanning-tree relations exact and leave the loop residuals on the others.
bool corrected_poses_from_relations(const CarmenLog& raw, const std::vector<Relation>& relations,
                                    std::vector<CorrectedPose>* out, std::string* error);

// Timestamped trajectories for evaluate_relations (t = ipc_timestamp of each scan).
Trajectory odometry_trajectory(const CarmenLog& raw);  // raw odometry (CarmenScan::odom)
Trajectory make_trajectory(const CarmenLog& raw, const std::vector<fw::Se2d>& poses);

}  // namespace sim
