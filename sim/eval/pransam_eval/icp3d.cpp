#include "sim/eval/pransam_eval/icp3d.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>

namespace sim::pransam_eval {

std::uint64_t PlaneModel::key(long x, long y, long z) const {
  // 21 bits per axis, offset so that negative cells stay distinct.
  const auto u = [](long v) { return static_cast<std::uint64_t>(v + (1l << 20)) & ((1ull << 21) - 1); };
  return (u(x) << 42) | (u(y) << 21) | u(z);
}

std::uint64_t PlaneModel::key(const Eigen::Vector3f& p) const {
  return key(static_cast<long>(std::floor(p.x() / cell_)), static_cast<long>(std::floor(p.y() / cell_)),
             static_cast<long>(std::floor(p.z() / cell_)));
}

void PlaneModel::build(const std::vector<Eigen::Vector3f>* points, float normal_radius) {
  points_ = points;
  cell_ = normal_radius;
  grid_.clear();
  for (std::size_t i = 0; i < points->size(); ++i) grid_[key((*points)[i])].push_back(static_cast<std::uint32_t>(i));
  normals_.assign(points->size(), Eigen::Vector3f::UnitZ());
  const float r2 = normal_radius * normal_radius;
  for (std::size_t i = 0; i < points->size(); ++i) {
    const Eigen::Vector3f& p = (*points)[i];
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    int n = 0;
    for_each_near(p, [&](std::uint32_t j) {
      const Eigen::Vector3f& q = (*points)[j];
      if ((q - p).squaredNorm() > r2) return;
      const Eigen::Vector3d qd = q.cast<double>();
      mean += qd;
      cov += qd * qd.transpose();
      ++n;
    });
    if (n < 3) continue;
    mean /= n;
    cov = cov / n - mean * mean.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
    normals_[i] = es.eigenvectors().col(0).cast<float>();  // smallest eigenvalue: the surface normal
  }
}

int PlaneModel::nearest(const Eigen::Vector3f& p, float max_dist) const {
  float best = max_dist * max_dist;
  int bi = -1;
  for_each_near(p, [&](std::uint32_t j) {
    const float d2 = ((*points_)[j] - p).squaredNorm();
    if (d2 < best) {
      best = d2;
      bi = static_cast<int>(j);
    }
  });
  return bi;
}

IcpResult refine_point_to_plane(const std::vector<Eigen::Vector3f>& scene, const PlaneModel& model, float voxel,
                                const Eigen::Matrix3f& r0, const Eigen::Vector3f& t0, const IcpOptions& options) {
  IcpResult res;
  Eigen::Matrix3d r = r0.cast<double>();
  Eigen::Vector3d t = t0.cast<double>();
  for (int it = 0; it < options.iterations; ++it) {
    const float f = options.iterations > 1 ? static_cast<float>(it) / static_cast<float>(options.iterations - 1) : 1.0f;
    const float dist = voxel * (options.start_dist + (options.end_dist - options.start_dist) * f);
    Eigen::Matrix<double, 6, 6> h = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    int used = 0;
    for (const auto& a : scene) {
      const Eigen::Vector3d p = r * a.cast<double>() + t;
      const int j = model.nearest(p.cast<float>(), dist);
      if (j < 0) continue;
      const Eigen::Vector3d n = model.normal(j).cast<double>();
      const double e = n.dot(p - model.point(j).cast<double>());
      Eigen::Matrix<double, 6, 1> jac;
      jac << n, p.cross(n);  // δt and a small left rotation ω: ∂e/∂ω = (p × n)
      h += jac * jac.transpose();
      g += jac * e;
      ++used;
    }
    if (used < 12) break;
    for (int k = 0; k < 6; ++k) h(k, k) += 1e-9;
    const Eigen::Matrix<double, 6, 1> step = -h.ldlt().solve(g);
    if (!step.allFinite()) break;
    const Eigen::Vector3d w = step.tail<3>();
    Eigen::Matrix3d dr = Eigen::Matrix3d::Identity();
    if (w.norm() > 1e-12) dr = Eigen::AngleAxisd(w.norm(), w / w.norm()).toRotationMatrix();
    r = dr * r;
    t = dr * t + step.head<3>();
    if (step.head<3>().norm() < 1e-4 * voxel && w.norm() < 1e-5) break;  // converged (0.005 mm at 5 cm)
  }
  // Re-orthonormalise (accumulated products of rotations drift slightly).
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  r = svd.matrixU() * svd.matrixV().transpose();
  double sum = 0;
  std::size_t in = 0;
  for (const auto& a : scene) {
    const Eigen::Vector3d p = r * a.cast<double>() + t;
    const int j = model.nearest(p.cast<float>(), voxel);
    if (j < 0) continue;
    sum += (p - model.point(j).cast<double>()).squaredNorm();
    ++in;
  }
  res.rotation = r.cast<float>();
  res.translation = t.cast<float>();
  res.inlier_rms = in ? std::sqrt(sum / static_cast<double>(in)) : NAN;
  res.inlier_fraction = scene.empty() ? 0.0 : static_cast<double>(in) / static_cast<double>(scene.size());
  return res;
}

}  // namespace sim::pransam_eval
