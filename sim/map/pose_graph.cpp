#include "sim/common/fail.h"
#include "sim/map/pose_graph.h"

#include <Eigen/LU>
#include <cmath>

namespace sim {
namespace {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;

double chi2_of(const std::vector<fw::Se2d>& x, const std::vector<PoseGraphEdge>& edges) {
  double c = 0;
  for (const PoseGraphEdge& e : edges) {
    const Vec3 r = pose_graph_residual(x[e.i], x[e.j], e.z);
    c += r.dot(e.information * r);
  }
  return c;
}

struct BlockSystem {
  std::vector<Mat3> diag;
  std::vector<Mat3> off;  // one per edge: H_ij
  std::vector<Vec3> b;
};

void multiply(const BlockSystem& s, const std::vector<PoseGraphEdge>& edges, const std::vector<Vec3>& x,
              std::vector<Vec3>* y) {
  for (std::size_t n = 0; n < x.size(); ++n) (*y)[n] = s.diag[n] * x[n];
  for (std::size_t k = 0; k < edges.size(); ++k) {
    (*y)[edges[k].i] += s.off[k] * x[edges[k].j];
    (*y)[edges[k].j] += s.off[k].transpose() * x[edges[k].i];
  }
}

double dot(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double d = 0;
  for (std::size_t n = 0; n < a.size(); ++n) d += a[n].dot(b[n]);
  return d;
}

}  // namespace

Vec3 pose_graph_residual(const fw::Se2d& xi, const fw::Se2d& xj, const fw::Se2d& z) {
  const fw::Se2d e = z.inverse().compose(xi.between(xj));
  return Vec3(e.x, e.y, fw::wrap_angle(e.theta));
}

bool optimize_pose_graph(std::vector<fw::Se2d>* poses, const std::vector<PoseGraphEdge>& edges,
                         const PoseGraphOptions& o, PoseGraphResult* result, std::string* error) {
  std::vector<fw::Se2d>& x = *poses;
  const std::size_t n = x.size();
  if (n == 0 || edges.empty()) return fail(error, "pose graph: no nodes or no edges");
  for (std::size_t k = 0; k < edges.size(); ++k) {
    const PoseGraphEdge& e = edges[k];
    if (e.i >= n || e.j >= n || e.i == e.j) return fail(error, "pose graph: edge " + std::to_string(k) + " has a bad node index");
    if (!std::isfinite(e.z.x) || !std::isfinite(e.z.y) || !std::isfinite(e.z.theta) || !e.information.allFinite()) {
      return fail(error, "pose graph: edge " + std::to_string(k) + " is not finite");
    }
  }
  PoseGraphResult res;
  double chi2 = chi2_of(x, edges);
  res.initial_chi2 = chi2;
  BlockSystem s;
  s.diag.resize(n);
  s.off.resize(edges.size());
  s.b.resize(n);
  std::vector<Vec3> dx(n), r(n), z(n), p(n), q(n);
  std::vector<Mat3> precond(n);
  for (int it = 0; it < o.max_iterations; ++it) {
    for (std::size_t m = 0; m < n; ++m) {
      s.diag[m].setZero();
      s.b[m].setZero();
    }
    for (std::size_t k = 0; k < edges.size(); ++k) {
      const PoseGraphEdge& e = edges[k];
      const fw::Se2d& xi = x[e.i];
      const fw::Se2d& xj = x[e.j];
      const double ci = std::cos(xi.theta), si = std::sin(xi.theta);
      const double cz = std::cos(e.z.theta), sz = std::sin(e.z.theta);
      Eigen::Matrix2d RiT, RzT, dRiT;
      RiT << ci, si, -si, ci;
      RzT << cz, sz, -sz, cz;
      dRiT << -si, ci, -ci, -si;
      const Eigen::Vector2d dt(xj.x - xi.x, xj.y - xi.y);
      Mat3 A = Mat3::Zero(), B = Mat3::Zero();
      A.topLeftCorner<2, 2>() = -RzT * RiT;
      A.block<2, 1>(0, 2) = RzT * dRiT * dt;
      A(2, 2) = -1;
      B.topLeftCorner<2, 2>() = RzT * RiT;
      B(2, 2) = 1;
      const Vec3 err = pose_graph_residual(xi, xj, e.z);
      const Mat3 AtO = A.transpose() * e.information, BtO = B.transpose() * e.information;
      s.diag[e.i] += AtO * A;
      s.diag[e.j] += BtO * B;
      s.off[k] = AtO * B;
      s.b[e.i] += AtO * err;
      s.b[e.j] += BtO * err;
    }
    s.diag[0] += Mat3::Identity() * 1e12;  // gauge: node 0 fixed
    for (std::size_t m = 0; m < n; ++m) {
      // A node without constraints keeps its pose (identity block keeps the system regular).
      if (s.diag[m].isZero()) s.diag[m] = Mat3::Identity();
      precond[m] = s.diag[m].inverse();
    }
    // PCG on H dx = -b.
    for (std::size_t m = 0; m < n; ++m) {
      dx[m].setZero();
      r[m] = -s.b[m];
      z[m] = precond[m] * r[m];
      p[m] = z[m];
    }
    double rz = dot(r, z);
    const double r0 = std::sqrt(dot(r, r));
    int cg = 0;
    for (; cg < o.cg_max_iterations && r0 > 0; ++cg) {
      multiply(s, edges, p, &q);
      const double pq = dot(p, q);
      if (!(pq > 0)) break;
      const double alpha = rz / pq;
      for (std::size_t m = 0; m < n; ++m) {
        dx[m] += alpha * p[m];
        r[m] -= alpha * q[m];
      }
      if (std::sqrt(dot(r, r)) <= o.cg_relative_tolerance * r0) break;
      for (std::size_t m = 0; m < n; ++m) z[m] = precond[m] * r[m];
      const double rz_new = dot(r, z);
      const double beta = rz_new / rz;
      rz = rz_new;
      for (std::size_t m = 0; m < n; ++m) p[m] = z[m] + beta * p[m];
    }
    res.cg_iterations_last = cg;
    for (std::size_t m = 0; m < n; ++m) {
      if (!dx[m].allFinite()) return fail(error, "pose graph: solve diverged (non-finite update)");
      x[m].x += dx[m](0);
      x[m].y += dx[m](1);
      x[m].theta = fw::wrap_angle(x[m].theta + dx[m](2));
    }
    const double new_chi2 = chi2_of(x, edges);
    res.iterations = it + 1;
    const double change = std::abs(chi2 - new_chi2) / std::max(chi2, 1e-300);
    chi2 = new_chi2;
    if (change < o.stop_relative_chi2_change) break;
  }
  res.final_chi2 = chi2;
  if (result != nullptr) *result = res;
  return true;
}

}  // namespace sim
