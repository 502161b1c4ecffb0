// One loop L of AntSLAM (Ch. 3, SPEC §2): the Dijkstra-shortest fragment sequence from the
// candidate fragment c to the active fragment a, as the edges walked in order (each forward or
// backward), and the loop-closing measurement h ~ N(μ_h, Σ_h) of F_a in F_c found by pRANSAM.
// The cost of a hypothesis H = (t_1 … t_n) (one transform per edge of L) is Eq. 3.13:
//   W(H) = Σ_i (t_i − μ_i)ᵀ Σ_i⁻¹ (t_i − μ_i) + (x − μ_h)ᵀ Σ_h⁻¹ (x − μ_h),  x = t_1 ⊕ … ⊕ t_n
// (t_i walked backward enters x as ⊖t_i). Frozen edges (corrected by an earlier loop) are
// constants: they enter x with their value and add nothing to the first sum.
#pragma once

#include <cstdint>

#include "firmware/antslam/sampled_edge.h"

namespace fw::antslam {

struct LoopStep {
  const SampledEdge* edge = nullptr;
  bool forward = true;  // walked from edge->from to edge->to
};

struct LoopProblem {
  const LoopStep* steps = nullptr;
  std::uint32_t num_steps = 0;
  Se2d closure_mean;                    // μ_h: F_a in F_c
  Mat3 closure_info = Mat3::Identity(); // Σ_h⁻¹
};

// The transform an edge contributes when it holds forward-direction value t.
inline Se2d step_transform(const LoopStep& s, const Se2d& t) { return s.forward ? t : t.inverse(); }

// Eq. 3.13 for per-step forward-direction values (frozen steps: their own value, whatever is given).
double loop_cost(const LoopProblem& p, const Se2d* values);

// Closure term only: x = ⊕ of the steps, (x − μ_h)ᵀ Σ_h⁻¹ (x − μ_h).
double closure_cost(const LoopProblem& p, const Se2d& x);

// Errors: no steps, null edge, non-finite closure.
Status validate_loop(const LoopProblem& p);

}  // namespace fw::antslam
