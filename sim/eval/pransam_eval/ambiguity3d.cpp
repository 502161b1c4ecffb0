#include "sim/eval/pransam_eval/ambiguity3d.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <unordered_map>

namespace sim::pransam_eval {

const char* rival_kind_name(RivalKind k) {
  switch (k) {
    case RivalKind::kKept: return "kept";
    case RivalKind::kFlip: return "flip";
    case RivalKind::kSlide: return "slide";
    default: return "none";
  }
}

int count_inliers(const std::vector<Eigen::Vector3f>& scene, const PlaneModel& model, const Eigen::Matrix3f& r,
                  const Eigen::Vector3f& t, float max_dist) {
  int k = 0;
  for (const auto& a : scene) k += model.nearest(r * a + t, max_dist) >= 0;
  return k;
}

namespace {

// Paired comparison of two poses on the same scene points (McNemar per point or over cells, see the header):
// z > 0 when `a` explains more of the scene than `b`.
double paired_z(const std::vector<Eigen::Vector3f>& scene, const PlaneModel& model, const PoseCandidate& a,
                const PoseCandidate& b, float voxel, double cell) {
  std::unordered_map<long long, int> d;
  double only_a = 0.0, only_b = 0.0;
  for (const auto& p : scene) {
    const bool ia = model.nearest(a.rotation * p + a.translation, voxel) >= 0;
    const bool ib = model.nearest(b.rotation * p + b.translation, voxel) >= 0;
    if (ia == ib) continue;
    if (!(cell > 0.0)) {  // every point its own unit: McNemar's (b − c) / √(b + c)
      (ia ? only_a : only_b) += 1.0;
      continue;
    }
    const long long x = static_cast<long long>(std::floor(p.x() / cell)) & 0xFFFFF;
    const long long y = static_cast<long long>(std::floor(p.y() / cell)) & 0xFFFFF;
    const long long z = static_cast<long long>(std::floor(p.z() / cell)) & 0xFFFFF;
    d[(x << 40) | (y << 20) | z] += ia ? 1 : -1;
  }
  double sum = only_a - only_b, sum2 = only_a + only_b;
  for (const auto& [key, v] : d) {
    sum += v;
    sum2 += static_cast<double>(v) * v;
  }
  return sum2 > 0.0 ? sum / std::sqrt(sum2) : 0.0;  // identical inlier sets: nothing tells them apart
}

AmbiguityVerdict judge(const std::vector<Eigen::Vector3f>& scene, const PlaneModel& model, float voxel,
                       const PoseCandidate& best, const std::vector<PoseCandidate>& kept,
                       const AmbiguityOptions& options) {
  AmbiguityVerdict v;
  v.answer = best;
  if (scene.empty()) return v;
  v.best_inliers = count_inliers(scene, model, best.rotation, best.translation, voxel);
  v.margin = options.z * std::sqrt(v.best_inliers);
  // Scene centroid (scene frame) and, moved by the best pose, its shape in the model frame.
  Eigen::Vector3d cs = Eigen::Vector3d::Zero();
  for (const auto& a : scene) cs += a.cast<double>();
  cs /= static_cast<double>(scene.size());
  const Eigen::Vector3f c_scene = cs.cast<float>();
  const Eigen::Vector3f c = best.rotation * c_scene + best.translation;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& a : scene) {
    const Eigen::Vector3d q = (best.rotation * (a - c_scene)).cast<double>();
    cov += q * q.transpose();
  }
  cov /= static_cast<double>(scene.size());
  const double radius = std::max(std::sqrt(cov.trace()), static_cast<double>(voxel));

