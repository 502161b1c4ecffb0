#include "firmware/antslam/antslam.h"

#include <Eigen/LU>
#include <cmath>

namespace fw::antslam {

namespace {
constexpr std::uint32_t kMaxCandidates = 16;
constexpr std::uint32_t kNoHops = 0xffffffffu;
constexpr std::uint32_t kNoEdge = 0xffffffffu;

// Largest eigenvalue of the 2×2 position covariance (closed form; no Eigen solver, no heap), as a
// standard deviation.
double position_sigma(const Mat3& cov) {
  const double ca = cov(0, 0), cb = cov(0, 1), cc = cov(1, 1);
  const double lmax = 0.5 * (ca + cc) + std::sqrt(0.25 * (ca - cc) * (ca - cc) + cb * cb);
  return std::sqrt(lmax > 1e-12 ? lmax : 1e-12);
}

// Radius of a fragment's keyframes around its frame.
double frame_radius(const Se2d* k, std::uint32_t n) {
  double r = 0.0;
  for (std::uint32_t i = 0; i < n; ++i) r = std::fmax(r, std::hypot(k[i].x, k[i].y));
  return r;
}

// Distance of the nearest pair of poses: ka mapped by x against kc.
double nearest_pose_distance(const Se2d& x, const Se2d* ka, std::uint32_t na, const Se2d* kc, std::uint32_t nc) {
  double dmin = 1e300;
  for (std::uint32_t i = 0; i < na; ++i) {
    const Se2d pa = x.compose(ka[i]);
    for (std::uint32_t j = 0; j < nc; ++j) {
      const double d = std::hypot(pa.x - kc[j].x, pa.y - kc[j].y);
      if (d < dmin) dmin = d;
    }
  }
  return dmin;
}

// Insert c at distance m into the sorted short list of at most `cap` (ties: older fragment first).
void insert_candidate(std::uint32_t c, double m, std::uint32_t cap, std::uint32_t* cand, double* cand_m,
                      std::uint32_t* num_cand) {
  std::uint32_t pos = *num_cand;
  while (pos > 0 && cand_m[pos - 1] > m) --pos;
  if (pos >= cap) return;
  const std::uint32_t last = *num_cand < cap ? *num_cand : cap - 1;
  for (std::uint32_t k = last; k > pos; --k) {
    cand[k] = cand[k - 1];
    cand_m[k] = cand_m[k - 1];
  }
  cand[pos] = c;
  cand_m[pos] = m;
  if (*num_cand < cap) ++*num_cand;
}
}  // namespace

Status AntSlamOptions::validate() const {
  if (max_scans == 0 || max_fragments < 2 || max_points_per_fragment < 16 || max_keyframes_per_fragment == 0 ||
      max_loop_steps == 0) {
    return Status::error(Errc::kInvalidArgument, "antslam: capacities must be positive (fragments >= 2, points >= 16)");
  }
  if (samples_per_edge == 0 || samples_per_edge > 4096) {
    return Status::error(Errc::kInvalidArgument, "antslam: samples_per_edge %u not in 1..4096", samples_per_edge);
  }
  if (!(fragment_length_m > 0.0)) return Status::error(Errc::kInvalidArgument, "antslam: fragment_length_m must be > 0");
  if (!(var_xy_per_m >= 0 && var_theta_per_m >= 0 && var_theta_per_rad >= 0 && var_floor > 0)) {
    return Status::error(Errc::kInvalidArgument, "antslam: motion noise must be >= 0 (floor > 0)");
  }
  if (beam_stride == 0) return Status::error(Errc::kInvalidArgument, "antslam: beam_stride must be > 0");
  if (max_candidates > kMaxCandidates) {
    return Status::error(Errc::kInvalidArgument, "antslam: max_candidates %u > %u", max_candidates, kMaxCandidates);
  }
  if (!(closure_sigma_xy > 0 && closure_sigma_theta > 0)) {
    return Status::error(Errc::kInvalidArgument, "antslam: closure sigmas must be > 0");
  }
  if (!(candidate_mahalanobis > 0 && closure_gate_chi2 > 0 && overlap_radius_m >= 0 && frozen_cov_scale > 0)) {
    return Status::error(Errc::kInvalidArgument, "antslam: loop-closing gates must be > 0");
  }
  if (traversal && (max_borders_per_fragment < 2 || max_hull_points < 3 || !(border.alpha >= 0.0 && border.alpha <= 1.0) ||
                    !(border.max_angle_off_rad > 0.0))) {
    return Status::error(Errc::kInvalidArgument,
                         "antslam: traversal needs max_borders_per_fragment >= 2, max_hull_points >= 3, border "
                         "alpha in [0, 1] and max_angle_off_rad > 0");
  }
  FW_RETURN_IF_ERROR(aco.validate());
  FW_RETURN_IF_ERROR(edge_fit.validate());
  FW_RETURN_IF_ERROR(graph.validate());
  if ((pair_closures && pair_isolation) || gate_isolation) {
    FW_RETURN_IF_ERROR(isolation.validate());
    if (isolation_max_points < 16 || isolation_field_cells < 1024) {
      return Status::error(Errc::kInvalidArgument, "antslam: isolation_max_points >= 16 and isolation_field_cells >= 1024");
    }
  }
  return lm.validate();
}

AntSlamOptions default_antslam_options() {
  AntSlamOptions o;
  o.matcher.num_workers = 2;
  o.matcher.field.resolution = 0.05f;
  o.match.max_iterations = 40000;
  o.match.omega_thres = 0.8f;
  o.match.refine_iterations = 6;
  o.match.refine_min_quality = 0.4f;
  return o;
}

namespace {
pransam::MatcherOptions sized_matcher(const AntSlamOptions& o) {
  pransam::MatcherOptions m = o.matcher;
  m.max_scene_points = o.max_points_per_fragment;
  m.max_model_points = o.max_points_per_fragment;
  return m;
}
std::uint32_t max_edges(const AntSlamOptions& o) { return o.max_fragments + o.max_closures; }
using FragmentStateStorage = AntSlam::FragmentState;

bool uses_isolation(const AntSlamOptions& o) { return (o.pair_closures && o.pair_isolation) || o.gate_isolation; }

// The isolation model's field: the matcher's contact parameters, with distances (fit_on_field).
pransam::ContactFieldOptions isolation_field_options(const AntSlamOptions& o) {
  pransam::ContactFieldOptions f = o.matcher.field;
  f.keep_distance = true;
  f.max_cells = o.isolation_field_cells;
  return f;
}
}  // namespace

std::size_t AntSlam::required_arena_bytes(const AntSlamOptions& o) {
  const std::size_t f = o.max_fragments, e = max_edges(o), s = o.max_scans;
  std::size_t b = 0;
  b += s * (sizeof(std::uint32_t) + sizeof(Se2d) + sizeof(float)) + f * sizeof(double);
  b += f * (2 * sizeof(Se2d) + 3 * sizeof(std::uint32_t) + sizeof(std::uint32_t) + sizeof(std::int32_t) +
            sizeof(std::uint32_t) + sizeof(std::uint32_t));
  b += f * o.max_points_per_fragment * sizeof(Point2f) + f * o.max_keyframes_per_fragment * sizeof(Se2d);
  b += e * (sizeof(SampledEdge) + o.samples_per_edge * (sizeof(Se2d) + sizeof(double)));
  b += o.max_closures * sizeof(ClosureRecord);
  b += f * (sizeof(std::uint32_t) + sizeof(FragmentStateStorage) + 2 * sizeof(std::uint32_t) +
            o.max_borders_per_fragment * sizeof(Border) + o.max_hull_points * sizeof(Point2f));
  b += o.max_points_per_fragment * sizeof(Point2f);
  b += o.max_loop_steps * (sizeof(LoopStep) + sizeof(Se2d));
  b += AntColony::required_arena_bytes(o.aco, o.max_loop_steps, o.samples_per_edge);
  b += LoopLm::required_arena_bytes(o.max_loop_steps);
  b += GraphRefine::required_arena_bytes(o.max_fragments, max_edges(o));
  if (uses_isolation(o)) {
    b += o.isolation_max_points * sizeof(Point2f) + 2 * o.max_points_per_fragment * (sizeof(Point2f) + sizeof(CellSample));
    b += pransam::ContactField<2>::arena_bytes(isolation_field_options(o)) + 64 * 4;
  }
  // pRANSAM: measured by the caller's arena (init reports capacity errors); a generous bound.
  b += 64u << 20;
  return b + 64 * 40;
}

Status AntSlam::init(const AntSlamOptions& options, StartupArena& arena, WorkerPool* pool, const hal::Clock* clock) {
  FW_RETURN_IF_ERROR(options.validate());
  options_ = options;
  pool_ = pool;
  clock_ = clock;
  const std::uint32_t f = options.max_fragments;
  max_edges_ = max_edges(options);
#define FW_ANTSLAM_ALLOC(ptr, T, n, what)              \
  do {                                                 \
    auto r_ = arena.allocate_array<T>((n), (what));    \
    if (!r_) return r_.status();                       \
    ptr = *r_;                                         \
  } while (0)
  FW_ANTSLAM_ALLOC(scan_fragment_, std::uint32_t, options.max_scans, "antslam scan fragment");
  FW_ANTSLAM_ALLOC(scan_rel_, Se2d, options.max_scans, "antslam scan poses");
  FW_ANTSLAM_ALLOC(scan_along_, float, options.max_scans, "antslam scan distances");
  FW_ANTSLAM_ALLOC(fragment_length_, double, f, "antslam fragment lengths");
  FW_ANTSLAM_ALLOC(frontend_frame_, Se2d, f, "antslam front-end frames");
  FW_ANTSLAM_ALLOC(world_, Se2d, f, "antslam fragment frames");
  FW_ANTSLAM_ALLOC(fragment_first_scan_, std::uint32_t, f, "antslam first scans");
  FW_ANTSLAM_ALLOC(adjacent_edge_, std::uint32_t, f, "antslam adjacent edges");
  FW_ANTSLAM_ALLOC(num_points_, std::uint32_t, f, "antslam point counts");
  FW_ANTSLAM_ALLOC(entry_edge_, std::uint32_t, f, "antslam entry edges");
  FW_ANTSLAM_ALLOC(state_, FragmentState, f, "antslam fragment states");
  FW_ANTSLAM_ALLOC(num_borders_, std::uint32_t, f, "antslam border counts");
  FW_ANTSLAM_ALLOC(hull_size_, std::uint32_t, f, "antslam hull sizes");
  FW_ANTSLAM_ALLOC(borders_, Border, static_cast<std::size_t>(f) * options.max_borders_per_fragment, "antslam borders");
  FW_ANTSLAM_ALLOC(hull_, Point2f, static_cast<std::size_t>(f) * options.max_hull_points, "antslam hulls");
  FW_ANTSLAM_ALLOC(hull_scratch_, Point2f, options.max_points_per_fragment, "antslam hull scratch");
  FW_ANTSLAM_ALLOC(num_keyframes_, std::uint32_t, f, "antslam keyframe counts");
  FW_ANTSLAM_ALLOC(points_, Point2f, static_cast<std::size_t>(f) * options.max_points_per_fragment, "antslam points");
  FW_ANTSLAM_ALLOC(keyframes_, Se2d, static_cast<std::size_t>(f) * options.max_keyframes_per_fragment,
                   "antslam keyframes");
  FW_ANTSLAM_ALLOC(edges_, SampledEdge, max_edges_, "antslam edges");
  FW_ANTSLAM_ALLOC(edge_options_, Se2d, static_cast<std::size_t>(max_edges_) * options.samples_per_edge,
                   "antslam edge options");
  FW_ANTSLAM_ALLOC(edge_option_cost_, double, static_cast<std::size_t>(max_edges_) * options.samples_per_edge,
                   "antslam option costs");
  FW_ANTSLAM_ALLOC(closures_, ClosureRecord, options.max_closures, "antslam closures");
  FW_ANTSLAM_ALLOC(parent_edge_, std::int32_t, f, "antslam bfs parents");
  FW_ANTSLAM_ALLOC(hops_, std::uint32_t, f, "antslam bfs hops");
  FW_ANTSLAM_ALLOC(queue_, std::uint32_t, f, "antslam bfs queue");
  FW_ANTSLAM_ALLOC(steps_, LoopStep, options.max_loop_steps, "antslam loop steps");
  FW_ANTSLAM_ALLOC(values_, Se2d, options.max_loop_steps, "antslam loop values");
  FW_RETURN_IF_ERROR(aco_.init(options.aco, options.max_loop_steps, options.samples_per_edge, arena, pool));
  FW_RETURN_IF_ERROR(lm_.init(options.lm, options.max_loop_steps, arena));
  FW_RETURN_IF_ERROR(graph_.init(options.graph, options.max_fragments, max_edges_, arena));
  if (uses_isolation(options)) {
    FW_ANTSLAM_ALLOC(iso_model_, Point2f, options.isolation_max_points, "antslam isolation model");
    FW_ANTSLAM_ALLOC(iso_scene_, Point2f, 2 * static_cast<std::size_t>(options.max_points_per_fragment),
                     "antslam isolation scene");
    FW_ANTSLAM_ALLOC(iso_cells_, CellSample, 2 * static_cast<std::size_t>(options.max_points_per_fragment),
                     "antslam isolation cells");
    FW_RETURN_IF_ERROR(iso_field_.init(isolation_field_options(options), arena));
  }
  FW_RETURN_IF_ERROR(matcher_.init(sized_matcher(options), arena, pool));
#undef FW_ANTSLAM_ALLOC
  edge_rng_.reseed(options.seed, 0xED6E);
  num_scans_ = num_fragments_ = num_edges_ = num_closures_ = 0;
  active_ = pending_parent_ = 0;
  pending_.clear();
  traversing_ = false;
  model_of_ = kNoEdge;
  stats_ = AntSlamStats{};
  initialized_ = true;
  return Status::ok();
}

Status AntSlam::add_edge(std::uint32_t from, std::uint32_t to, const Se2d& mean, const Mat3& cov,
                         const Mat3& predict_cov, std::uint32_t* index) {
  if (num_edges_ >= max_edges_) {
    return Status::error(Errc::kCapacityExceeded, "antslam: more than %u edges", max_edges_);
  }
  const std::size_t off = static_cast<std::size_t>(num_edges_) * options_.samples_per_edge;
  FW_RETURN_IF_ERROR(init_sampled_edge(from, to, mean, cov, edge_options_ + off, edge_option_cost_ + off,
                                       options_.samples_per_edge, edge_rng_, &edges_[num_edges_]));
  edges_[num_edges_].predict_cov = predict_cov;
  *index = num_edges_++;
  return Status::ok();
}

bool AntSlam::sensor_model_cov(const Point2f* scene, std::size_t n, const Se2d& pose, Mat3* cov) {
  EdgeFit fit;
  if (!fit_edge(matcher_.field(), scene, n, pose, options_.edge_fit, &fit)) return false;
  *cov = fit.cov;
  cov->diagonal().array() += options_.var_floor;
  return true;
}

Status AntSlam::start_fragment(const Se2d& frontend_pose, const Point2f* points, std::size_t count) {
  if (num_fragments_ >= options_.max_fragments) {
    return Status::error(Errc::kCapacityExceeded, "antslam: more than %u fragments (max_fragments)",
                         options_.max_fragments);
  }
  const std::uint32_t f = num_fragments_;
  frontend_frame_[f] = frontend_pose;
  fragment_first_scan_[f] = num_scans_;
  num_points_[f] = 0;
  num_keyframes_[f] = 0;
  num_borders_[f] = 0;
  hull_size_[f] = 0;
  state_[f] = FragmentState::kExplore;
  adjacent_edge_[f] = kNoEdge;
  entry_edge_[f] = kNoEdge;
  if (f == 0) {
    world_[0] = frontend_pose;
  } else {
    // Entry edge T(F_p → F_f) ~ N(μ, Σ) from the fragment p the robot was in (F_f−1 unless it was
    // traversing): μ the tracked pose, Σ by Eq. 3.9 (or Eq. 3.4), sampled (Eq. 3.10).
    const std::uint32_t p = pending_parent_;
    Mat3 motion = rel_cov_;
    motion.diagonal().array() += options_.var_floor;
    motion = 0.5 * (motion + motion.transpose());
    // Eq. 3.9: the scan that opens F_f placed on F_f−1's points around the front end's pose.
    Mat3 cov = motion;
    if (options_.edge_model == EdgeModel::kSensorModel) {
      const bool fitted = points != nullptr && num_points_[p] >= options_.min_fragment_points &&
                          use_fragment_model(p) && sensor_model_cov(points, count, rel_, &cov);
      if (fitted) ++stats_.sensor_fits; else ++stats_.motion_fallbacks;
    }
    std::uint32_t e = 0;
    FW_RETURN_IF_ERROR(add_edge(p, f, rel_, cov, motion, &e));
    entry_edge_[f] = e;
    if (!traversing_) {  // p's exploration ends here: the edge its scans' correction is spread along
      fragment_length_[p] = travelled_;
      adjacent_edge_[p] = e;
    }
    world_[f] = world_[p].compose(edges_[e].value);
  }
  ++num_fragments_;
  active_ = f;
  traversing_ = false;
  rel_ = Se2d();
  rel_cov_ = Mat3::Zero();
  travelled_ = 0.0;
  have_keyframe_ = false;
  return Status::ok();
}

Status AntSlam::add_scan(const Se2d& pose, const Point2f* points, std::size_t count) {
  if (!initialized_) return Status::error(Errc::kNotInitialized, "antslam: init() not called");
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
    return Status::error(Errc::kInvalidArgument, "antslam: scan %u: non-finite front-end pose", num_scans_);
  }
  if (num_scans_ >= options_.max_scans) {
    return Status::error(Errc::kCapacityExceeded, "antslam: more than %u scans (max_scans)", options_.max_scans);
  }
  bool closed_fragment = false;
  if (num_fragments_ == 0) {
    FW_RETURN_IF_ERROR(start_fragment(pose, points, count));
  } else {
    const Se2d u = last_frontend_.between(pose);
    // Eq. 3.4: x_t = x_{t−1} ⊕ u_t, Σ_t = J_x Σ_{t−1} J_xᵀ + J_u G J_uᵀ.
    const double d = std::hypot(u.x, u.y);
    Mat3 g = Mat3::Zero();
    g(0, 0) = g(1, 1) = options_.var_xy_per_m * d;
    g(2, 2) = options_.var_theta_per_m * d + options_.var_theta_per_rad * std::fabs(u.theta);
    const Mat3 jx = rel_.jacobian_compose_first(u);
    const Mat3 ju = rel_.jacobian_compose_second();
    rel_cov_ = jx * rel_cov_ * jx.transpose() + ju * g * ju.transpose();
    rel_ = rel_.compose(u);
    if (traversing_) {
      FW_RETURN_IF_ERROR(traverse(pose, points, count));
    } else {
      travelled_ += d;
      if (travelled_ >= options_.fragment_length_m) {
        if (options_.traversal) {
          FW_RETURN_IF_ERROR(end_exploration(pose, points, count));
        } else {
          pending_parent_ = active_;
          FW_RETURN_IF_ERROR(start_fragment(pose, points, count));
          closed_fragment = true;
        }
      }
    }
  }
  last_frontend_ = pose;
  const std::uint32_t f = active_;
  scan_fragment_[num_scans_] = f;
  scan_rel_[num_scans_] = rel_;
  // A traversed fragment's outgoing correction is not spread over a revisit (scan_pose).
  scan_along_[num_scans_] = traversing_ ? -1.0f : static_cast<float>(travelled_);
  ++num_scans_;
  if (traversing_) {  // TRAVERSAL: tracked, not mapped
    ++stats_.traversal_scans;
    return Status::ok();
  }
  fragment_length_[f] = travelled_;
  // Keyframe: keep this scan's points (fragment frame) for loop closing.
  const bool key = keyframe_due();
  if (key && points != nullptr && count > 0) {
    have_keyframe_ = true;
    last_keyframe_ = rel_;
    if (num_keyframes_[f] < options_.max_keyframes_per_fragment) {
      keyframes_[static_cast<std::size_t>(f) * options_.max_keyframes_per_fragment + num_keyframes_[f]++] = rel_;
    }
    Point2f* dst = points_ + static_cast<std::size_t>(f) * options_.max_points_per_fragment;
    const float c = static_cast<float>(std::cos(rel_.theta)), s = static_cast<float>(std::sin(rel_.theta));
    const float tx = static_cast<float>(rel_.x), ty = static_cast<float>(rel_.y);
    for (std::size_t k = 0; k < count; k += options_.beam_stride) {
      if (num_points_[f] >= options_.max_points_per_fragment) {
        ++stats_.dropped_points;
        continue;
      }
      const Point2f& p = points[k];
      if (!std::isfinite(p(0)) || !std::isfinite(p(1))) continue;
      dst[num_points_[f]++] = Point2f(tx + c * p(0) - s * p(1), ty + s * p(0) + c * p(1));
    }
  }
  if (closed_fragment && num_fragments_ >= 2) return close_loop(num_fragments_ - 2);
  return Status::ok();
}

