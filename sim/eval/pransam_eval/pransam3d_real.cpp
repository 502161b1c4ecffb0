#include "sim/eval/pransam_eval/pransam3d_real.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "firmware/base/arena.h"
#include "firmware/base/worker_pool.h"
#include "firmware/pransam/matcher.h"
#include "sim/common/stopwatch.h"

namespace sim::pransam_eval {

namespace {
// Pransam3dConfig::smaller_as_scene: match the model onto the scene when it has fewer points.
bool swapped(const CloudDraw& d, const Pransam3dConfig& config) {
  return config.smaller_as_scene && d.model.size() < d.scene.size();
}

// Matcher sized once for the largest draw (cells of the model's box + the ε_s margin). Each cloud
// that may be B (both with retry_other_way) sizes the field; each that may be A the scene.
fw::pransam::MatcherOptions matcher_options_for(const std::vector<CloudDraw>& draws, const Pransam3dConfig& config) {
  std::size_t max_scene = 3, max_model = 3, max_cells = 0;
  std::uint32_t max_axis = 0;
  for (const CloudDraw& d : draws) {
    for (const bool swap : {false, true}) {
      if (swap != swapped(d, config) && !config.retry_other_way) continue;
      const std::vector<Eigen::Vector3f>& a = swap ? d.model : d.scene;
      const std::vector<Eigen::Vector3f>& b = swap ? d.scene : d.model;
      max_scene = std::max(max_scene, a.size());
      max_model = std::max(max_model, b.size());
      Eigen::Vector3f lo = b[0], hi = b[0];
      for (const auto& p : b) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
      const float res = config.field_voxels * d.voxel;
      const Eigen::Vector3f cells = (hi - lo) / res + Eigen::Vector3f::Constant(2.0f * (config.eps_soft_voxels / config.field_voxels) + 8.0f);
      max_cells = std::max(max_cells, static_cast<std::size_t>(cells.prod()) + 1024);
      max_axis = std::max(max_axis, static_cast<std::uint32_t>(cells.maxCoeff()) + 16);
    }
  }
  fw::pransam::MatcherOptions o;
  o.num_workers = config.workers;
  o.max_scene_points = static_cast<std::uint32_t>(max_scene);
  o.max_model_points = static_cast<std::uint32_t>(max_model);
  o.field.max_cells = max_cells;
  o.field.max_axis = max_axis;
  o.max_batch = 1024;
  o.collect_capacity = 64;
  return o;
}
}  // namespace

bool run_pransam3d(const std::vector<CloudDraw>& draws, const Pransam3dConfig& config, int pool_threads,
                   MethodRun* out, std::string* error, bool verbose) {
  out->method = "pransam";
  out->outcomes.clear();
  if (draws.empty()) return true;
  fw::pransam::MatcherOptions o = matcher_options_for(draws, config);
  const std::size_t max_scene = o.max_scene_points, max_model = o.max_model_points, max_cells = o.field.max_cells;
  const std::size_t bytes = 2 * fw::pransam::kNumSlots * 12 + max_cells * 5 + (max_scene + max_model) * 64 +
                            static_cast<std::size_t>(o.num_workers) * (std::size_t(1) << 20) + (std::size_t(64) << 20);
  fw::StartupArena arena;
  fw::Status s = arena.init_mapped(bytes, false, "pransam3d eval");
  std::unique_ptr<fw::WorkerPool> pool;
  if (s.is_ok() && pool_threads > 0) {
    pool = std::make_unique<fw::WorkerPool>();
    fw::WorkerPoolOptions po;
    po.num_workers = pool_threads;
    s = pool->start(po);
  }
  // The contact field's metric options depend on the voxel: one matcher per voxel size, set up at
  // the first draw of that size (the experiments use one size per cloud).
  auto matcher = std::make_unique<fw::pransam::Matcher<3>>();
  float matcher_voxel = -1.0f;
  for (const CloudDraw& d : draws) {
    if (!s.is_ok()) break;
    if (d.voxel != matcher_voxel) {
      if (matcher_voxel > 0.0f) {
        *error = "pransam3d: draws of different voxel sizes in one run";
        return false;
      }
      o.field.resolution = config.field_voxels * d.voxel;
      o.field.eps_hard = config.eps_hard_voxels * d.voxel;
      o.field.eps_soft = config.eps_soft_voxels * d.voxel;
      s = matcher->init(o, arena, pool.get());
      matcher_voxel = d.voxel;
      if (!s.is_ok()) break;
    }
    fw::pransam::MatchParams p;
    p.seed = config.seed * 1000003ull + d.index;
    p.max_iterations = config.max_iterations;
    p.omega_thres = config.omega_stop;
    p.max_extent = config.extent_voxels * d.voxel;
    p.refine_iterations = config.refine_iterations;
    p.refine_min_quality = config.refine_min_quality;
    p.refine_cutoff = 2.0f * d.voxel;
    // One direction: A matched onto B (swap: the model onto the scene; no free-space test, whose
    // sensor is the scene's).
    auto match_one_way = [&](bool swap, fw::pransam::MatchResult<3>* r) {
      p.scene_origin_is_sensor = false;
      if (config.free_space && d.scene_sensor_known && !swap) {
        p.scene_origin_is_sensor = true;
        for (int a = 0; a < 3; ++a) p.scene_sensor[a] = d.scene_sensor(a);
        p.free_space_min_quality = config.free_space_min_quality;
        p.free_space_margin = config.free_space_margin_voxels * d.voxel;
        p.free_space_block_radius = config.free_space_block_voxels * d.voxel;
        p.max_blocked_fraction = config.max_blocked;
      }
      const std::vector<Eigen::Vector3f>& a = swap ? d.model : d.scene;
      const std::vector<Eigen::Vector3f>& b = swap ? d.scene : d.model;
      fw::Status st = matcher->set_model(b.data(), b.size(), d.cloud.c_str());
      if (st.is_ok()) st = matcher->match(a.data(), a.size(), p, r);
      return st;
    };
    fw::pransam::MatchResult<3> r;
    const double t0 = now_ms();
    bool swap = swapped(d, config);
    s = match_one_way(swap, &r);
    bool reported = s.is_ok() && r.best_valid && r.best.quality >= config.omega_thres;
    bool retried = false;
    if (s.is_ok() && !reported && config.retry_other_way) {
      swap = !swap;
      retried = true;
      s = match_one_way(swap, &r);
      reported = s.is_ok() && r.best_valid && r.best.quality >= config.omega_thres;
    }
    double ms = now_ms() - t0;
    if (!s.is_ok()) break;
    Eigen::Matrix3f rot = r.best_valid ? r.best.rotation : Eigen::Matrix3f::Identity();
    Eigen::Vector3f tr = r.best_valid ? r.best.translation : Eigen::Vector3f::Zero();
    if (swap) {  // scene = R model + t, so the scene → model answer is (Rᵀ, −Rᵀ t)
      rot.transposeInPlace();
      tr = -(rot * tr);
    }
    PlaneModel pm;
    pm.build(&d.model, 3.0f * d.voxel);
    CloudOutcome oc = score_answer(d, pm, rot, tr, reported, ms);
    AmbiguityVerdict av;
    if (reported && config.ambiguity) {
      // The verdict is part of pRANSAM's answer here: its time (the rivals' refinements) is added.
      const double ta = now_ms();
      PoseCandidate best;
      best.rotation = oc.rotation;
      best.translation = oc.translation;
      av = check_ambiguity(d.scene, pm, d.voxel, best, {}, config.ambiguity_options);
      const double verdict_ms = now_ms() - ta;
      ms += verdict_ms;
      if (av.adoptions > 0) {
        // A distinct rival explained the data clearly better and was adopted: score that pose.
        const bool correct_before = oc.correct;
        oc = score_answer(d, pm, av.answer.rotation, av.answer.translation, reported, ms);
        if (verbose) std::printf("  (adopted %d× a better rival; correct before %d, after %d)\n", av.adoptions,
                                 correct_before ? 1 : 0, oc.correct ? 1 : 0);
      }
      oc.ms = ms;
      oc.verdict_ms = verdict_ms;
      if (av.ambiguous) {
        oc.ambiguous = true;
        oc.reported = false;
      }
    }
    if (verbose) {
      double k_truth = -1;
      if (d.has_truth) {
        const IcpResult t = refine_point_to_plane(d.scene, pm, d.voxel, d.truth_rotation, d.truth_translation);
        k_truth = t.inlier_fraction * static_cast<double>(d.scene.size());
      }
      std::printf("  %s #%zu scene %zu model %zu%s ov %.2f: %.1f ms it %llu coll %llu fs-rej %llu Ω %.3f %s  err %.4f m %.2f°  rms %.4f"
                  "  k %.0f ±%.0f rival %s %.0f z %.2f (%.1f° %.3f m) k_truth %.0f\n",
                  d.cloud.c_str(), d.index, d.scene.size(), d.model.size(), swap ? (retried ? " (A = model, retried)" : " (A = model)") : (retried ? " (retried)" : ""), d.overlap, ms,
                  static_cast<unsigned long long>(r.stats.iterations), static_cast<unsigned long long>(r.stats.collisions),
                  static_cast<unsigned long long>(r.stats.free_space_rejected),
                  r.best_valid ? r.best.quality : 0.0f,
                  oc.ambiguous ? (oc.correct ? "ambiguous(correct)" : "ambiguous(wrong)")
                  : reported ? (oc.correct || !d.has_truth ? "reported" : "REPORTED-WRONG") : (oc.correct ? "missed(correct)" : "nothing"),
                  oc.trans_err, oc.rot_err_deg, oc.inlier_rms, av.best_inliers, av.margin, rival_kind_name(av.rival),
                  av.rival_inliers, av.rival_z, av.rival_rot_deg, av.rival_trans_m, k_truth);
    }
    out->outcomes.push_back(oc);
  }
  if (!s.is_ok()) {
    *error = s.message();
    return false;
  }
  return true;
}

}  // namespace sim::pransam_eval
