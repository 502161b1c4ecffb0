// The draws of the real 3-D experiments (issue 17) on ../shared/data/pcl3d, shared by pRANSAM and
// the PCL peers so that every method sees exactly the same clouds:
//  - office1 (organized RGB-D frame, 254,456 finite points): two overlapping slabs of the frame
//    along a random image axis (x or y), cut at point quantiles so that each holds the same number
//    of points and a share o ~ U[0.60, 0.80] of the scene's points lies in the model slab too;
//    the scene slab A is moved by a uniformly random rotation (the full SO(3), random unit
//    quaternion) and a translation in [-1, 1]³ m, with Gaussian noise σ = 0.1 voxel per axis; both
//    slabs are then voxel-downsampled separately (independent samplings of the same surfaces);
//  - car6, milk: the model is the whole (downsampled) cloud; the scene is a copy cut by a random
//    plane that keeps a fraction U[0.60, 0.80] of it, moved and noised as above (translation in
//    ±the cloud's diameter), downsampled separately;
//  - bun0 ↔ bun4: the real pair as it is (already sparse), no ground truth.
// Truth (rotation, translation) maps scene points into the model frame, like a pRANSAM hypothesis.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/io/pcd.h"

namespace sim::pransam_eval {

struct CloudDraw {
  std::string cloud;       // "office1", "car6", "milk", "bunny"
  std::size_t index = 0;   // draw number
  float voxel = 0.05f;     // downsampling voxel (metres); thresholds are stated relative to it
  std::vector<Eigen::Vector3f> scene, model;  // A (moved) and B, downsampled
  bool has_truth = true;
  Eigen::Matrix3f truth_rotation = Eigen::Matrix3f::Identity();
  Eigen::Vector3f truth_translation = Eigen::Vector3f::Zero();
  double overlap = 0.0;    // share of A's raw points inside B's region (drawn fraction for objects)
  Eigen::Vector3f scene_sensor = Eigen::Vector3f::Zero();  // the camera in A's frame (office only)
  bool scene_sensor_known = false;
};

struct DrawOptions {
  std::size_t draws = 100;
  std::uint64_t seed = 17;
  float voxel = 0.05f;
  float overlap_min = 0.60f, overlap_max = 0.80f;
  float noise_voxels = 0.1f;   // σ of the Gaussian noise, in voxels
};

// Voxel sizes of the experiment (metres): office 5 cm; car6 (6.7 m long) 10 cm; milk (25 cm) 5 mm.
float default_voxel(const std::string& cloud);

// Path of a cloud in the data folder (MMLFW_DATA_DIR, default ../shared/data): pcl3d/<file>.
std::string cloud_path(const std::string& file);

bool make_office_draws(const PcdCloud& office, const DrawOptions& o, std::vector<CloudDraw>* out, std::string* error);
bool make_object_draws(const PcdCloud& object, const std::string& name, const DrawOptions& o,
                       std::vector<CloudDraw>* out, std::string* error);
// bun0 (model) and bun4 (scene), no ground truth, no downsampling.
bool make_bunny_pair(const PcdCloud& bun0, const PcdCloud& bun4, CloudDraw* out);

// Loads pcl3d/<file> and makes the draws of `cloud` ("office1", "car6", "milk"); false with a clear
// message (naming the path) when the file is missing or malformed.
bool load_draws(const std::string& cloud, const DrawOptions& o, std::vector<CloudDraw>* out, std::string* error);
bool load_bunny(CloudDraw* out, std::string* error);

// Errors of an estimate against the draw's truth: translation of the scene's centroid (m) and
// rotation angle (degrees).
void pose_error(const CloudDraw& d, const Eigen::Matrix3f& r, const Eigen::Vector3f& t, double* trans_m,
                double* rot_deg);

}  // namespace sim::pransam_eval