Status AntSlam::finish() {
  if (!initialized_) return Status::error(Errc::kNotInitialized, "antslam: init() not called");
  if (num_fragments_ == 0) return Status::ok();
  if (!traversing_) FW_RETURN_IF_ERROR(close_loop(active_));  // a traversed fragment's loop was tried when it ended
  return options_.final_refinement ? refine_whole_graph() : Status::ok();
}

Status AntSlam::refine_whole_graph() {
  if (!initialized_) return Status::error(Errc::kNotInitialized, "antslam: init() not called");
  const std::uint64_t t0 = now();
  GraphRefineReport rep;
  FW_RETURN_IF_ERROR(graph_.refine(edges_, num_edges_, world_, num_fragments_, &rep));
  // Every edge takes the transform between its refined frames; the entry edges rebuild world_.
  for (std::uint32_t k = 0; k < num_edges_; ++k) {
    edges_[k].value = world_[edges_[k].from].between(world_[edges_[k].to]);
  }
  recompute_world();
  stats_.graph_initial_cost = rep.initial_cost;
  stats_.graph_final_cost = rep.final_cost;
  stats_.graph_iterations = rep.iterations;
  stats_.graph_cg_iterations = rep.cg_iterations;
  stats_.graph_ns = now() - t0;
  return Status::ok();
}