  std::vector<std::pair<RivalKind, PoseCandidate>> starts;
  for (const auto& k : kept) starts.emplace_back(RivalKind::kKept, k);
  // Moves about the best pose's scene centroid: R' = ΔR·R, t' = ΔR·(t − c) + c + Δt.
  const auto moved = [&](const Eigen::Matrix3f& dr, const Eigen::Vector3f& dt) {
    PoseCandidate p;
    p.rotation = dr * best.rotation;
    p.translation = dr * (best.translation - c) + c + dt;
    return p;
  };
  if (options.flips) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
    for (int a = 0; a < 3; ++a) {
      const Eigen::Vector3f axis = es.eigenvectors().col(a).cast<float>().normalized();
      starts.emplace_back(RivalKind::kFlip, moved(Eigen::AngleAxisf(static_cast<float>(M_PI), axis).toRotationMatrix(),
                                                  Eigen::Vector3f::Zero()));
    }
    // The model's own near-symmetries: 180° about its principal axes through its centroid, applied
    // after the answer (a part of a symmetric object placed on the wrong end turns into the right
    // one; the scene-centred turns above keep the part where it is).
    const std::vector<Eigen::Vector3f>& m = model.points();
    if (m.size() >= 3) {
      Eigen::Vector3d cm = Eigen::Vector3d::Zero();
      for (const auto& q : m) cm += q.cast<double>();
      cm /= static_cast<double>(m.size());
      Eigen::Matrix3d mcov = Eigen::Matrix3d::Zero();
      for (const auto& q : m) mcov += (q.cast<double>() - cm) * (q.cast<double>() - cm).transpose();
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> em(mcov / static_cast<double>(m.size()));
      const Eigen::Vector3f cmf = cm.cast<float>();
      for (int a = 0; a < 3; ++a) {
        const Eigen::Matrix3f s =
            Eigen::AngleAxisf(static_cast<float>(M_PI), em.eigenvectors().col(a).cast<float>().normalized()).toRotationMatrix();
        PoseCandidate p;
        p.rotation = s * best.rotation;
        p.translation = s * (best.translation - cmf) + cmf;
        starts.emplace_back(RivalKind::kFlip, p);
      }
    }
  }
  if (options.slides) {
    // Point-to-plane information of the contact at the best pose, parameters (δt, radius·δω).
    Eigen::Matrix<double, 6, 6> h = Eigen::Matrix<double, 6, 6>::Zero();
    int used = 0;
    for (const auto& a : scene) {
      const Eigen::Vector3f p = best.rotation * a + best.translation;
      const int j = model.nearest(p, voxel);
      if (j < 0) continue;
      const Eigen::Vector3d n = model.normal(j).cast<double>();
      Eigen::Matrix<double, 6, 1> jac;
      jac << n, (p - c).cast<double>().cross(n) / radius;
      h += jac * jac.transpose();
      ++used;
    }
    if (used >= 12) {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(h);
      const Eigen::Matrix<double, 6, 1> w = es.eigenvectors().col(0);  // weakest direction
      for (float s : options.slide_voxels) {
        for (float sign : {1.0f, -1.0f}) {
          const double step = static_cast<double>(sign * s * voxel);
          const Eigen::Vector3d dt = step * w.head<3>();
          const Eigen::Vector3d dw = step * w.tail<3>() / radius;
          Eigen::Matrix3f dr = Eigen::Matrix3f::Identity();
          if (dw.norm() > 1e-12) dr = Eigen::AngleAxisf(static_cast<float>(dw.norm()), dw.normalized().cast<float>()).toRotationMatrix();
          starts.emplace_back(RivalKind::kSlide, moved(dr, dt.cast<float>()));
        }
      }
    }
  }
  std::vector<Eigen::Vector3f> subset;
  const std::vector<Eigen::Vector3f>* refine_on = &scene;
  if (options.refine_points > 0 && scene.size() > options.refine_points) {
    const std::size_t stride = (scene.size() + options.refine_points - 1) / options.refine_points;
    for (std::size_t i = 0; i < scene.size(); i += stride) subset.push_back(scene[i]);
    refine_on = &subset;
  }
  for (const auto& [kind, start] : starts) {
    const IcpResult r = refine_point_to_plane(*refine_on, model, voxel, start.rotation, start.translation);
    ++v.refinements;
    const double rot_deg =
        Eigen::AngleAxisf(r.rotation * best.rotation.transpose()).angle() * 180.0 / M_PI;
    const double trans = ((r.rotation * c_scene + r.translation) - c).norm();
    if (!(rot_deg > options.rot_sep_deg || trans > options.trans_sep_voxels * voxel)) continue;  // same pose
    const double k = count_inliers(scene, model, r.rotation, r.translation, voxel);
    PoseCandidate rp;
    rp.rotation = r.rotation;
    rp.translation = r.translation;
    // The most threatening rival: the lowest paired z (paired) or the most inliers (unpaired).
    const double z = options.paired ? paired_z(scene, model, best, rp, voxel, options.cell_voxels * voxel) : 0.0;
    if (options.paired ? (v.rival_inliers < 0 || z < v.rival_z) : k > v.rival_inliers) {
      v.rival_z = z;
      v.rival_inliers = k;
      v.rival = kind;
      v.rival_rot_deg = rot_deg;
      v.rival_trans_m = trans;
      v.rival_pose.rotation = r.rotation;
      v.rival_pose.translation = r.translation;
    }
  }
  v.ambiguous = v.rival_inliers >= 0 &&
                (options.paired ? v.rival_z < options.z : v.rival_inliers >= v.best_inliers - v.margin);
  return v;
}

}  // namespace

AmbiguityVerdict check_ambiguity(const std::vector<Eigen::Vector3f>& scene, const PlaneModel& model, float voxel,
                                 const PoseCandidate& best, const std::vector<PoseCandidate>& kept,
                                 const AmbiguityOptions& options) {
  AmbiguityVerdict v = judge(scene, model, voxel, best, kept, options);
  int adoptions = 0, refinements = v.refinements;
  const auto clearly_better = [&](const AmbiguityVerdict& x) {
    if (x.rival_inliers < 0) return false;
    return options.paired ? x.rival_z < -options.z : x.rival_inliers > x.best_inliers + x.margin;
  };
  while (adoptions < options.max_adoptions && clearly_better(v)) {
    ++adoptions;
    v = judge(scene, model, voxel, v.rival_pose, {}, options);
    refinements += v.refinements;
  }
  v.adoptions = adoptions;
  v.refinements = refinements;
  // Still a clearly better rival after the last adoption: the answer is not settled.
  if (clearly_better(v)) v.ambiguous = true;
  return v;
}

}  // namespace sim::pransam_eval
