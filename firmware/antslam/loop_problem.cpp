#include "firmware/antslam/loop_problem.h"

#include <cmath>

namespace fw::antslam {

double closure_cost(const LoopProblem& p, const Se2d& x) { return mahalanobis2(x, p.closure_mean, p.closure_info); }

double loop_cost(const LoopProblem& p, const Se2d* values) {
  double w = 0.0;
  Se2d x;
  for (std::uint32_t i = 0; i < p.num_steps; ++i) {
    const LoopStep& s = p.steps[i];
    const Se2d t = s.edge->frozen ? s.edge->value : values[i];
    if (!s.edge->frozen) w += mahalanobis2(t, s.edge->mean, s.edge->info);  // Eq. 3.13, first sum
    x = x.compose(step_transform(s, t));
  }
  return w + closure_cost(p, x);  // Eq. 3.13, closure term
}

Status validate_loop(const LoopProblem& p) {
  if (p.steps == nullptr || p.num_steps == 0) return Status::error(Errc::kInvalidArgument, "loop: no edges");
  for (std::uint32_t i = 0; i < p.num_steps; ++i) {
    if (p.steps[i].edge == nullptr) return Status::error(Errc::kInvalidArgument, "loop: step %u has no edge", i);
  }
  if (!std::isfinite(p.closure_mean.x) || !std::isfinite(p.closure_mean.y) || !std::isfinite(p.closure_mean.theta) ||
      !p.closure_info.allFinite()) {
    return Status::error(Errc::kInvalidArgument, "loop: non-finite closure measurement");
  }
  return Status::ok();
}

}  // namespace fw::antslam