bool AntSlam::keyframe_due() const {
  return !have_keyframe_ ||
         std::hypot(rel_.x - last_keyframe_.x, rel_.y - last_keyframe_.y) >= options_.keyframe_step_m ||
         std::fabs(wrap_angle(rel_.theta - last_keyframe_.theta)) >= options_.keyframe_turn_rad;
}

Mat3 AntSlam::closure_prior() const {
  Mat3 c = Mat3::Zero();
  c.diagonal() << options_.closure_sigma_xy * options_.closure_sigma_xy,
      options_.closure_sigma_xy * options_.closure_sigma_xy, options_.closure_sigma_theta * options_.closure_sigma_theta;
  return c;
}

bool AntSlam::use_fragment_model(std::uint32_t f) {
  model_of_ = kNoEdge;
  if (!matcher_.set_model(points_ + static_cast<std::size_t>(f) * options_.max_points_per_fragment, num_points_[f],
                          "antslam fragment")
           .is_ok()) {
    return false;
  }
  model_of_ = f;
  return true;
}

bool AntSlam::pose_in_fragment(std::uint32_t c, Se2d* pose, Mat3* cov) {
  if (c >= num_fragments_) return false;
  Se2d x;
  Mat3 cx = Mat3::Zero();
  if (c != active_) {
    shortest_paths(active_);
    if (hops_[c] == kNoHops) return false;
    const std::uint32_t n = build_path(c, active_);
    if (n == 0) return false;
    compound_path(n, &x, &cx);
  }
  // x ⊕ rel: Σ = J1 Σ_x J1ᵀ + J2 Σ_rel J2ᵀ (Eq. 3.4's propagation, one step).
  const Mat3 j1 = x.jacobian_compose_first(rel_), j2 = x.jacobian_compose_second();
  *cov = j1 * cx * j1.transpose() + j2 * rel_cov_ * j2.transpose();
  *pose = x.compose(rel_);
  return true;
}

