#include "firmware/rbsm/rbsm.h"

#include "firmware/base/memory_report.h"
#include "firmware/rbsm/particle_weights.h"
#include "firmware/scan/point_to_line.h"

#include <cmath>

namespace fw {
namespace {
constexpr float kDegToRad = 0.017453292519943295f;
}  // namespace

Status RbsmOptions::validate() const {
  if (num_particles < 1 || num_particles > kMaxParticles) {
    return Status::error(Errc::kInvalidArgument, "rbsm: num_particles %u outside [1, %u]", num_particles, kMaxParticles);
  }
  if (!(sigma_xy2_cells2 > 0.0f) || !std::isfinite(sigma_xy2_cells2) || !(sigma_psi2_deg2 > 0.0f) ||
      !std::isfinite(sigma_psi2_deg2)) {
    return Status::error(Errc::kInvalidArgument, "rbsm: initial covariance (%g cells², %g deg²) must be positive",
                         static_cast<double>(sigma_xy2_cells2), static_cast<double>(sigma_psi2_deg2));
  }
  if (!(accept_ratio > 0.0f && accept_ratio <= 1.0f)) {
    return Status::error(Errc::kInvalidArgument, "rbsm: accept_ratio (Delta) %g outside (0, 1]",
                         static_cast<double>(accept_ratio));
  }
  if (!(shrink > 0.0f && shrink < 1.0f)) {
    return Status::error(Errc::kInvalidArgument, "rbsm: shrink (delta) %g outside (0, 1)", static_cast<double>(shrink));
  }
  if (max_iterations < 1 || max_iterations > 1000) {
    return Status::error(Errc::kInvalidArgument, "rbsm: max_iterations %u outside [1, 1000]", max_iterations);
  }
  if (min_iterations < 1 || min_iterations > max_iterations) {
    return Status::error(Errc::kInvalidArgument, "rbsm: min_iterations %u outside [1, max_iterations %u]", min_iterations,
                         max_iterations);
  }
  if (min_points < 1) return Status::error(Errc::kInvalidArgument, "rbsm: min_points must be at least 1");
  if (!(max_range >= 0.0f) || !std::isfinite(max_range)) {
    return Status::error(Errc::kInvalidArgument, "rbsm: max_range %g must be >= 0", static_cast<double>(max_range));
  }
  if (hill_climbing && (hill_climb_steps < 1 || hill_climb_steps > 50)) {
    return Status::error(Errc::kInvalidArgument, "rbsm: hill_climb_steps %u outside [1, 50]", hill_climb_steps);
  }
  if (mahalanobis && (!(range_sigma > 0.0f) || !(bearing_sigma_deg > 0.0f) || !(map_point_sigma_cells > 0.0f))) {
    return Status::error(Errc::kInvalidArgument, "rbsm: Mahalanobis noise parameters must be positive");
  }
  if (motion_prior && (!(prior_sigma_xy_m > 0.0f) || !(prior_sigma_xy_per_m >= 0.0f))) {
    return Status::error(Errc::kInvalidArgument, "rbsm: motion prior needs prior_sigma_xy_m > 0 and prior_sigma_xy_per_m >= 0");
  }
  if (refine) {
    if (refine_iterations < 1 || refine_iterations > 100) {
      return Status::error(Errc::kInvalidArgument, "rbsm: refine_iterations %u outside [1, 100]", refine_iterations);
    }
    if (refine_radius_cells < 1 || refine_radius_cells > 4) {
      return Status::error(Errc::kInvalidArgument, "rbsm: refine_radius_cells %u outside [1, 4]", refine_radius_cells);
    }
    if (refine_min_cells < 2) return Status::error(Errc::kInvalidArgument, "rbsm: refine_min_cells must be at least 2");
    if (!(refine_max_line_ratio > 0.0f && refine_max_line_ratio <= 1.0f) || !(refine_gate_cells > 0.0f) ||
        !(refine_huber_cells > 0.0f) || !(refine_min_fraction >= 0.0f && refine_min_fraction <= 1.0f) ||
        !(refine_max_shift_cells > 0.0f) || !(refine_max_shift_deg > 0.0f) ||
        !(refine_min_eigen_ratio > 0.0f && refine_min_eigen_ratio < 1.0f) ||
        !(refine_max_score_loss >= 0.0f && refine_max_score_loss <= 1.0f)) {
      return Status::error(Errc::kInvalidArgument,
                           "rbsm: refine thresholds invalid (line ratio in (0, 1], gate, huber, shifts > 0, "
                           "min fraction in [0, 1], min eigen ratio in (0, 1))");
    }
  }
  return grid.validate();
}

std::size_t Rbsm::required_arena_bytes(const RbsmOptions& o) {
  return EndpointGrid::required_bytes(o.grid) + static_cast<std::size_t>(o.num_particles) * 9 * 4 + 9 * 64;
}

Status Rbsm::init(const RbsmOptions& options, StartupArena& arena, WorkerPool* pool) {
  FW_RETURN_IF_ERROR(options.validate());
  options_ = options;
  pool_ = pool;
  FW_RETURN_IF_ERROR(grid_.init(options.grid, arena));
  const std::size_t m = options.num_particles;
  float** floats[] = {&x_, &y_, &psi_, &sx_, &sy_, &spsi_, &cos_, &sin_};
  for (float** f : floats) {
    Result<void*> r = arena.allocate(m * sizeof(float), 64, "rbsm particles");
    if (!r) return r.status();
    *f = static_cast<float*>(*r);
  }
  Result<void*> r = arena.allocate(m * sizeof(std::uint32_t), 64, "rbsm weights");
  if (!r) return r.status();
  w_ = static_cast<std::uint32_t*>(*r);
  FW_RETURN_IF_ERROR(MemoryReport::instance().add(
      {"rbsm", "particles (SoA) + weights", m * (8 * sizeof(float) + sizeof(std::uint32_t)), m, nullptr}));
  initialized_ = true;
  reset();
  return Status::ok();
}

// Back to the state after init(): empty map with its window un-centred (EndpointGrid::clear),
// streams reseeded, no tracking. Nothing of a previous run may leak into the next one.
void Rbsm::reset() {
  grid_.clear();
  tracking_ = false;
  last_estimate_ = Se2f();
  num_points_ = 0;
  cur_sig_xy_ = cur_sig_psi_ = 0.0f;
  for (std::uint32_t p = 0; p < RbsmOptions::kPartitions; ++p) {
    streams_[p].reseed(options_.seed, 1 + p);
    part_best_w_[p] = part_best_j_[p] = 0;
  }
  resample_stream_.reseed(options_.seed, 0);
  if (x_ != nullptr) {
    for (std::uint32_t j = 0; j < options_.num_particles; ++j) x_[j] = y_[j] = psi_[j] = 0.0f;
  }
}

// One pose, same arithmetic (and so the same values) as weigh_block.
std::uint32_t Rbsm::weigh_single(float x, float y, float c, float s) const {
  const EndpointGrid::LookupView& v = view_;
  const float ox = (x - v.origin_x) * v.inv_subcell, oy = (y - v.origin_y) * v.inv_subcell;
  const float cs = c * v.inv_subcell, sn = s * v.inv_subcell;
  std::uint32_t w = 0;
  for (std::uint32_t i = 0; i < num_points_; ++i) {
    const float fx = ox + (cs * px_[i] - sn * py_[i]);
    const float fy = oy + (sn * px_[i] + cs * py_[i]);
    if (!(fx >= 0.0f && fx < v.extent && fy >= 0.0f && fy < v.extent)) continue;
    const std::uint32_t ix = static_cast<std::uint32_t>(static_cast<std::int32_t>(fx) + v.origin_sx) & v.mask;
    const std::uint32_t iy = static_cast<std::uint32_t>(static_cast<std::int32_t>(fy) + v.origin_sy) & v.mask;
    w += v.values[EndpointGrid::tiled_index(ix, iy, v.shift)];
  }
  return w;
}

// Eq. 2.12–2.16: h = s − m̂ with m̂ the nearest occupied cell centre within ξ;
// C = J_x P_B J_xᵀ + J_p P_p J_pᵀ + P_q; weight term exp(−hᵀC⁻¹h), quantised like Eq. 2.9.
std::uint32_t Rbsm::weigh_mahalanobis(float x, float y, float psi, float c, float s) const {
  (void)psi;
  const float res = grid_.resolution();
  const float xi = options_.grid.xi_cells * res;
  const float pbx = cur_sig_xy_ * cur_sig_xy_, pbt = cur_sig_psi_ * cur_sig_psi_;
  const float pq = options_.map_point_sigma_cells * res * options_.map_point_sigma_cells * res;
  std::uint32_t w = 0;
  for (std::uint32_t i = 0; i < num_points_; ++i) {
    const float wx = x + c * px_[i] - s * py_[i], wy = y + s * px_[i] + c * py_[i];
    float mx, my, d2;
    if (!grid_.nearest_occupied(wx, wy, xi, &mx, &my, &d2)) continue;
    const float hx = wx - mx, hy = wy - my;
    // J_x = [I | ∂/∂θ], ∂/∂θ = (−px s − py c, px c − py s); P_B = diag(σxy², σxy², σψ²).
    const float jx = -px_[i] * s - py_[i] * c, jy = px_[i] * c - py_[i] * s;
    float cxx = pbx + jx * jx * pbt + pq, cxy = jx * jy * pbt, cyy = pbx + jy * jy * pbt + pq;
    // J_p P_p J_pᵀ with J_p = R(θ).
    const float a = pcov_[i][0], b = pcov_[i][1], d = pcov_[i][2];
    cxx += c * c * a - 2.0f * c * s * b + s * s * d;
    cxy += c * s * a + (c * c - s * s) * b - c * s * d;
    cyy += s * s * a + 2.0f * c * s * b + c * c * d;
    const float det = cxx * cyy - cxy * cxy;
    if (!(det > 0.0f)) continue;
    const float m2 = (cyy * hx * hx - 2.0f * cxy * hx * hy + cxx * hy * hy) / det;
    w += static_cast<std::uint32_t>(std::exp(-m2) * static_cast<float>(EndpointGrid::kLikelihoodMax) + 0.5f);
  }
  return w;
}

std::uint32_t Rbsm::score_pose(const Se2f& pose) {
  view_ = grid_.lookup_view();
  return weigh_single(pose.x, pose.y, std::cos(pose.theta), std::sin(pose.theta));
}

// Weights of sampled particles [begin, end) (particle_weights.h; same values as weigh_single()).
void Rbsm::weigh_block(std::uint32_t begin, std::uint32_t end) {
  if (options_.mahalanobis) {
    for (std::uint32_t j = begin; j < end; ++j) w_[j] = weigh_mahalanobis(sx_[j], sy_[j], spsi_[j], cos_[j], sin_[j]);
    return;
  }
  const ParticleBlock b{sx_, sy_, cos_, sin_, w_, begin, end};
  weigh_particles(view_, px_, py_, num_points_, b, options_.wide_simd);
}

// Alg. 1 l. 12: coordinate hill climbing (±step in x, y, ψ; halve the steps when nothing improves).
void Rbsm::hill_climb(std::uint32_t j, float step_xy, float step_psi) {
  float x = sx_[j], y = sy_[j], psi = spsi_[j];
  std::uint32_t best = w_[j];
  for (std::uint32_t k = 0; k < options_.hill_climb_steps; ++k) {
    const float cand[6][3] = {{step_xy, 0, 0}, {-step_xy, 0, 0}, {0, step_xy, 0},
                              {0, -step_xy, 0}, {0, 0, step_psi}, {0, 0, -step_psi}};
    int arg = -1;
    for (int n = 0; n < 6; ++n) {
      const float p = psi + cand[n][2];
      const float c = std::cos(p), s = std::sin(p);
      const std::uint32_t w = options_.mahalanobis ? weigh_mahalanobis(x + cand[n][0], y + cand[n][1], p, c, s)
                                                   : weigh_single(x + cand[n][0], y + cand[n][1], c, s);
      if (w > best) {
        best = w;
        arg = n;
      }
    }
    if (arg < 0) {
      step_xy *= 0.5f;
      step_psi *= 0.5f;
      continue;
    }
    x += cand[arg][0];
    y += cand[arg][1];
    psi += cand[arg][2];
  }
  sx_[j] = x;
  sy_[j] = y;
  spsi_[j] = psi;
  cos_[j] = std::cos(psi);
  sin_[j] = std::sin(psi);
  w_[j] = best;
}

void Rbsm::run_partition(std::uint32_t p, float sig_xy, float sig_psi) {
  const std::uint32_t m = options_.num_particles;
  const std::uint32_t begin = static_cast<std::uint32_t>(static_cast<std::uint64_t>(m) * p / RbsmOptions::kPartitions);
  const std::uint32_t end = static_cast<std::uint32_t>(static_cast<std::uint64_t>(m) * (p + 1) / RbsmOptions::kPartitions);
  RandomStream& rng = streams_[p];
  // Alg. 1 l. 10: x_j ~ N(x_j, Σ), Σ diagonal (Eq. 2.11).
  for (std::uint32_t j = begin; j < end; ++j) {
    sx_[j] = x_[j] + sig_xy * static_cast<float>(rng.gaussian());
    sy_[j] = y_[j] + sig_xy * static_cast<float>(rng.gaussian());
    spsi_[j] = psi_[j] + sig_psi * static_cast<float>(rng.gaussian());
    cos_[j] = std::cos(spsi_[j]);
    sin_[j] = std::sin(spsi_[j]);
  }
  weigh_block(begin, end);  // l. 11
  if (options_.hill_climbing) {
    for (std::uint32_t j = begin; j < end; ++j) hill_climb(j, 0.5f * sig_xy, 0.5f * sig_psi);
  }
  if (prior_inv_var_xy_ > 0.0f && round_ == 1) apply_motion_prior(begin, end);
  std::uint32_t bw = 0, bj = begin;
  for (std::uint32_t j = begin; j < end; ++j) {
    if (w_[j] > bw) {
      bw = w_[j];
      bj = j;
    }
  }
  part_best_w_[p] = bw;
  part_best_j_[p] = bj;
}

// Extension of Alg. 1: Eq. 2.8 is flat along a featureless corridor, so resampling keeps the set's
// spread there and every round adds Σ: the set diffused metres along the axis and x̂_t jumped inside
// it (intel scans 12317–12328: ±3.7 m between consecutive scans, README). The odometry says how far
// the robot can have moved since the last match; weighing the sampled set by that prior (proposal
// times likelihood, as a particle filter does) keeps it where the wheels allow along the directions
// the scan leaves open. Wide (σ ≥ 0.5 m) and on the position only: Eq. 2.8 is a sum of bounded
// per-point scores, so its ratios between good and fair poses are small and a tight prior would
// outvote the scan; the heading is left to the scan (per-scan heading errors of the wheels reach
// degrees, fr079). First round only: applied in every round it compounds to σ/√rounds (measured,
// 3 seeds: fr079 long relations 0.07 → 0.19 m). Integer weights stay integers (rounded down).
void Rbsm::apply_motion_prior(std::uint32_t begin, std::uint32_t end) {
  for (std::uint32_t j = begin; j < end; ++j) {
    if (w_[j] == 0) continue;
    const double dx = static_cast<double>(sx_[j]) - prior_center_.x, dy = static_cast<double>(sy_[j]) - prior_center_.y;
    const double m2 = (dx * dx + dy * dy) * prior_inv_var_xy_;
    w_[j] = static_cast<std::uint32_t>(static_cast<double>(w_[j]) * std::exp(-0.5 * m2));
  }
}

struct Rbsm::Job {
  Rbsm* self;
  float sig_xy, sig_psi;
};

void Rbsm::job_entry(void* context, int worker, int num_workers) {
  Job* job = static_cast<Job*>(context);
  std::size_t b, e;
  WorkerPool::partition(RbsmOptions::kPartitions, worker, num_workers, &b, &e);
  for (std::size_t p = b; p < e; ++p) job->self->run_partition(static_cast<std::uint32_t>(p), job->sig_xy, job->sig_psi);
}

// Alg. 1 l. 16–19, low-variance (systematic) resampling: one uniform draw, M evenly spaced pointers.
void Rbsm::resample(std::uint64_t total) {
  const std::uint32_t m = options_.num_particles;
  const double step = static_cast<double>(total) / static_cast<double>(m);
  double u = resample_stream_.uniform01() * step;
  std::uint32_t i = 0;
  double cum = static_cast<double>(w_[0]);
  for (std::uint32_t k = 0; k < m; ++k) {
    while (u >= cum && i + 1 < m) {
      ++i;
      cum += static_cast<double>(w_[i]);
    }
    x_[k] = sx_[i];
    y_[k] = sy_[i];
    psi_[k] = spsi_[i];
    u += step;
  }
}

// Extension of Alg. 1 (issue 15): point-to-line Gauss–Newton of x̂_t against the end-point map.
// The end-point map M_t (Sec. 2.3) holds every accepted scan point as an occupied cell; the surface
// a point should lie on is recovered locally as the line through the occupied cells around it
// (centroid + principal axis of their scatter), which averages the cell quantisation that bounds
// the particles' precision (Eq. 2.9 is a step function of the cell). Residual r = nᵀ(q − c), the
// point-to-line distance; Huber-weighted, gated at refine_gate_cells; the solver is the one PL-ICP
// and the tracker use (firmware/scan/point_to_line.h). The step is restricted to the directions the
// surfaces constrain, so a corridor's axis stays where the particles put it (measured on aces
// with a free step: whole-log error 0.17 → 0.51 m, long relations 1.3 → 5.5 m).
bool Rbsm::refine(const Se2f& start, Se2f* out, std::uint32_t* used) const {
  *out = start;
  *used = 0;
  const float res = grid_.resolution();
  const float gate = options_.refine_gate_cells * res, huber = options_.refine_huber_cells * res;
  const std::int32_t radius = static_cast<std::int32_t>(options_.refine_radius_cells);
  const std::uint32_t min_used =
      options_.min_points > static_cast<std::uint32_t>(options_.refine_min_fraction * static_cast<float>(num_points_))
          ? options_.min_points
          : static_cast<std::uint32_t>(options_.refine_min_fraction * static_cast<float>(num_points_));
  double lever2 = 0.0;
  for (std::uint32_t i = 0; i < num_points_; ++i) lever2 += static_cast<double>(px_[i]) * px_[i] + static_cast<double>(py_[i]) * py_[i];
  const double lever = std::sqrt(lever2 / num_points_) > 1.0 ? std::sqrt(lever2 / num_points_) : 1.0;
  Se2f t = start;
  PointToLineSystem sys;
  for (std::uint32_t it = 0; it < options_.refine_iterations; ++it) {
    const float c = std::cos(t.theta), s = std::sin(t.theta);
    sys.clear();
    for (std::uint32_t i = 0; i < num_points_; ++i) {
      const float qx = t.x + c * px_[i] - s * py_[i], qy = t.y + s * px_[i] + c * py_[i];
      EndpointGrid::LocalScatter sc;
      grid_.local_scatter(qx, qy, radius, &sc);
      if (sc.count < options_.refine_min_cells) continue;
      float nx, ny, ratio;
      line_normal_from_scatter(sc.sxx, sc.sxy, sc.syy, &nx, &ny, &ratio);
      if (ratio > options_.refine_max_line_ratio) continue;
      const float r = nx * (qx - sc.cx) + ny * (qy - sc.cy);
      const float ar = std::fabs(r);
      if (ar > gate) continue;
      const double w = ar <= huber ? 1.0 : static_cast<double>(huber) / ar;
      sys.add(px_[i], py_[i], c, s, nx, ny, r, w);
    }
    *used = sys.used;
    if (sys.used < min_used) return false;
    // Only the directions the surfaces constrain move (a corridor's axis stays where the particles
    // put it); θ is compared with translation over the RMS lever of the points.
    Eigen::Vector3d dx;
    if (!sys.solve_constrained(&dx, lever, options_.refine_min_eigen_ratio)) return false;
    t = Se2f(t.x + static_cast<float>(dx(0)), t.y + static_cast<float>(dx(1)),
             wrap_angle(t.theta + static_cast<float>(dx(2))));
    // Converged: the step is far below the cell (measured: a looser stop, 1/50 cell, costs
    // 5 % of the short-relation precision on fr079 and saves 3 % CPU).
    if (dx.head<2>().norm() < 1e-3 * res && std::fabs(dx(2)) < 1e-5) break;
  }
  const float shift = std::hypot(t.x - start.x, t.y - start.y);
  if (!(shift <= options_.refine_max_shift_cells * res) ||
      !(std::fabs(wrap_angle(t.theta - start.theta)) <= options_.refine_max_shift_deg * kDegToRad)) {
    return false;
  }
  *out = t;
  return true;
}

// Alg. 1 l. 2–4: motion model. The set moves with the displacement from the last estimate to the
// guess (= the odometry increment when guess = last ⊕ u_t); the motion prior of this match
// (extension, apply_motion_prior) is centred on the guess with σ growing with |u|.
void Rbsm::move_particles(const Se2f& guess) {
  const std::uint32_t m = options_.num_particles;
  prior_inv_var_xy_ = 0.0f;
  if (!tracking_) {
    for (std::uint32_t j = 0; j < m; ++j) {
      x_[j] = guess.x;
      y_[j] = guess.y;
      psi_[j] = guess.theta;
    }
    return;
  }
  const Se2f u = last_estimate_.between(guess);
  if (options_.motion_prior) {
    const float sxy = options_.prior_sigma_xy_m + options_.prior_sigma_xy_per_m * std::hypot(u.x, u.y);
    prior_center_ = guess;
    prior_inv_var_xy_ = 1.0f / (sxy * sxy);
  }
  for (std::uint32_t j = 0; j < m; ++j) {
    const float c = std::cos(psi_[j]), s = std::sin(psi_[j]);
    const float nx = x_[j] + c * u.x - s * u.y, ny = y_[j] + s * u.x + c * u.y;
    x_[j] = nx;
    y_[j] = ny;
    psi_[j] = wrap_angle(psi_[j] + u.theta);
  }
}

Status Rbsm::match(const Point2f* points, std::size_t count, const Se2f& guess, ScanMatchResult* out) {
  if (!initialized_) return Status::error(Errc::kNotInitialized, "rbsm: match() before init()");
  if (out == nullptr) return Status::error(Errc::kInvalidArgument, "rbsm: null result");
  if (count > 0 && points == nullptr) return Status::error(Errc::kInvalidArgument, "rbsm: null points (count %zu)", count);
  if (count > RbsmOptions::kMaxPoints) {
    return Status::error(Errc::kInvalidArgument, "rbsm: %zu points exceed capacity %u", count, RbsmOptions::kMaxPoints);
  }
  if (!std::isfinite(guess.x) || !std::isfinite(guess.y) || !std::isfinite(guess.theta)) {
    return Status::error(Errc::kInvalidArgument, "rbsm: non-finite initial guess (%g, %g, %g)",
                         static_cast<double>(guess.x), static_cast<double>(guess.y), static_cast<double>(guess.theta));
  }
  *out = ScanMatchResult{};
  // Valid points only (NaN/inf dropped, optional range limit); P_p per point for Eq. 2.14.
  num_points_ = 0;
  const float max_r2 = options_.max_range > 0.0f ? options_.max_range * options_.max_range : 0.0f;
  const float sr2 = options_.range_sigma * options_.range_sigma;
  const float sb2 = options_.bearing_sigma_deg * kDegToRad * options_.bearing_sigma_deg * kDegToRad;
  for (std::size_t i = 0; i < count; ++i) {
    const float px = points[i](0), py = points[i](1);
    if (!std::isfinite(px) || !std::isfinite(py)) continue;
    const float r2 = px * px + py * py;
    if (max_r2 > 0.0f && r2 > max_r2) continue;
    px_[num_points_] = px;
    py_[num_points_] = py;
    if (options_.mahalanobis) {
      const float r = std::sqrt(r2);
      const float ca = r > 0.0f ? px / r : 1.0f, sa = r > 0.0f ? py / r : 0.0f;
      // Polar → Cartesian: J = [[c, −r s], [s, r c]], P_p = J diag(σr², σb²) Jᵀ.
      pcov_[num_points_][0] = ca * ca * sr2 + r2 * sa * sa * sb2;
      pcov_[num_points_][1] = ca * sa * sr2 - r2 * sa * ca * sb2;
      pcov_[num_points_][2] = sa * sa * sr2 + r2 * ca * ca * sb2;
    }
    ++num_points_;
  }
  out->used_points = num_points_;
  if (num_points_ < options_.min_points) {
    return Status::error(Errc::kInvalidArgument, "rbsm: only %u valid points of %zu (min %u)", num_points_, count,
                         options_.min_points);
  }
  const std::uint32_t m = options_.num_particles;
  move_particles(guess);
  if (grid_.occupied_count() == 0) {
    out->pose = guess;
    out->map_was_empty = true;
    out->converged = true;
    tracking_ = true;
    last_estimate_ = guess;
    return Status::ok();
  }
  view_ = grid_.lookup_view();
  const float res = grid_.resolution();
  float var_xy = options_.sigma_xy2_cells2 * res * res;
  float var_psi = options_.sigma_psi2_deg2 * kDegToRad * kDegToRad;
  std::uint32_t best_w = 0;
  Se2f best = guess;
  bool converged = false;
  float ratio = 0.0f;
  std::uint32_t it = 0;
  while (it < options_.max_iterations) {  // l. 7
    ++it;
    round_ = it;
    cur_sig_xy_ = std::sqrt(var_xy);
    cur_sig_psi_ = std::sqrt(var_psi);
    if (pool_ != nullptr && pool_->running() && pool_->size() > 1) {
      Job job{this, cur_sig_xy_, cur_sig_psi_};
      pool_->run(&Rbsm::job_entry, &job);
    } else {
      for (std::uint32_t p = 0; p < RbsmOptions::kPartitions; ++p) run_partition(p, cur_sig_xy_, cur_sig_psi_);
    }
    // Merge in partition order: best particle (Eq. 2.7, earliest index on ties), Σw, Σw².
    for (std::uint32_t p = 0; p < RbsmOptions::kPartitions; ++p) {
      if (part_best_w_[p] > best_w) {
        best_w = part_best_w_[p];
        const std::uint32_t j = part_best_j_[p];
        best = Se2f(sx_[j], sy_[j], wrap_angle(spsi_[j]));
      }
    }
    std::uint64_t total = 0, total2 = 0;
    for (std::uint32_t j = 0; j < m; ++j) {
      total += w_[j];
      total2 += static_cast<std::uint64_t>(w_[j]) * w_[j];
    }
    var_xy *= options_.shrink;  // l. 21
    var_psi *= options_.shrink;
    if (total == 0) continue;  // no particle overlaps the map: keep χ, narrow Σ
    resample(total);           // l. 16–19
    // l. 20: M_eff = 1/Σ ŵ² with ŵ = w/Σw, i.e. (Σw)²/Σw².
    const double meff = static_cast<double>(total) * static_cast<double>(total) / static_cast<double>(total2);
    ratio = static_cast<float>(meff / m);
    if (meff >= static_cast<double>(options_.accept_ratio) * m && it >= options_.min_iterations) {
      converged = true;
      break;
    }
  }
  out->iterations = it;
  out->converged = converged;
  out->effective_ratio = ratio;
  out->pose = best_w > 0 ? best : guess;
  // The particle set stays centred on Alg. 1's estimate: the next motion step (last ⊖ guess) then
  // carries it onto the refined pose ⊕ u_t, so the refinement is not applied twice.
  const Se2f alg1_estimate = out->pose;
  out->unrefined_pose = alg1_estimate;
  if (options_.refine && best_w > 0) {
    std::uint32_t used = 0;
    Se2f refined;
    // Accepted only when Alg. 1's own likelihood (Eq. 2.8–2.9) does not drop by more than
    // refine_max_score_loss: the refinement may polish x̂_t, not move it somewhere the particles
    // would have scored worse.
    if (refine(out->pose, &refined, &used) &&
        static_cast<float>(weigh_single(refined.x, refined.y, std::cos(refined.theta), std::sin(refined.theta))) >=
            (1.0f - options_.refine_max_score_loss) * static_cast<float>(best_w)) {
      out->pose = refined;
      out->refined = true;
    }
  }
  out->score = static_cast<float>(best_w) / (static_cast<float>(EndpointGrid::kLikelihoodMax) * num_points_);
  {
    const float c = std::cos(out->pose.theta), s = std::sin(out->pose.theta);
    std::uint32_t matched = 0;
    for (std::uint32_t i = 0; i < num_points_; ++i) {
      const float wx = out->pose.x + c * px_[i] - s * py_[i], wy = out->pose.y + s * px_[i] + c * py_[i];
      if (grid_.likelihood(wx, wy) > 0) ++matched;
    }
    out->matched_points = matched;
  }
  tracking_ = true;
  last_estimate_ = alg1_estimate;
  return Status::ok();
}

Status Rbsm::integrate(const Point2f* points, std::size_t count, const Se2f& pose, Point2f* new_cells,
                       std::size_t capacity, std::size_t* num_new) {
  if (!initialized_) return Status::error(Errc::kNotInitialized, "rbsm: integrate() before init()");
  if (count > 0 && points == nullptr) return Status::error(Errc::kInvalidArgument, "rbsm: null points (count %zu)", count);
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
    return Status::error(Errc::kInvalidArgument, "rbsm: integrate at non-finite pose");
  }
  const std::size_t n =
      grid_.insert_scan(points, count, pose.x, pose.y, pose.theta, options_.max_range, new_cells, capacity);
  if (num_new) *num_new = n;
  return Status::ok();
}

}  // namespace fw
