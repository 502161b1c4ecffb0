// Small 2D pose-graph optimizer (host): Gauss-Newton on SE(2) relative-pose constraints
// (Grisetti, Kümmerle, Stachniss, Burgard, "A tutorial on graph-based SLAM", 2010, Sec. IV), the
// sparse normal equations solved by block-Jacobi preconditioned conjugate gradients (fixed-size
// Eigen blocks only, so it also builds under EIGEN_NO_MALLOC). Used to turn the fr-clinic
// benchmark relations (which chain every relation timestamp to the next and add 169 loop
// closures) into poses for its global map, as that data set has no corrected log.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "firmware/base/se2.h"

namespace sim {

struct PoseGraphEdge {
  std::size_t i = 0, j = 0;  // z = x_i ⊖ x_j measured (x_j in the frame of x_i)
  fw::Se2d z;
  Eigen::Matrix3d information = Eigen::Matrix3d::Identity();
};

struct PoseGraphOptions {
  int max_iterations = 30;
  double stop_relative_chi2_change = 1e-6;
  int cg_max_iterations = 20000;
  double cg_relative_tolerance = 1e-8;
};

struct PoseGraphResult {
  int iterations = 0;
  double initial_chi2 = 0, final_chi2 = 0;
  int cg_iterations_last = 0;
};

// Optimizes `poses` in place; node 0 is held fixed (gauge). Errors: empty graph, bad node index,
// non-finite values, or a diverging solve.
bool optimize_pose_graph(std::vector<fw::Se2d>* poses, const std::vector<PoseGraphEdge>& edges,
                         const PoseGraphOptions& options, PoseGraphResult* result, std::string* error);

// The residual e = t2v(z⁻¹ (x_i⁻¹ x_j)) of one edge (x, y, wrapped θ).
Eigen::Vector3d pose_graph_residual(const fw::Se2d& xi, const fw::Se2d& xj, const fw::Se2d& z);

}  // namespace sim
