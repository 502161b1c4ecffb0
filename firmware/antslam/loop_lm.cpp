#include "firmware/antslam/loop_lm.h"

#include <Eigen/LU>
#include <cmath>

namespace fw::antslam {

Status LoopLmOptions::validate() const {
  if (max_iterations == 0) return Status::error(Errc::kInvalidArgument, "loop LM: max_iterations must be > 0");
  if (!(initial_lambda > 0.0)) return Status::error(Errc::kInvalidArgument, "loop LM: initial_lambda must be > 0");
  if (!(min_relative_decrease >= 0.0)) {
    return Status::error(Errc::kInvalidArgument, "loop LM: min_relative_decrease must be >= 0");
  }
  return Status::ok();
}

std::size_t LoopLm::required_arena_bytes(std::uint32_t max_steps) {
  return static_cast<std::size_t>(max_steps) * (3 * sizeof(Se2d) + 2 * sizeof(Mat3) + sizeof(Vec3)) + 6 * 64;
}

Status LoopLm::init(const LoopLmOptions& options, std::uint32_t max_steps, StartupArena& arena) {
  FW_RETURN_IF_ERROR(options.validate());
  if (max_steps == 0) return Status::error(Errc::kInvalidArgument, "loop LM: max_steps must be > 0");
  options_ = options;
  max_steps_ = max_steps;
  auto a = arena.allocate_array<Se2d>(max_steps, "lm prefix");
  if (!a) return a.status();
  auto b = arena.allocate_array<Se2d>(max_steps, "lm suffix");
  if (!b) return b.status();
  auto c = arena.allocate_array<Se2d>(max_steps, "lm trial");
  if (!c) return c.status();
  auto d = arena.allocate_array<Mat3>(max_steps, "lm jacobians");
  if (!d) return d.status();
  auto e = arena.allocate_array<Mat3>(max_steps, "lm blocks");
  if (!e) return e.status();
  auto f = arena.allocate_array<Vec3>(max_steps, "lm gradient");
  if (!f) return f.status();
  prefix_ = *a;
  suffix_ = *b;
  trial_ = *c;
  jac_ = *d;
  dinv_ = *e;
  grad_ = *f;
  initialized_ = true;
  return Status::ok();
}

Se2d LoopLm::chain(const LoopProblem& p, const Se2d* values) const {
  Se2d x;
  for (std::uint32_t i = 0; i < p.num_steps; ++i) {
    const SampledEdge& e = *p.steps[i].edge;
    x = x.compose(step_transform(p.steps[i], e.frozen ? e.value : values[i]));
  }
  return x;
}

Status LoopLm::solve(const LoopProblem& p, Se2d* values, LoopLmReport* report) {
  if (!initialized_) return Status::error(Errc::kNotInitialized, "loop LM: init() not called");
  FW_RETURN_IF_ERROR(validate_loop(p));
  const std::uint32_t n = p.num_steps;
  if (n > max_steps_) {
    return Status::error(Errc::kCapacityExceeded, "loop LM: loop of %u edges exceeds max_steps %u", n, max_steps_);
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    if (p.steps[i].edge->frozen) values[i] = p.steps[i].edge->value;
  }
  double cost = loop_cost(p, values);
  if (!std::isfinite(cost)) return Status::error(Errc::kNumerical, "loop LM: non-finite start cost");
  if (report) report->initial_cost = cost;
  const Mat3 cov_h = p.closure_info.inverse();
  double lambda = options_.initial_lambda;
  std::uint32_t it = 0;
  for (it = 0; it < options_.max_iterations; ++it) {
    // Prefix/suffix products of the chain.
    Se2d acc;
    for (std::uint32_t i = 0; i < n; ++i) {
      prefix_[i] = acc;
      const SampledEdge& e = *p.steps[i].edge;
      acc = acc.compose(step_transform(p.steps[i], e.frozen ? e.value : values[i]));
    }
    const Vec3 r_h = se2_difference(acc, p.closure_mean);
    acc = Se2d();
    for (std::uint32_t i = n; i-- > 0;) {
      suffix_[i] = acc;
      const SampledEdge& e = *p.steps[i].edge;
      acc = step_transform(p.steps[i], e.frozen ? e.value : values[i]).compose(acc);
    }
    // J_i by central differences; D_i = Σ_i⁻¹ (damped); g_i = Σ_i⁻¹ r_i + J_iᵀ Σ_h⁻¹ r_h.
    Mat3 m = cov_h;  // Σ_h + Σ J_i D_i⁻¹ J_iᵀ
    Vec3 s = Vec3::Zero();
    const Vec3 w_h = p.closure_info * r_h;
    for (std::uint32_t i = 0; i < n; ++i) {
      const SampledEdge& e = *p.steps[i].edge;
      if (e.frozen) continue;
      constexpr double kH = 1e-6;
      for (int c = 0; c < 3; ++c) {
        Vec3 t(values[i].x, values[i].y, values[i].theta);
        t(c) += kH;
        const Se2d xp = prefix_[i].compose(step_transform(p.steps[i], Se2d::from_vector(t))).compose(suffix_[i]);
        t(c) -= 2 * kH;
        const Se2d xm = prefix_[i].compose(step_transform(p.steps[i], Se2d::from_vector(t))).compose(suffix_[i]);
        jac_[i].col(c) = se2_difference(xp, xm) / (2 * kH);
      }
      Mat3 d = e.info;
      d.diagonal() *= (1.0 + lambda);  // Marquardt damping
      dinv_[i] = d.inverse();
      const Vec3 r_i = se2_difference(values[i], e.mean);
      grad_[i] = e.info * r_i + jac_[i].transpose() * w_h;
      m += jac_[i] * dinv_[i] * jac_[i].transpose();
      s += jac_[i] * (dinv_[i] * grad_[i]);
    }
    const Vec3 ms = m.inverse() * s;
    if (!ms.allFinite()) return Status::error(Errc::kNumerical, "loop LM: singular closure system");
    // δ_i = −(D_i⁻¹ g_i − D_i⁻¹ J_iᵀ (Σ_h + J D⁻¹ Jᵀ)⁻¹ J D⁻¹ g)  (Woodbury)
    for (std::uint32_t i = 0; i < n; ++i) {
      if (p.steps[i].edge->frozen) {
        trial_[i] = values[i];
        continue;
      }
      const Vec3 delta = -(dinv_[i] * grad_[i] - dinv_[i] * (jac_[i].transpose() * ms));
      trial_[i] = Se2d(values[i].x + delta(0), values[i].y + delta(1), wrap_angle(values[i].theta + delta(2)));
    }
    const double trial_cost = loop_cost(p, trial_);
    if (std::isfinite(trial_cost) && trial_cost < cost) {
      const double decrease = (cost - trial_cost) / (cost > 0 ? cost : 1.0);
      for (std::uint32_t i = 0; i < n; ++i) values[i] = trial_[i];
      cost = trial_cost;
      lambda = lambda * 0.1 > 1e-12 ? lambda * 0.1 : 1e-12;
      if (decrease < options_.min_relative_decrease) {
        ++it;
        break;
      }
    } else {
      lambda *= 10.0;
      if (lambda > 1e12) {
        ++it;
        break;
      }
    }
  }
  if (report) {
    report->iterations = it;
    report->final_cost = cost;
  }
  return Status::ok();
}

}  // namespace fw::antslam
