// Final refinement of the whole fragment graph (extension of Alg. 3, not in the dissertation).
// AntSLAM corrects each loop when it closes and freezes it ("corrected loops are frozen"), so a later
// closure's error can only go into the edges not yet frozen — one or two new ones (README, AntSLAM
// section: on intel the front end alone scores better than after the loop corrections). Once the
// run ends, nothing else will close, and the map frames can be refined against every measurement
// at once: the fragment frames P_i minimise the same quadratic edge cost as Eq. 3.13's first term,
//   W = Σ_e r_eᵀ Σ_e⁻¹ r_e,   r_e = (P_from ⊖ P_to) − μ_e   (se2_difference, angle wrapped),
// over every adjacent and closing edge (a pose-graph least-squares problem, Gauss–Newton). Frame 0
// is held (gauge). The normal equations H δ = −g are solved by conjugate gradients preconditioned
// with H's 3×3 diagonal blocks and H applied edge by edge (matrix-free): fixed-size Eigen blocks,
// storage from the arena, O(edges) per product, no sparse factorisation. Deterministic.
#pragma once

#include <cstdint>

#include "firmware/antslam/sampled_edge.h"
#include "firmware/base/arena.h"
#include "firmware/base/status.h"

namespace fw::antslam {

struct GraphRefineOptions {
  std::uint32_t max_iterations = 20;       // Gauss–Newton
  std::uint32_t max_cg_iterations = 20000;  // per Gauss–Newton step (fr-clinic: 9173 over its 4 steps)
  double cg_relative_tolerance = 1e-10;    // |r| / |g|
  double min_relative_decrease = 1e-9;     // stop when W drops by less than this share
  Status validate() const;
};

struct GraphRefineReport {
  std::uint32_t iterations = 0;
  std::uint32_t cg_iterations = 0;  // summed over the Gauss–Newton steps
  double initial_cost = 0.0, final_cost = 0.0;
};

// W of the frames `poses` under `edges` (each edge's mean μ and information Σ⁻¹).
double graph_cost(const SampledEdge* edges, std::uint32_t num_edges, const Se2d* poses);

class GraphRefine {
 public:
  static std::size_t required_arena_bytes(std::uint32_t max_nodes, std::uint32_t max_edges);
  Status init(const GraphRefineOptions& options, std::uint32_t max_nodes, std::uint32_t max_edges,
              StartupArena& arena);
  // poses: in the start, out the minimum (poses[0] unchanged). Every edge's from/to < num_nodes.
  // A step that does not lower W is not taken (the start is returned when none does).
  Status refine(const SampledEdge* edges, std::uint32_t num_edges, Se2d* poses, std::uint32_t num_nodes,
                GraphRefineReport* report);

 private:
  // H v for the current linearisation (the edges' Jacobians kept in jac_ by the Gauss–Newton step).
  void apply_h(const SampledEdge* edges, std::uint32_t num_edges, const Eigen::Vector3d* v, Eigen::Vector3d* out,
               std::uint32_t n) const;
  GraphRefineOptions options_;
  std::uint32_t max_nodes_ = 0, max_edges_ = 0;
  Eigen::Matrix3d* jac_ = nullptr;  // per edge: ∂r/∂P_from, ∂r/∂P_to at the current linearisation
  Eigen::Vector3d* g_ = nullptr;   // gradient, then CG residual
  Eigen::Vector3d* x_ = nullptr;   // CG solution (δ)
  Eigen::Vector3d* p_ = nullptr;   // CG direction
  Eigen::Vector3d* q_ = nullptr;   // H p
  Eigen::Vector3d* z_ = nullptr;   // preconditioned residual
  Eigen::Matrix3d* dinv_ = nullptr;  // inverse diagonal blocks
  Se2d* trial_ = nullptr;
};

}  // namespace fw::antslam
