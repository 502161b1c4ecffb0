#include "sim/io/voxel_downsample.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace sim {

bool voxel_downsample(const std::vector<Eigen::Vector3f>& in, float voxel, std::vector<Eigen::Vector3f>* out,
                      std::string* error, const std::string& name) {
  out->clear();
  if (!(voxel > 0.0f) || !std::isfinite(voxel)) {
    *error = name + ": voxel size " + std::to_string(voxel) + " is not a positive finite size";
    return false;
  }
  if (in.empty()) return true;
  Eigen::Vector3f lo = in[0];
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (!in[i].allFinite()) {
      *error = name + ": point " + std::to_string(i) + " is not finite";
      return false;
    }
    lo = lo.cwiseMin(in[i]);
  }
  // Voxels anchored at multiples of `voxel` (not at the cloud's corner), so two clouds of one scene
  // share the grid; keys are taken relative to the lowest voxel to stay non-negative.
  const Eigen::Vector3f base = (lo / voxel).array().floor() * voxel;
  constexpr std::int64_t kAxis = std::int64_t(1) << 20;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    const Eigen::Vector3f c = (in[i] - base) / voxel;
    std::int64_t k[3];
    for (int a = 0; a < 3; ++a) {
      k[a] = static_cast<std::int64_t>(std::floor(c(a)));
      if (k[a] < 0) k[a] = 0;  // rounding of a point on the lowest voxel's face
      if (k[a] >= kAxis) {
        *error = name + ": cloud spans more than 2^20 voxels of " + std::to_string(voxel) + " m along an axis";
        return false;
      }
    }
    keyed[i] = {static_cast<std::uint64_t>((k[0] << 40) | (k[1] << 20) | k[2]), static_cast<std::uint32_t>(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  for (std::size_t b = 0; b < keyed.size();) {
    std::size_t e = b;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    while (e < keyed.size() && keyed[e].first == keyed[b].first) sum += in[keyed[e++].second].cast<double>();
    out->push_back((sum / static_cast<double>(e - b)).cast<float>());
    b = e;
  }
  return true;
}

}  // namespace sim