bool AntSlam::inside(std::uint32_t f, const Se2d& at) const {
  const std::size_t bo = static_cast<std::size_t>(f) * options_.max_borders_per_fragment;
  const std::size_t ho = static_cast<std::size_t>(f) * options_.max_hull_points;
  return state_[f] == FragmentState::kTraversal &&
         inside_fragment(borders_ + bo, num_borders_[f], hull_ + ho, hull_size_[f], at.x, at.y);
}

void AntSlam::add_border(std::uint32_t f, const Border& b) {
  if (num_borders_[f] >= options_.max_borders_per_fragment) {
    ++stats_.dropped_borders;
    return;
  }
  borders_[static_cast<std::size_t>(f) * options_.max_borders_per_fragment + num_borders_[f]++] = b;
}

bool AntSlam::cut_border(std::uint32_t f, const Se2d& at, Border* out) {
  if (!select_border(points_ + static_cast<std::size_t>(f) * options_.max_points_per_fragment, num_points_[f], at,
                     options_.border, out)) {
    ++stats_.no_border;
    return false;
  }
  add_border(f, *out);
  ++stats_.borders;
  return true;
}

void AntSlam::enter(std::uint32_t g, const Se2d& g_from_active, const Mat3& extra_cov) {
  const Mat3 j = g_from_active.jacobian_compose_second();
  rel_cov_ = j * rel_cov_ * j.transpose() + extra_cov;
  rel_ = g_from_active.compose(rel_);
  active_ = g;
  traversing_ = true;
  have_keyframe_ = false;
  ++stats_.traversals;
}

