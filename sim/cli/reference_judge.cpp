#include "sim/cli/reference_judge.h"

#include <cmath>

#include "firmware/base/se2.h"
#include "sim/common/units.h"
#include "sim/eval/mml_eval/reference_map_check.h"
#include "sim/eval/mml_eval/unmapped_scan.h"

namespace sim {

namespace {

// Beyond the integrity limits or the step's PL against the log reference alone: where the map is asked.
bool beyond_a_limit(const StepRecord& r) {
  mmleval::JudgedError raw;
  raw.ref_m = r.err_m;
  raw.ref_ang = r.err_deg;
  const hal::PoseEstimate& e = r.estimate;
  return mmleval::beyond_reference(raw, kIntegrityLimitM, kIntegrityLimitDeg) ||
         mmleval::beyond_reference(raw, e.protection_xy_m, e.protection_theta_rad * kRadToDeg);
}

}  // namespace

std::size_t check_steps_against_map(const fw::GlobalMap& map, const std::vector<Frame>& frames,
                                    std::vector<StepRecord>* steps) {
  std::size_t checked = 0;
  for (StepRecord& r : *steps) {
    if (!r.has_truth || !r.has_pose || r.estimate.status != hal::LocalizationStatus::kLocalized) continue;
    if (!std::isfinite(r.err_m) || !std::isfinite(r.err_deg) || !beyond_a_limit(r)) continue;
    const std::uint32_t k = r.estimate.scan_id;
    if (k >= frames.size() || frames[k].scan.scan_id != k) continue;
    const mmleval::ReferenceMapFit f = mmleval::check_reference_against_map(map, mmleval::carmen_scan_of(frames[k].scan), r.truth);
    ++checked;
    r.map_checked = true;
    r.map_pose_better = f.improves;
    const hal::PoseEstimate& e = r.estimate;
    r.map_err_m = std::hypot(e.x - f.best.x, e.y - f.best.y);
    r.map_err_deg = std::fabs(fw::wrap_angle(static_cast<double>(e.theta) - f.best.theta)) * kRadToDeg;
  }
  return checked;
}

std::size_t mark_unmapped_steps(const fw::GlobalMap& map, const std::vector<Frame>& frames,
                                std::vector<StepRecord>* steps) {
  std::size_t marked = 0;
  for (StepRecord& r : *steps) {
    const std::uint32_t k = r.estimate.scan_id;
    if (!r.has_truth || r.in_unknown || k >= frames.size() || frames[k].scan.scan_id != k) continue;
    const mmleval::UnmappedScan u = mmleval::unmapped_scan(map, mmleval::carmen_scan_of(frames[k].scan), r.truth);
    if (!mmleval::in_unmapped_area(u)) continue;
    r.in_unknown = true;
    ++marked;
  }
  return marked;
}

}  // namespace sim
