// The common refinement of the 3-D experiments (issue 17): every method's answer (pRANSAM, PCL
// FPFH + SampleConsensusPrerejective, K-4PCS) is polished by the same trimmed point-to-plane ICP
// before it is scored, so "within 2 cm / 2° after refinement" compares the global step only.
// Model normals: PCA of the model points within 2.5 voxels; nearest neighbours: a hash grid of
// cells of the search radius (27 cells per query). Host code (std containers).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace sim::pransam_eval {

class PlaneModel {
 public:
  // `points` must outlive the model; normal_radius (m) also sets the grid cell.
  void build(const std::vector<Eigen::Vector3f>* points, float normal_radius);
  // Nearest model point within max_dist (≤ the normal radius): index or -1.
  int nearest(const Eigen::Vector3f& p, float max_dist) const;
  const Eigen::Vector3f& point(int i) const { return (*points_)[static_cast<std::size_t>(i)]; }
  const Eigen::Vector3f& normal(int i) const { return normals_[static_cast<std::size_t>(i)]; }
  const std::vector<Eigen::Vector3f>& points() const { return *points_; }

 private:
  std::uint64_t key(const Eigen::Vector3f& p) const;
  std::uint64_t key(long x, long y, long z) const;
  // Calls f(j) for every model point j in the 3×3×3 cells around p (one cell = the normal radius).
  template <class F>
  void for_each_near(const Eigen::Vector3f& p, F&& f) const {
    const long cx = static_cast<long>(std::floor(p.x() / cell_)), cy = static_cast<long>(std::floor(p.y() / cell_)),
               cz = static_cast<long>(std::floor(p.z() / cell_));
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy)
        for (long dz = -1; dz <= 1; ++dz) {
          auto it = grid_.find(key(cx + dx, cy + dy, cz + dz));
          if (it == grid_.end()) continue;
          for (std::uint32_t j : it->second) f(j);
        }
  }
  const std::vector<Eigen::Vector3f>* points_ = nullptr;
  std::vector<Eigen::Vector3f> normals_;
  float cell_ = 1.0f;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> grid_;
};

struct IcpOptions {
  int iterations = 30;
  float start_dist = 3.0f;   // correspondence radius at the start, in voxels
  float end_dist = 1.0f;     // … shrinking linearly to this (voxels)
};

struct IcpResult {
  Eigen::Matrix3f rotation = Eigen::Matrix3f::Identity();
  Eigen::Vector3f translation = Eigen::Vector3f::Zero();
  double inlier_rms = 0.0;       // point-to-point RMS of the scene points within 1 voxel of the model
  double inlier_fraction = 0.0;  // their share of the scene
};

// Refines (r0, t0), which maps scene into the model frame.
IcpResult refine_point_to_plane(const std::vector<Eigen::Vector3f>& scene, const PlaneModel& model, float voxel,
                                const Eigen::Matrix3f& r0, const Eigen::Vector3f& t0,
                                const IcpOptions& options = IcpOptions());

}  // namespace sim::pransam_eval