Status AntSlam::end_exploration(const Se2d& frontend_pose, const Point2f* points, std::size_t count) {
  const std::uint32_t a = active_;
  Border b;
  const bool have_border = cut_border(a, rel_, &b);
  state_[a] = FragmentState::kTraversal;  // never back to EXPLORE
  hull_size_[a] = static_cast<std::uint32_t>(
      convex_hull(points_ + static_cast<std::size_t>(a) * options_.max_points_per_fragment, num_points_[a], hull_scratch_,
                  hull_ + static_cast<std::size_t>(a) * options_.max_hull_points, options_.max_hull_points));
  if (hull_size_[a] == 0) ++stats_.no_hull;
  fragment_length_[a] = travelled_;
  // The loop first: a revisit puts the robot into the fragment it closed with.
  last_closed_ = false;
  FW_RETURN_IF_ERROR(close_loop(a));
  if (last_closed_) {
    const std::uint32_t c = last_closure_c_;
    const Se2d c_from_a = world_[c].inverse().compose(world_[a]);
    if (inside(c, c_from_a.compose(rel_))) {
      enter(c, c_from_a, last_closure_cov_);
      return Status::ok();
    }
  }
  return open_fragment_from(a, have_border ? &b : nullptr, frontend_pose, points, count);
}

// A new EXPLORE fragment from `parent` at the tracked pose; it gets the reversed border the robot
// crossed (if one was cut), expressed in its own frame.
Status AntSlam::open_fragment_from(std::uint32_t parent, const Border* crossed, const Se2d& frontend_pose,
                                   const Point2f* points, std::size_t count) {
  const Se2d at = rel_;
  pending_parent_ = parent;
  FW_RETURN_IF_ERROR(start_fragment(frontend_pose, points, count));
  if (crossed != nullptr) add_border(active_, crossed->reversed().transformed(at.inverse()));
  return Status::ok();
}

// Tracking w.r.t. the traversed fragment: every keyframe step the scan is fitted on f's distance
// field from the tracked pose (the front end maps against its own local map, not f's); a fit as good
// as a loop closure must be and inside the tracked covariance's gate is fused by a Kalman update.
void AntSlam::track_in_fragment(std::uint32_t f, const Point2f* points, std::size_t count) {
  if (points == nullptr || count == 0 || num_points_[f] < options_.min_fragment_points) return;
  if (!keyframe_due()) return;
  if (model_of_ != f && !use_fragment_model(f)) return;
  std::size_t n = 0;
  for (std::size_t k = 0; k < count && n < options_.max_points_per_fragment; k += options_.beam_stride) {
    if (std::isfinite(points[k](0)) && std::isfinite(points[k](1))) hull_scratch_[n++] = points[k];
  }
  have_keyframe_ = true;
  last_keyframe_ = rel_;
  const FieldFit fit = fit_on_field(matcher_.field(), hull_scratch_, n, rel_, options_.refine_iterations,
                                    options_.refine_cutoff_start, options_.refine_cutoff_end);
  if (!(fit.quality >= options_.min_closure_quality)) return;
  const Mat3 gate = rel_cov_ + closure_prior();
  const Vec3 d = se2_difference(fit.pose, rel_);
  if (!(d.dot(gate.inverse() * d) <= options_.closure_gate_chi2)) return;
  // Kalman update of the tracked pose with the fit (Σ of the fit by Eq. 3.9 where it can be
  // fitted, else the closure sigmas): the correction is weighed, not snapped to.
  Mat3 r = closure_prior();
  sensor_model_cov(hull_scratch_, n, fit.pose, &r);
  const Mat3 k = rel_cov_ * (rel_cov_ + r).inverse();
  const Vec3 step = k * d;
  rel_ = Se2d(rel_.x + step(0), rel_.y + step(1), wrap_angle(rel_.theta + step(2)));
  rel_cov_ = (Mat3::Identity() - k) * rel_cov_;
  rel_cov_ = 0.5 * (rel_cov_ + rel_cov_.transpose()).eval();
  last_keyframe_ = rel_;
  ++stats_.traversal_fits;
}

Status AntSlam::traverse(const Se2d& frontend_pose, const Point2f* points, std::size_t count) {
  const std::uint32_t c = active_;
  if (inside(c, rel_)) {
    if (options_.traversal_tracking) track_in_fragment(c, points, count);
    return Status::ok();
  }
  // Into a fragment joined to c by an edge (a measured relation) whose region the robot is in.
  for (std::uint32_t e = 0; e < num_edges_; ++e) {
    const SampledEdge& ed = edges_[e];
    if (ed.from != c && ed.to != c) continue;
    const std::uint32_t g = ed.from == c ? ed.to : ed.from;
    const Se2d g_from_c = world_[g].inverse().compose(world_[c]);
    if (inside(g, g_from_c.compose(rel_))) {
      enter(g, g_from_c, Mat3::Zero());
      return Status::ok();
    }
  }
  // Unexplored terrain: a border on c where the robot leaves it, and a new fragment from c.
  Border b;
  const bool have_border = cut_border(c, rel_, &b);
  return open_fragment_from(c, have_border ? &b : nullptr, frontend_pose, points, count);
}

void AntSlam::shortest_paths(std::uint32_t a) {
  // All edges weigh 1: Dijkstra's shortest fragment sequence is a breadth-first search.
  for (std::uint32_t i = 0; i < num_fragments_; ++i) {
    hops_[i] = kNoHops;
    parent_edge_[i] = -1;
  }
  std::uint32_t head = 0, tail = 0;
  hops_[a] = 0;
  queue_[tail++] = a;
  while (head < tail) {
    const std::uint32_t n = queue_[head++];
    for (std::uint32_t e = 0; e < num_edges_; ++e) {
      const SampledEdge& ed = edges_[e];
      std::uint32_t m = kNoHops;
      if (ed.from == n) m = ed.to;
      else if (ed.to == n) m = ed.from;
      if (m == kNoHops || m >= num_fragments_ || hops_[m] != kNoHops) continue;
      hops_[m] = hops_[n] + 1;
      parent_edge_[m] = static_cast<std::int32_t>(e);
      queue_[tail++] = m;
    }
  }
}

// F_a in F_c along the first n steps of the current path and its covariance (Eq. 3.4 compounding;
// frozen edges count with frozen_cov_scale, reversed steps with the inverse's Jacobian).
void AntSlam::compound_path(std::uint32_t n, Se2d* x, Mat3* cov) const {
  for (std::uint32_t i = 0; i < n; ++i) {
    const SampledEdge& e = *steps_[i].edge;
    const Se2d t = step_transform(steps_[i], e.value);
    Mat3 ct = e.frozen ? Mat3(e.predict_cov * options_.frozen_cov_scale) : e.predict_cov;
    if (!steps_[i].forward) {
      const Mat3 ji = e.value.jacobian_inverse();
      ct = ji * ct * ji.transpose();
    }
    const Mat3 j1 = x->jacobian_compose_first(t), j2 = x->jacobian_compose_second();
    *cov = j1 * *cov * j1.transpose() + j2 * ct * j2.transpose();
    *x = x->compose(t);
  }
}

