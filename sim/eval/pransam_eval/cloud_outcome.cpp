#include "sim/eval/pransam_eval/cloud_outcome.h"

#include <algorithm>
#include <cstdio>

#include "sim/eval/pransam_eval/pransam_eval_lib.h"  // percentile

namespace sim::pransam_eval {

std::size_t MethodRun::successes() const {
  std::size_t k = 0;
  for (const auto& o : outcomes) k += o.reported && o.correct;
  return k;
}
std::size_t MethodRun::wrong() const {
  std::size_t k = 0;
  for (const auto& o : outcomes) k += o.reported && !o.correct;
  return k;
}
std::size_t MethodRun::nothing() const {
  std::size_t k = 0;
  for (const auto& o : outcomes) k += !o.reported && !o.ambiguous;
  return k;
}
std::size_t MethodRun::ambiguous() const {
  std::size_t k = 0;
  for (const auto& o : outcomes) k += o.ambiguous;
  return k;
}
double MethodRun::ms_p50() const {
  std::vector<double> v;
  for (const auto& o : outcomes) v.push_back(o.ms);
  return percentile(v, 0.5);
}
double MethodRun::ms_p99() const {
  std::vector<double> v;
  for (const auto& o : outcomes) v.push_back(o.ms);
  return percentile(v, 0.99);
}
void MethodRun::append(const MethodRun& other) {
  outcomes.insert(outcomes.end(), other.outcomes.begin(), other.outcomes.end());
}

CloudOutcome score_answer(const CloudDraw& d, const PlaneModel& model, const Eigen::Matrix3f& r,
                          const Eigen::Vector3f& t, bool reported, double ms) {
  CloudOutcome o;
  o.ms = ms;
  o.reported = reported;
  const IcpResult ref = refine_point_to_plane(d.scene, model, d.voxel, r, t);
  o.rotation = ref.rotation;
  o.translation = ref.translation;
  o.inlier_rms = ref.inlier_rms;
  o.inlier_fraction = ref.inlier_fraction;
  if (d.has_truth) {
    pose_error(d, o.rotation, o.translation, &o.trans_err, &o.rot_err_deg);
    o.correct = o.trans_err < kTransTolVoxels * d.voxel && o.rot_err_deg < kRotTolDeg;
  }
  return o;
}

double agreement(const CloudDraw& d, const std::vector<CloudOutcome>& runs) {
  std::size_t best = 0;
  for (const auto& a : runs) {
    CloudDraw ref = d;  // truth := a, then count the runs within tolerance of it
    ref.has_truth = true;
    ref.truth_rotation = a.rotation;
    ref.truth_translation = a.translation;
    std::size_t k = 0;
    for (const auto& b : runs) {
      double et, er;
      pose_error(ref, b.rotation, b.translation, &et, &er);
      k += et < kTransTolVoxels * d.voxel && er < kRotTolDeg;
    }
    best = std::max(best, k);
  }
  return runs.empty() ? 0.0 : static_cast<double>(best) / static_cast<double>(runs.size());
}

std::string summary_line(const std::string& what, const MethodRun& r) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), "%-32s success %3zu/%zu  wrong %2zu  ambiguous %2zu  nothing %3zu  p50 %8.1f ms  p99 %8.1f ms",
                what.c_str(), r.successes(), r.n(), r.wrong(), r.ambiguous(), r.nothing(), r.ms_p50(), r.ms_p99());
  return buf;
}

}  // namespace sim::pransam_eval
