#include "sim/eval/pransam_eval/cloud_draws.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "firmware/base/rng.h"
#include "sim/eval/pransam_scenes.h"
#include "sim/io/datasets.h"
#include "sim/io/voxel_downsample.h"

namespace sim::pransam_eval {

namespace {

using pransam_scenes::gaussian3f;

// Uniform in [lo, hi) in each coordinate, last coordinate first (as gaussian3f, pransam_scenes.h).
Eigen::Vector3f uniform3f(fw::RandomStream& r, float lo, float hi) {
  const float z = r.uniform(lo, hi), y = r.uniform(lo, hi), x = r.uniform(lo, hi);
  return Eigen::Vector3f(x, y, z);
}

// Uniform rotation over SO(3): a normalised 4-D Gaussian is a uniform unit quaternion.
Eigen::Matrix3f random_rotation(fw::RandomStream& r) {
  const float qz = r.gaussianf(0, 1), qy = r.gaussianf(0, 1), qx = r.gaussianf(0, 1), qw = r.gaussianf(0, 1);
  Eigen::Quaternionf q(qw, qx, qy, qz);
  q.normalize();
  return q.toRotationMatrix();
}

// Moves `pts` by x → R·x + t with noise, downsamples; sets the truth (scene → model) on d.
bool move_scene(const std::vector<Eigen::Vector3f>& pts, fw::RandomStream& r, float max_trans, float noise,
                CloudDraw* d, std::string* error) {
  const Eigen::Matrix3f rot = random_rotation(r);
  const Eigen::Vector3f t = uniform3f(r, -max_trans, max_trans);
  std::vector<Eigen::Vector3f> moved;
  moved.reserve(pts.size());
  for (const auto& p : pts) {
    moved.push_back(rot * p + t + gaussian3f(r, noise));
  }
  d->truth_rotation = rot.transpose();
  d->truth_translation = -(rot.transpose() * t);
  d->scene_sensor = t;  // the camera (origin of the raw frame) in A's frame
  return voxel_downsample(moved, d->voxel, &d->scene, error, d->cloud + " scene");
}

}  // namespace

float default_voxel(const std::string& cloud) {
  if (cloud == "car6") return 0.10f;
  if (cloud == "milk") return 0.005f;
  return 0.05f;
}

std::string cloud_path(const std::string& file) { return data_path("pcl3d/" + file); }

bool make_office_draws(const PcdCloud& office, const DrawOptions& o, std::vector<CloudDraw>* out, std::string* error) {
  out->clear();
  const std::vector<Eigen::Vector3f>& raw = office.points;
  if (raw.size() < 1000) {
    *error = office.path + ": only " + std::to_string(raw.size()) + " finite points for the office draws";
    return false;
  }
  // Sorted coordinates per image axis: the slabs are cut at point quantiles, so that the drawn
  // overlap is the share of A's points that B also holds (the frame's density is far from uniform).
  std::vector<float> sorted[2];
  for (int a = 0; a < 2; ++a) {
    sorted[a].reserve(raw.size());
    for (const auto& p : raw) sorted[a].push_back(p(a));
    std::sort(sorted[a].begin(), sorted[a].end());
  }
  for (std::size_t k = 0; k < o.draws; ++k) {
    fw::RandomStream r(o.seed, 1000 + k);
    CloudDraw d;
    d.cloud = "office1";
    d.index = k;
    d.voxel = o.voxel;
    d.scene_sensor_known = true;
    const int axis = r.uniform01f() < 0.5f ? 0 : 1;
    const float ov = r.uniform(o.overlap_min, o.overlap_max);
    // Both slabs hold a share s of the points, one from each end: overlap (2s − 1)/s = ov.
    const float share = 1.0f / (2.0f - ov);
    const std::vector<float>& v = sorted[axis];
    const float low_cut = v[static_cast<std::size_t>(share * static_cast<float>(v.size() - 1))];
    const float high_cut = v[static_cast<std::size_t>((1.0f - share) * static_cast<float>(v.size() - 1))];
    const bool scene_low = r.uniform01f() < 0.5f;
    std::vector<Eigen::Vector3f> a, b;
    std::size_t a_in_b = 0;
    for (const auto& p : raw) {
      const bool in_low = p(axis) <= low_cut, in_high = p(axis) >= high_cut;
      const bool in_a = scene_low ? in_low : in_high, in_b = scene_low ? in_high : in_low;
      if (in_a) a.push_back(p);
      if (in_b) b.push_back(p);
      if (in_a && in_b) ++a_in_b;
    }
    d.overlap = a.empty() ? 0.0 : static_cast<double>(a_in_b) / static_cast<double>(a.size());
    if (!move_scene(a, r, 1.0f, o.noise_voxels * o.voxel, &d, error)) return false;
    if (!voxel_downsample(b, o.voxel, &d.model, error, "office1 model")) return false;
    out->push_back(std::move(d));
  }
  return true;
}

bool make_object_draws(const PcdCloud& object, const std::string& name, const DrawOptions& o,
                       std::vector<CloudDraw>* out, std::string* error) {
  out->clear();
  const std::vector<Eigen::Vector3f>& raw = object.points;
  if (raw.size() < 100) {
    *error = object.path + ": only " + std::to_string(raw.size()) + " finite points for the object draws";
    return false;
  }
  Eigen::Vector3f lo = raw[0], hi = raw[0], c = Eigen::Vector3f::Zero();
  for (const auto& p : raw) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    c += p;
  }
  c /= static_cast<float>(raw.size());
  const float diameter = (hi - lo).norm();
  std::vector<Eigen::Vector3f> model;
  if (!voxel_downsample(raw, o.voxel, &model, error, name + " model")) return false;
  for (std::size_t k = 0; k < o.draws; ++k) {
    fw::RandomStream r(o.seed, 2000 + k);
    CloudDraw d;
    d.cloud = name;
    d.index = k;
    d.voxel = o.voxel;
    d.model = model;
    d.scene_sensor_known = true;  // the scan's VIEWPOINT (its frame's origin), moved with it
    // Cut by a random plane: keep the points below the keep-fraction quantile along a random direction.
    Eigen::Vector3f n = gaussian3f(r, 1);
    n.normalize();
    const float keep = r.uniform(o.overlap_min, o.overlap_max);
    std::vector<float> s;
    s.reserve(raw.size());
    for (const auto& p : raw) s.push_back(n.dot(p - c));
    std::vector<float> sorted = s;
    const std::size_t q = static_cast<std::size_t>(keep * static_cast<float>(raw.size() - 1));
    std::nth_element(sorted.begin(), sorted.begin() + q, sorted.end());
    const float cut = sorted[q];
    std::vector<Eigen::Vector3f> a;
    for (std::size_t i = 0; i < raw.size(); ++i)
      if (s[i] <= cut) a.push_back(raw[i]);
    d.overlap = static_cast<double>(a.size()) / static_cast<double>(raw.size());
    if (!move_scene(a, r, diameter, o.noise_voxels * o.voxel, &d, error)) return false;
    out->push_back(std::move(d));
  }
  return true;
}