std::uint32_t AntSlam::build_path(std::uint32_t c, std::uint32_t a) {
  // Walk from c toward a along the BFS parents: the steps come out in the order c → a.
  std::uint32_t n = 0, node = c;
  while (node != a && n < options_.max_loop_steps) {
    const SampledEdge& e = edges_[parent_edge_[node]];
    const bool forward = e.from == node;
    steps_[n++] = LoopStep{&e, forward};
    node = forward ? e.to : e.from;
  }
  return node == a ? n : 0;
}

Se2d AntSlam::scan_pose(std::uint32_t i) const {
  const std::uint32_t f = scan_fragment_[i];
  if (adjacent_edge_[f] == kNoEdge || !(fragment_length_[f] > 0.0) || scan_along_[i] < 0.0f) {
    return world_[f].compose(scan_rel_[i]);
  }
  const SampledEdge& e = edges_[adjacent_edge_[f]];
  const Se2d delta = e.value.compose(e.mean.inverse());
  double alpha = static_cast<double>(scan_along_[i]) / fragment_length_[f];
  alpha = alpha < 0.0 ? 0.0 : (alpha > 1.0 ? 1.0 : alpha);
  const Se2d part(alpha * delta.x, alpha * delta.y, alpha * delta.theta);
  return world_[f].compose(part).compose(scan_rel_[i]);
}

void AntSlam::recompute_world() {
  // Entry edges come from older fragments: one pass in order.
  for (std::uint32_t f = 1; f < num_fragments_; ++f) {
    const SampledEdge& e = edges_[entry_edge_[f]];
    world_[f] = world_[e.from].compose(e.value);
  }
}

// Older fragments c that may overlap a, nearest (Mahalanobis) first, at most max_candidates of them.
std::uint32_t AntSlam::find_candidates(std::uint32_t a, std::uint32_t* cand) {
  double cand_m[kMaxCandidates];
  std::uint32_t num_cand = 0;
  for (std::uint32_t c = 0; c + options_.min_fragment_gap <= a; ++c) {
    if (hops_[c] == kNoHops || num_points_[c] < options_.min_fragment_points) continue;
    // With traversal the graph is a tree: a fragment opened from an old one is near it in hops.
    if (options_.traversal && hops_[c] < options_.min_fragment_gap) continue;
    const std::uint32_t n = build_path(c, a);
    if (n == 0) continue;
    double m = 0.0;
    if (!candidate_distance(c, a, n, &m)) continue;
    insert_candidate(c, m, options_.max_candidates, cand, cand_m, &num_cand);
  }
  return num_cand;
}

// Mahalanobis distance m of a's poses to the nearest pose of c (beyond the overlap radius), a's
// poses mapped into F_c along the current path of n steps; false when c is beyond the gate.
bool AntSlam::candidate_distance(std::uint32_t c, std::uint32_t a, std::uint32_t n, double* m) const {
  // Predicted x = F_a in F_c along the path and its covariance (Eq. 3.4 compounding).
  Se2d x;
  Mat3 cov = Mat3::Zero();
  compound_path(n, &x, &cov);
  const double sigma = position_sigma(cov);
  const Se2d* kc = keyframes_ + static_cast<std::size_t>(c) * options_.max_keyframes_per_fragment;
  const Se2d* ka = keyframes_ + static_cast<std::size_t>(a) * options_.max_keyframes_per_fragment;
  // Cheap bound first: fragment radii around their frames.
  const double ra = frame_radius(ka, num_keyframes_[a]), rc = frame_radius(kc, num_keyframes_[c]);
  const double lower = std::hypot(x.x, x.y) - ra - rc - options_.overlap_radius_m;
  if (lower > options_.candidate_mahalanobis * sigma) return false;
  const double dmin = nearest_pose_distance(x, ka, num_keyframes_[a], kc, num_keyframes_[c]);
  *m = (dmin > options_.overlap_radius_m ? dmin - options_.overlap_radius_m : 0.0) / sigma;
  return *m <= options_.candidate_mahalanobis;
}

// pRANSAM: a's points (scene, F_a) against c's (model, F_c) → h = F_a in F_c, refined when asked;
// false (rejected_quality) when c gives no hypothesis good enough for a closure.
bool AntSlam::match_closure(std::uint32_t a, std::uint32_t c, const Se2d& x, Se2d* h, float* quality) {
  const Point2f* scene = points_ + static_cast<std::size_t>(a) * options_.max_points_per_fragment;
  ++stats_.candidates;
  const std::uint64_t t0 = now();
  // A fragment pRANSAM cannot take as a model (degenerate, too large for the field) is no candidate.
  if (!use_fragment_model(c)) {
    ++stats_.rejected_quality;
    return false;
  }
  matcher_.reset();
  pransam::MatchParams mp = options_.match;
  mp.seed = options_.seed * 1000003u + a * 4099u + c;
  pransam::MatchResult<2> res;
  const Status st = matcher_.match(scene, num_points_[a], mp, &res);
  stats_.matcher_ns += now() - t0;
  if (!st.is_ok() || !res.best_valid || res.best.quality < options_.min_closure_quality) {
    ++stats_.rejected_quality;
    return false;
  }
  *quality = res.best.quality;
  *h = pransam::to_se2(res.best).cast<double>();
  if (options_.refine_closure) *h = refine_hypothesis(scene, num_points_[a], *h, x);
  return true;
}

// Closure refinement (field_fit.h): h and the prediction x both fitted on c's distance field (the
// matcher's model); the prediction wins unless h fits better by prefer_prediction_margin.
Se2d AntSlam::refine_hypothesis(const Point2f* scene, std::uint32_t n, const Se2d& h, const Se2d& x) {
  const FieldFit fh = fit_on_field(matcher_.field(), scene, n, h, options_.refine_iterations,
                                   options_.refine_cutoff_start, options_.refine_cutoff_end);
  const FieldFit fx = fit_on_field(matcher_.field(), scene, n, x, options_.refine_iterations,
                                   options_.refine_cutoff_start, options_.refine_cutoff_end);
  if (fx.quality + options_.prefer_prediction_margin >= fh.quality) {
    ++stats_.prediction_kept;
    return fx.pose;
  }
  return fh.pose;
}

// Σ_h of the closing edge: the fixed closure sigmas, replaced by the Eq. 3.9 fit where it succeeds.
Mat3 AntSlam::closure_cov(const Point2f* scene, std::uint32_t n, const Se2d& h) {
  Mat3 cov_h = closure_prior();
  // Eq. 3.9 for the closing edge: a's points around h on c's field (the matcher's model).
  if (options_.edge_model == EdgeModel::kSensorModel) {
    if (sensor_model_cov(scene, n, h, &cov_h)) ++stats_.sensor_fits; else ++stats_.motion_fallbacks;
  }
  return cov_h;
}

