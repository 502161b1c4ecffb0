// Voxel-grid downsampling of a 3-D point cloud for the host tools (the role of PCL's VoxelGrid):
// space is cut into cubes of edge `voxel` anchored at the origin, and every occupied cube becomes
// the centroid of its points. The output is ordered by voxel key, so it depends on the point SET
// only, not on the input order (same input ⇒ same output, whatever the reader or a shuffle did).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace sim {

// False (with *error naming `name`) when voxel is not a positive finite size, a point is not
// finite, or the cloud spans more than 2^20 voxels along an axis (the key would overflow).
bool voxel_downsample(const std::vector<Eigen::Vector3f>& in, float voxel, std::vector<Eigen::Vector3f>* out,
                      std::string* error, const std::string& name = "cloud");

}  // namespace sim