bool make_bunny_pair(const PcdCloud& bun0, const PcdCloud& bun4, CloudDraw* out) {
  *out = CloudDraw();
  out->cloud = "bunny";
  out->voxel = 0.005f;  // ~ the views' point spacing (397 points over 15 cm)
  out->model = bun0.points;
  out->scene = bun4.points;
  out->has_truth = false;
  return true;
}

bool load_draws(const std::string& cloud, const DrawOptions& o, std::vector<CloudDraw>* out, std::string* error) {
  const std::string file = cloud == "office1" ? "office1.pcd.gz" : cloud + ".pcd";
  if (cloud != "office1" && cloud != "car6" && cloud != "milk") {
    *error = "unknown cloud '" + cloud + "' (office1, car6, milk)";
    return false;
  }
  PcdCloud c;
  if (!read_pcd(cloud_path(file), &c, error)) return false;
  return cloud == "office1" ? make_office_draws(c, o, out, error) : make_object_draws(c, cloud, o, out, error);
}

bool load_bunny(CloudDraw* out, std::string* error) {
  PcdCloud b0, b4;
  if (!read_pcd(cloud_path("bun0.pcd"), &b0, error) || !read_pcd(cloud_path("bun4.pcd"), &b4, error)) return false;
  return make_bunny_pair(b0, b4, out);
}

void pose_error(const CloudDraw& d, const Eigen::Matrix3f& r, const Eigen::Vector3f& t, double* trans_m,
                double* rot_deg) {
  // Translation error at the scene's centroid: the raw translation would mix in the rotation error
  // times the distance to the origin (car6 lies 70 m from its origin).
  Eigen::Vector3f c = Eigen::Vector3f::Zero();
  for (const auto& p : d.scene) c += p;
  if (!d.scene.empty()) c /= static_cast<float>(d.scene.size());
  *trans_m = ((r * c + t) - (d.truth_rotation * c + d.truth_translation)).norm();
  const Eigen::Matrix3f e = r * d.truth_rotation.transpose();
  const double cos_angle = std::clamp((static_cast<double>(e.trace()) - 1.0) / 2.0, -1.0, 1.0);
  *rot_deg = std::acos(cos_angle) * 180.0 / M_PI;
}

}  // namespace sim::pransam_eval