// The loop L (c → a, the first n steps_) with the closure h ~ N(μ_h, Σ_h), corrected by the
// selected optimiser into values_; w0 / w1 its cost W (Eq. 3.13) before / after (0 when all frozen).
Status AntSlam::optimize_loop(std::uint32_t n, const Se2d& h, const Mat3& cov_h, double* w0, double* w1) {
  LoopProblem problem;
  problem.steps = steps_;
  problem.num_steps = n;
  problem.closure_mean = h;
  problem.closure_info = cov_h.inverse();
  bool any_free = false;
  for (std::uint32_t i = 0; i < n; ++i) {
    values_[i] = steps_[i].edge->value;
    any_free = any_free || !steps_[i].edge->frozen;
  }
  const std::uint64_t t1 = now();
  if (any_free) {
    if (options_.optimizer == LoopOptimizer::kAntColony) {
      AntColonyReport rep;
      FW_RETURN_IF_ERROR(aco_.solve(problem, num_closures_, values_, &rep));
      *w0 = rep.initial_cost;
      *w1 = rep.best_cost;
    } else {
      LoopLmReport rep;
      FW_RETURN_IF_ERROR(lm_.solve(problem, values_, &rep));
      *w0 = rep.initial_cost;
      *w1 = rep.final_cost;
    }
  }
  stats_.optimizer_ns += now() - t1;
  stats_.aco_initial_cost += *w0;
  stats_.aco_final_cost += *w1;
  return Status::ok();
}

// Writes the optimised values_ into the loop's free edges and freezes them; returns F_a in F_c along
// the corrected chain.
Se2d AntSlam::freeze_loop(std::uint32_t n) {
  Se2d xc;
  for (std::uint32_t i = 0; i < n; ++i) {
    SampledEdge& e = edges_[steps_[i].edge - edges_];
    if (!e.frozen) {
      e.value = values_[i];
      e.frozen = true;  // corrected loops are frozen
    }
    xc = xc.compose(step_transform(steps_[i], e.value));
  }
  return xc;
}

// Candidate c for a: match and gate against the prediction; closes the loop when it passes, else
// records the closure in gated[] for the pair test. Errors only from the optimiser / edges.
Status AntSlam::try_closure(std::uint32_t a, std::uint32_t c, bool* closed, ClosureCandidate* gated,
                            std::uint32_t* num_gated) {
  const Point2f* scene = points_ + static_cast<std::size_t>(a) * options_.max_points_per_fragment;
  std::uint32_t n = build_path(c, a);
  Se2d x;
  Mat3 cov = Mat3::Zero();
  compound_path(n, &x, &cov);
  ClosureCandidate k;
  k.a = a;
  k.c = c;
  if (!match_closure(a, c, x, &k.h, &k.quality)) return Status::ok();
  k.cov_h = closure_cov(scene, num_points_[a], k.h);
  k.dh = se2_difference(k.h, x);
  const double chi2 = k.dh.dot((cov + k.cov_h).inverse() * k.dh);
  k.gate_chi2 = static_cast<float>(chi2);
  k.heading_chi2 = static_cast<float>(k.dh(2) * k.dh(2) / (cov(2, 2) + k.cov_h(2, 2)));
  bool pass = chi2 <= options_.closure_gate_chi2;
  if (pass && options_.gate_isolation) {
    // Isolated among the rivals the gate admits too (a rival the prediction rules out is no alias).
    float z = 0.0f;
    IsolationPrior prior;
    prior.mean = x;
    prior.info = (cov + k.cov_h).inverse();
    prior.gate = options_.closure_gate_chi2;
    pass = closure_isolated(nullptr, k, Se2d(), &z, &prior);
    shortest_paths(a);  // closure_isolated() rooted the BFS at c and reused steps_
    n = build_path(c, a);
    if (!pass) ++stats_.gated_not_isolated;
  }
  if (!pass) {
    if (!(chi2 <= options_.closure_gate_chi2)) ++stats_.rejected_gate;
    if (*num_gated < kMaxCandidates) gated[(*num_gated)++] = k;
    return Status::ok();
  }
  return close_with(a, k, n, closed);
}

// Corrects the loop c → a (the first n steps_) with the closure k, freezes it and adds the closing edge.
Status AntSlam::close_with(std::uint32_t a, const ClosureCandidate& k, std::uint32_t n, bool* closed,
                           const ClosureRecord* pair) {
  double w0 = 0, w1 = 0;
  FW_RETURN_IF_ERROR(optimize_loop(n, k.h, k.cov_h, &w0, &w1));
  const Se2d xc = freeze_loop(n);
  std::uint32_t ei = 0;
  FW_RETURN_IF_ERROR(add_edge(k.c, a, k.h, k.cov_h, k.cov_h, &ei));
  edges_[ei].closure = true;
  edges_[ei].value = xc;  // consistent with the corrected chain
  edges_[ei].frozen = true;
  closures_[num_closures_++] = ClosureRecord{k.c,
                                             a,
                                             n,
                                             k.quality,
                                             k.gate_chi2,
                                             static_cast<float>(std::hypot(k.dh(0), k.dh(1))),
                                             static_cast<float>(w0),
                                             static_cast<float>(w1)};
  if (pair != nullptr) {
    ClosureRecord& r = closures_[num_closures_ - 1];
    r.pair_with = pair->pair_with;
    r.pair_chi2 = pair->pair_chi2;
    r.isolation_z = pair->isolation_z;
  }
  ++stats_.loops;
  recompute_world();
  last_closed_ = true;
  last_closure_c_ = k.c;
  last_closure_cov_ = k.cov_h;
  *closed = true;
  return Status::ok();
}

bool AntSlam::chain(std::uint32_t from, std::uint32_t to, std::uint32_t max_steps, Se2d* x, Mat3* cov) {
  *x = Se2d();
  *cov = Mat3::Zero();
  if (from == to) return true;
  if (hops_[from] == kNoHops || hops_[from] > max_steps) return false;
  const std::uint32_t n = build_path(from, to);
  if (n == 0) return false;
  compound_path(n, x, cov);
  return true;
}

