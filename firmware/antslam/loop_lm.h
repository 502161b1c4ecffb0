// Levenberg–Marquardt on the AntSLAM loop cost W (Eq. 3.13), the dissertation's comparison for the
// ant colony (SPEC §2: "LM was faster/better except in rare local minima"). Unknowns: the
// forward-direction transforms t_i of the free edges of the loop (3 each). The normal matrix is
// H = D + Jᵀ Σ_h⁻¹ J with D = blockdiag(Σ_i⁻¹) (the edge priors) and J (3 × 3n) the Jacobian of
// the closure residual x − μ_h, so it is solved exactly with the Woodbury identity in 3×3 blocks:
//   H⁻¹ g = D⁻¹g − D⁻¹Jᵀ (Σ_h + J D⁻¹ Jᵀ)⁻¹ J D⁻¹ g
// — fixed-size Eigen only, O(n) per iteration, no sparse solver. Marquardt damping scales D's
// diagonal by (1 + λ). J_i comes from the chain x = P_i ⊕ t_i^(±1) ⊕ S_i (prefix/suffix products)
// by central differences. Storage from the arena.
#pragma once

#include <cstdint>

#include "firmware/antslam/loop_problem.h"
#include "firmware/base/arena.h"
#include "firmware/base/status.h"

namespace fw::antslam {

struct LoopLmOptions {
  std::uint32_t max_iterations = 50;
  double initial_lambda = 1e-4;
  double min_relative_decrease = 1e-10;  // stop when W drops by less than this share
  Status validate() const;
};

struct LoopLmReport {
  std::uint32_t iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
};

class LoopLm {
 public:
  static std::size_t required_arena_bytes(std::uint32_t max_steps);
  Status init(const LoopLmOptions& options, std::uint32_t max_steps, StartupArena& arena);
  const LoopLmOptions& options() const { return options_; }

  // values: in the start (forward-direction transforms, e.g. the edge means), out the minimum.
  Status solve(const LoopProblem& problem, Se2d* values, LoopLmReport* report);

 private:
  Se2d chain(const LoopProblem& p, const Se2d* values) const;

  LoopLmOptions options_;
  std::uint32_t max_steps_ = 0;
  bool initialized_ = false;
  Se2d* prefix_ = nullptr;  // ⊕ of steps before i
  Se2d* suffix_ = nullptr;  // ⊕ of steps after i
  Se2d* trial_ = nullptr;
  Mat3* jac_ = nullptr;     // ∂(x − μ_h)/∂t_i
  Mat3* dinv_ = nullptr;    // damped D_i⁻¹
  Vec3* grad_ = nullptr;
};

}  // namespace fw::antslam
