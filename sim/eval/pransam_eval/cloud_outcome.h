// Scoring of one method's answer on one CloudDraw (issue 17), shared by pRANSAM and the PCL peers:
// the answer is refined by the common point-to-plane ICP (icp3d.h) and then compared with the
// truth. Correct = within max(0.4 voxel) of the truth at the scene centroid and 2° (office: 2 cm at
// the 5 cm voxel); reported = the method itself says it found a match (pRANSAM: Ω ≥ Ω_thres; FPFH +
// prerejective: converged with the inlier fraction; K-4PCS: converged). success = reported and
// correct; wrong = reported but not correct (the dangerous case); nothing = not reported;
// ambiguous = the method had an answer but a distinct rival explains the data about as well
// (ambiguity3d.h, pRANSAM only): not reported, counted in its own column (neither success nor wrong).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "sim/eval/pransam_eval/cloud_draws.h"
#include "sim/eval/pransam_eval/icp3d.h"

namespace sim::pransam_eval {

constexpr double kTransTolVoxels = 0.4;  // office: 2 cm at 5 cm voxels
constexpr double kRotTolDeg = 2.0;

struct CloudOutcome {
  double ms = 0;                 // the method's own time (model preparation + matching [+ verdict])
  double verdict_ms = 0;         // of which the ambiguity verdict (pRANSAM, ambiguity3d.h)
  bool reported = false;
  bool ambiguous = false;        // withheld as ambiguous (then reported = false)
  bool correct = false;          // after refinement (false without truth)
  double trans_err = NAN, rot_err_deg = NAN;
  double inlier_rms = NAN, inlier_fraction = NAN;
  Eigen::Matrix3f rotation = Eigen::Matrix3f::Identity();     // refined answer
  Eigen::Vector3f translation = Eigen::Vector3f::Zero();
};

struct MethodRun {
  std::string method;
  std::vector<CloudOutcome> outcomes;
  std::size_t n() const { return outcomes.size(); }
  std::size_t successes() const;
  std::size_t wrong() const;
  std::size_t nothing() const;    // not reported and not ambiguous
  std::size_t ambiguous() const;
  double success() const { return n() ? static_cast<double>(successes()) / static_cast<double>(n()) : 0.0; }
  double ms_p50() const;
  double ms_p99() const;
  void append(const MethodRun& other);
};

// Refines (r, t) with the common ICP against `model` (built over d.model) and scores it.
CloudOutcome score_answer(const CloudDraw& d, const PlaneModel& model, const Eigen::Matrix3f& r,
                          const Eigen::Vector3f& t, bool reported, double ms);

// Independent runs on a pair without truth (the bunny): the share of outcomes whose refined
// transform lies within the tolerance (kTransTolVoxels·voxel at the scene centroid, kRotTolDeg) of
// the transform most of them agree with; 1.0 = all runs agree on one transform.
double agreement(const CloudDraw& d, const std::vector<CloudOutcome>& runs);

// "office1 pransam: success 97/100, wrong 0, ambiguous 1, nothing 2, p50 … ms, p99 … ms".
std::string summary_line(const std::string& what, const MethodRun& r);

}  // namespace sim::pransam_eval