Status AntSlam::try_pair_closure(std::uint32_t a, const ClosureCandidate* gated, std::uint32_t num_gated,
                                 bool* closed) {
  constexpr std::uint32_t kRing = ClosureCandidateRing::kCapacity;
  // Chains a_p → a of every pending closure (BFS rooted at a, as close_loop left it).
  Se2d aa[kRing];
  Mat3 cov_aa[kRing];
  bool aa_ok[kRing];
  for (std::uint32_t i = 0; i < pending_.size(); ++i) {
    aa_ok[i] = pending_[i].a != a && pending_[i].heading_chi2 <= options_.closure_gate_chi2 &&
               chain(pending_[i].a, a, options_.pair_window + 1, &aa[i], &cov_aa[i]);
  }
  // Each gated candidate q: its best cycle with a pending p (BFS rooted at q.c for the chain c_p → c).
  double best[kMaxCandidates];
  std::uint32_t partner[kMaxCandidates];
  std::uint32_t num_paired = 0, first = kMaxCandidates;
  for (std::uint32_t j = 0; j < num_gated; ++j) {
    best[j] = options_.closure_gate_chi2 + 1.0;
    if (!(gated[j].heading_chi2 <= options_.closure_gate_chi2)) continue;  // turned: no drift explains it
    shortest_paths(gated[j].c);
    for (std::uint32_t i = 0; i < pending_.size(); ++i) {
      if (!aa_ok[i]) continue;
      Se2d cc;
      Mat3 cov_cc;
      if (!chain(pending_[i].c, gated[j].c, options_.pair_max_hops, &cc, &cov_cc)) continue;
      const double chi2 = pair_cycle_chi2(pending_[i], gated[j], cc, cov_cc, aa[i], cov_aa[i]);
      if (chi2 < best[j]) {
        best[j] = chi2;
        partner[j] = i;
      }
    }
    if (best[j] <= options_.closure_gate_chi2) {
      ++num_paired;
      if (first == kMaxCandidates || best[j] < best[first]) first = j;
    }
  }
  if (num_paired == 0) {
    shortest_paths(a);
    return Status::ok();
  }
  // Every paired candidate must agree with the chosen one (the same correction of the revisit).
  shortest_paths(gated[first].c);
  for (std::uint32_t j = 0; j < num_gated; ++j) {
    if (j == first || !(best[j] <= options_.closure_gate_chi2)) continue;
    Se2d cc;
    Mat3 cov_cc;
    const bool near = chain(gated[j].c, gated[first].c, options_.pair_max_hops, &cc, &cov_cc);
    if (!near || !(pair_cycle_chi2(gated[j], gated[first], cc, cov_cc, Se2d(), Mat3::Zero()) <=
                   options_.closure_gate_chi2)) {
      shortest_paths(a);
      return Status::ok();  // two different corrections: ambiguous
    }
  }
  ClosureRecord rec;
  rec.pair_with = pending_[partner[first]].a + 1;
  rec.pair_chi2 = static_cast<float>(best[first]);
  if (options_.pair_isolation &&
      !closure_isolated(&pending_[partner[first]], gated[first], aa[partner[first]], &rec.isolation_z)) {
    ++stats_.pairs_not_isolated;
    shortest_paths(a);
    return Status::ok();
  }
  shortest_paths(a);
  const std::uint32_t n = build_path(gated[first].c, a);
  if (n == 0) return Status::ok();
  FW_RETURN_IF_ERROR(close_with(a, gated[first], n, closed, &rec));
  ++stats_.pair_loops;
  return Status::ok();
}

bool AntSlam::closure_isolated(const ClosureCandidate* p, const ClosureCandidate& q, const Se2d& aa, float* z,
                               const IsolationPrior* prior) {
  // Scene: q.a's points and (a pair) p.a's moved into F_q.a.
  const std::size_t cap = options_.max_points_per_fragment;
  std::size_t ns = 0;
  const Point2f* qa = points_ + static_cast<std::size_t>(q.a) * cap;
  for (std::uint32_t i = 0; i < num_points_[q.a]; ++i) iso_scene_[ns++] = qa[i];
  if (p != nullptr) {
    const Se2d to_q = aa.inverse();
    const Point2f* pa = points_ + static_cast<std::size_t>(p->a) * cap;
    for (std::uint32_t i = 0; i < num_points_[p->a]; ++i) {
      iso_scene_[ns++] = to_q.transform_point(pa[i].cast<double>()).cast<float>();
    }
  }
  // Model: the old fragments within isolation.hops of q.c, in F_q.c, thinned evenly to capacity.
  shortest_paths(q.c);
  std::size_t total = 0;
  for (std::uint32_t f = 0; f < num_fragments_; ++f) {
    if (hops_[f] <= options_.isolation.hops && f + options_.min_fragment_gap <= q.a) total += num_points_[f];
  }
  const std::size_t cap_m = options_.isolation_max_points;
  const std::size_t stride = total > cap_m ? (total + cap_m - 1) / cap_m : 1;
  std::size_t nm = 0, k = 0;
  for (std::uint32_t f = 0; f < num_fragments_; ++f) {
    if (!(hops_[f] <= options_.isolation.hops && f + options_.min_fragment_gap <= q.a)) continue;
    Se2d cf;
    Mat3 cov;
    if (!chain(f, q.c, options_.isolation.hops, &cf, &cov)) continue;
    const Se2d to_c = cf.inverse();  // F_f in F_q.c
    const Point2f* fp = points_ + static_cast<std::size_t>(f) * cap;
    for (std::uint32_t i = 0; i < num_points_[f]; ++i, ++k) {
      if (k % stride == 0 && nm < cap_m) iso_model_[nm++] = to_c.transform_point(fp[i].cast<double>()).cast<float>();
    }
  }
  *z = 0.0f;
  // A model too large for the field is not shown isolated.
  if (!iso_field_.build(iso_model_, nm, "antslam isolation model").is_ok()) return false;
  const IsolationResult r =
      check_closure_isolation(iso_field_, iso_scene_, ns, q.h, options_.isolation, iso_cells_, prior);
  *z = r.rival_z;
  return r.isolated;
}

Status AntSlam::close_loop(std::uint32_t a) {
  if (num_closures_ >= options_.max_closures || a < options_.min_fragment_gap) return Status::ok();
  if (num_points_[a] < options_.min_fragment_points) return Status::ok();
  shortest_paths(a);
  // Candidates, nearest (Mahalanobis) first.
  std::uint32_t cand[kMaxCandidates];
  const std::uint32_t num_cand = find_candidates(a, cand);
  ClosureCandidate gated[kMaxCandidates];
  std::uint32_t num_gated = 0;
  bool closed = false;
  for (std::uint32_t k = 0; k < num_cand && !closed; ++k) {
    FW_RETURN_IF_ERROR(try_closure(a, cand[k], &closed, gated, &num_gated));  // one loop per fragment
  }
  if (!options_.pair_closures) return Status::ok();
  pending_.expire(a, options_.pair_window);
  if (!closed && num_gated > 0) FW_RETURN_IF_ERROR(try_pair_closure(a, gated, num_gated, &closed));
  if (closed) {
    pending_.clear();  // the revisit is corrected; later closures are gated against the new prediction
    return Status::ok();
  }
  for (std::uint32_t k = 0; k < num_gated; ++k) pending_.push(gated[k]);
  return Status::ok();
}

}  // namespace fw::antslam
