#include "firmware/baselines/mcl/mcl.h"

#include <cmath>

namespace fw {
namespace mcl {
namespace {

constexpr float kPi = 3.14159265358979f;

Status check_range(const char* field, double v, double lo, double hi) {
  if (!std::isfinite(v) || v < lo || v > hi) {
    return Status::error(Errc::kInvalidArgument, "MclOptions.%s = %g out of range [%g, %g]", field, v, lo, hi);
  }
  return Status::ok();
}

}  // namespace

Status MclOptions::validate() const {
  FW_RETURN_IF_ERROR(check_range("num_particles", num_particles, 1, kMaxParticles));
  if (model != SensorModel::kBeam && model != SensorModel::kLikelihoodField) {
    return Status::error(Errc::kInvalidArgument, "MclOptions.model = %d unknown", static_cast<int>(model));
  }
  FW_RETURN_IF_ERROR(check_range("num_beams", num_beams, 1, kMaxBeams));
  FW_RETURN_IF_ERROR(check_range("max_range_m", max_range_m, 0.1, 1000.0));
  FW_RETURN_IF_ERROR(check_range("z_hit", z_hit, 0.0, 1.0));
  FW_RETURN_IF_ERROR(check_range("z_short", z_short, 0.0, 1.0));
  FW_RETURN_IF_ERROR(check_range("z_max", z_max, 0.0, 1.0));
  FW_RETURN_IF_ERROR(check_range("z_rand", z_rand, 1e-6, 1.0));
  if (std::fabs(z_hit + z_short + z_max + z_rand - 1.0f) > 1e-3f) {
    return Status::error(Errc::kInvalidArgument, "MclOptions.z_hit+z_short+z_max+z_rand = %g, must be 1",
                         z_hit + z_short + z_max + z_rand);
  }
  FW_RETURN_IF_ERROR(check_range("sigma_hit_m", sigma_hit_m, 1e-3, 10.0));
  FW_RETURN_IF_ERROR(check_range("lambda_short", lambda_short, 1e-3, 100.0));
  FW_RETURN_IF_ERROR(check_range("lf_sigma_m", lf_sigma_m, 1e-3, 10.0));
  FW_RETURN_IF_ERROR(check_range("min_beam_log_likelihood", min_beam_log_likelihood, -100.0, 0.0));
  FW_RETURN_IF_ERROR(check_range("alpha1", alpha1, 0.0, 10.0));
  FW_RETURN_IF_ERROR(check_range("alpha2", alpha2, 0.0, 10.0));
  FW_RETURN_IF_ERROR(check_range("alpha3", alpha3, 0.0, 10.0));
  FW_RETURN_IF_ERROR(check_range("alpha4", alpha4, 0.0, 10.0));
  FW_RETURN_IF_ERROR(check_range("min_trans_noise_m", min_trans_noise_m, 0.0, 10.0));
  FW_RETURN_IF_ERROR(check_range("min_rot_noise_rad", min_rot_noise_rad, 0.0, 10.0));
  FW_RETURN_IF_ERROR(check_range("resample_neff_ratio", resample_neff_ratio, 0.0, 1.0));
  FW_RETURN_IF_ERROR(check_range("kld_epsilon", kld_epsilon, 1e-4, 1.0));
  FW_RETURN_IF_ERROR(check_range("kld_z", kld_z, 0.0, 10.0));
  FW_RETURN_IF_ERROR(check_range("kld_bin_xy_m", kld_bin_xy_m, 1e-3, 100.0));
  FW_RETURN_IF_ERROR(check_range("kld_bin_theta_rad", kld_bin_theta_rad, 1e-3, 6.3));
  if (kld_sampling) FW_RETURN_IF_ERROR(check_range("kld_min_particles", kld_min_particles, 1, num_particles));
  FW_RETURN_IF_ERROR(check_range("alpha_slow", alpha_slow, 0.0, 1.0));
  FW_RETURN_IF_ERROR(check_range("alpha_fast", alpha_fast, alpha_slow, 1.0));
  FW_RETURN_IF_ERROR(check_range("tau", tau, 2, kMaxConstraintWindow));
  FW_RETURN_IF_ERROR(check_range("localized_variance_m2", localized_variance_m2, 0.0, 1e6));
  FW_RETURN_IF_ERROR(check_range("localized_mean_m", localized_mean_m, 0.0, 1e6));
  FW_RETURN_IF_ERROR(check_range("localized_min_mass", localized_min_mass, 0.0, 1.0));
  FW_RETURN_IF_ERROR(check_range("estimate_radius_m", estimate_radius_m, 1e-3, 1e6));
  FW_RETURN_IF_ERROR(check_range("update_min_d", update_min_d, 0.0, 100.0));
  FW_RETURN_IF_ERROR(check_range("update_min_a", update_min_a, 0.0, kPi));
  return Status::ok();
}

Status Mcl::init(const MclOptions& options, const MapView& map, WorkerPool* pool) {
  FW_RETURN_IF_ERROR(options.validate());
  if (!map.valid()) return Status::error(Errc::kInvalidArgument, "Mcl: map view is empty or has null grids");
  options_ = options;
  map_ = map;
  pool_ = pool;
  initialized_ = true;
  reset();
  return Status::ok();
}

// The state init() leaves: no particles, main stream reseeded, per-step streams from step 0,
// no constraint window, no injection averages, counters zero. The main stream used to be seeded
// only in init(), so every run after the first drew other initial particles and resampling
// pointers: a trial's result depended on the trials run before it.
void Mcl::reset() {
  main_rng_.reseed(options_.seed, 1000003);
  n_ = 0;
  num_beams_ = 0;
  delta_ = Se2f();
  apply_motion_ = false;
  step_count_ = 0;
  w_slow_ = w_fast_ = 0.0f;
  have_best_prev_ = false;
  best_prev_ = Se2f();
  best_dist_.clear();
  updates_ = resamples_ = 0;
}

Status Mcl::sample_free(RandomStream* rng, Particle* p) {
  // Rejection sampling over the grid: a free cell (occupancy 0), uniform within it.
  for (int tries = 0; tries < 100000; ++tries) {
    const std::uint32_t cx = rng->uniform_index(map_.width), cy = rng->uniform_index(map_.height);
    if (map_.occupancy.at(static_cast<std::int32_t>(cx), static_cast<std::int32_t>(cy)) != 0) continue;
    p->x = map_.origin_x + (static_cast<float>(cx) + rng->uniform01f()) * map_.resolution;
    p->y = map_.origin_y + (static_cast<float>(cy) + rng->uniform01f()) * map_.resolution;
    p->theta = rng->uniform(-kPi, kPi);
    p->log_w = 0.0f;
    return Status::ok();
  }
  return Status::error(Errc::kNotFound, "Mcl: map has (almost) no free cells to sample from");
}

Status Mcl::init_uniform() {
  if (!initialized_) return Status::error(Errc::kNotInitialized, "Mcl: init_uniform() before init()");
  n_ = options_.num_particles;
  for (std::size_t i = 0; i < n_; ++i) FW_RETURN_IF_ERROR(sample_free(&main_rng_, &particles_[i]));
  have_best_prev_ = false;
  best_dist_.clear();
  w_slow_ = w_fast_ = 0.0f;
  step_count_ = 0;
  return Status::ok();
}

Status Mcl::init_gaussian(const Se2f& pose, const Eigen::Matrix3f& cov) {
  if (!initialized_) return Status::error(Errc::kNotInitialized, "Mcl: init_gaussian() before init()");
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta) || !cov.allFinite()) {
    return Status::error(Errc::kInvalidArgument, "Mcl: init_gaussian with non-finite pose or covariance");
  }
  n_ = options_.num_particles;
  // Diagonal sampling (correlations dropped; the filter restores them within a few steps).
  const float sx = std::sqrt(cov(0, 0) > 0 ? cov(0, 0) : 0.0f), sy = std::sqrt(cov(1, 1) > 0 ? cov(1, 1) : 0.0f);
  const float st = std::sqrt(cov(2, 2) > 0 ? cov(2, 2) : 0.0f);
  for (std::size_t i = 0; i < n_; ++i) {
    Particle& p = particles_[i];
    p.x = main_rng_.gaussianf(pose.x, sx);
    p.y = main_rng_.gaussianf(pose.y, sy);
    p.theta = wrap_angle(main_rng_.gaussianf(pose.theta, st));
    p.log_w = 0.0f;
  }
  have_best_prev_ = false;
  best_dist_.clear();
  w_slow_ = w_fast_ = 0.0f;
  step_count_ = 0;
  return Status::ok();
}

void Mcl::chunk_range(std::size_t chunk, std::size_t* b, std::size_t* e) const {
  *b = n_ * chunk / kChunks;
  *e = n_ * (chunk + 1) / kChunks;
}

namespace {
struct JobCtx {
  Mcl* self;
};
}  // namespace

void Mcl::run_chunks(WorkerPool::JobFn fn) {
  JobCtx ctx{this};
  if (pool_ != nullptr && pool_->running() && pool_->size() > 1) {
    pool_->run(fn, &ctx);
  } else {
    fn(&ctx, 0, 1);
  }
}

void Mcl::motion_job(void* ctx, int worker, int num_workers) {
  Mcl* self = static_cast<JobCtx*>(ctx)->self;
  std::size_t b, e;
  WorkerPool::partition(kChunks, worker, num_workers, &b, &e);
  for (std::size_t c = b; c < e; ++c) self->motion_chunk(c);
}

void Mcl::weight_job(void* ctx, int worker, int num_workers) {
  Mcl* self = static_cast<JobCtx*>(ctx)->self;
  std::size_t b, e;
  WorkerPool::partition(kChunks, worker, num_workers, &b, &e);
  for (std::size_t c = b; c < e; ++c) self->weight_chunk(c);
}

// Odometry motion model sampling (Thrun et al. Table 5.6): rot1, trans, rot2 with noise.
void Mcl::motion_chunk(std::size_t chunk) {
  std::size_t b, e;
  chunk_range(chunk, &b, &e);
  RandomStream rng(options_.seed, step_count_ * kChunks + chunk);
  const float dx = delta_.x, dy = delta_.y, dth = delta_.theta;
  const float trans = std::sqrt(dx * dx + dy * dy);
  // Backward motion keeps rot1 small (ROS AMCL's trick).
  float rot1 = trans < 0.01f ? 0.0f : std::atan2(dy, dx);
  float t = trans;
  if (std::fabs(rot1) > kPi / 2) { rot1 = wrap_angle(rot1 - kPi); t = -trans; }
  const float rot2 = wrap_angle(dth - rot1);
  const float a1 = options_.alpha1, a2 = options_.alpha2, a3 = options_.alpha3, a4 = options_.alpha4;
  const float s_rot1 = std::sqrt(a1 * rot1 * rot1 + a2 * trans * trans) + options_.min_rot_noise_rad;
  const float s_trans = std::sqrt(a3 * trans * trans + a4 * (rot1 * rot1 + rot2 * rot2)) + options_.min_trans_noise_m;
  const float s_rot2 = std::sqrt(a1 * rot2 * rot2 + a2 * trans * trans) + options_.min_rot_noise_rad;
  for (std::size_t i = b; i < e; ++i) {
    Particle& p = particles_[i];
    const float r1 = rot1 + s_rot1 * static_cast<float>(rng.gaussian());
    const float tr = t + s_trans * static_cast<float>(rng.gaussian());
    const float r2 = rot2 + s_rot2 * static_cast<float>(rng.gaussian());
    const float h = p.theta + r1;
    p.x += tr * std::cos(h);
    p.y += tr * std::sin(h);
    p.theta = wrap_angle(h + r2);
  }
}

// Beam model (Table 6.1) or likelihood field (Table 6.3) on the selected beams; log weights.
void Mcl::weight_chunk(std::size_t chunk) {
  std::size_t b, e;
  chunk_range(chunk, &b, &e);
  const float maxr = options_.max_range_m;
  const float inv_rand = options_.z_rand / maxr;
  const float norm_hit = 1.0f / (std::sqrt(2.0f * kPi) * options_.sigma_hit_m);
  const float inv2s2 = 1.0f / (2.0f * options_.sigma_hit_m * options_.sigma_hit_m);
  const float lf_inv2s2 = 1.0f / (2.0f * options_.lf_sigma_m * options_.lf_sigma_m);
  const float lf_norm = 1.0f / (std::sqrt(2.0f * kPi) * options_.lf_sigma_m);
  double best = -1e300;
  for (std::size_t i = b; i < e; ++i) {
    Particle& p = particles_[i];
    // A particle inside an obstacle or off the map is impossible.
    const std::uint8_t occ = map_.occupancy_at(p.x, p.y);
    float lw = 0.0f;
    if (occ != 0) {
      lw = options_.min_beam_log_likelihood * static_cast<float>(num_beams_) * 2.0f;
    } else if (options_.model == SensorModel::kBeam) {
      for (std::size_t k = 0; k < num_beams_; ++k) {
        const float z = beams_[k].range;
        const float zs = map_.raycast(p.x, p.y, p.theta + beams_[k].angle, maxr);
        float prob = inv_rand;
        if (z >= maxr) {
          prob += options_.z_max;
        } else {
          const float d = z - zs;
          prob += options_.z_hit * norm_hit * std::exp(-d * d * inv2s2);
          if (z < zs) {
            const float l = options_.lambda_short;
            prob += options_.z_short * l * std::exp(-l * z) / (1.0f - std::exp(-l * zs) + 1e-6f);
          }
        }
        float l = std::log(prob);
        lw += l < options_.min_beam_log_likelihood ? options_.min_beam_log_likelihood : l;
      }
    } else {
      const float c = std::cos(p.theta), s = std::sin(p.theta);
      for (std::size_t k = 0; k < num_beams_; ++k) {
        const float z = beams_[k].range;
        if (z >= maxr) continue;  // max readings carry no information in the field model
        const float lx = z * std::cos(beams_[k].angle), ly = z * std::sin(beams_[k].angle);
        const float d = map_.distance_at(p.x + c * lx - s * ly, p.y + s * lx + c * ly, 3.0f * options_.lf_sigma_m + 1.0f);
        const float prob = options_.z_hit * lf_norm * std::exp(-d * d * lf_inv2s2) + inv_rand;
        float l = std::log(prob);
        lw += l < options_.min_beam_log_likelihood ? options_.min_beam_log_likelihood : l;
      }
    }
    p.step_lw = lw;
    p.log_w += lw;
    if (p.log_w > best) best = p.log_w;
  }
  chunk_max_[chunk] = best;
}

std::uint32_t Mcl::kld_bound(std::uint32_t k) const {
  // Fox 2003: n = (k−1)/(2ε) · (1 − 2/(9(k−1)) + √(2/(9(k−1))) z)³
  if (k <= 1) return options_.kld_min_particles;
  const double km1 = k - 1.0;
  const double a = 2.0 / (9.0 * km1);
  const double c = 1.0 - a + std::sqrt(a) * options_.kld_z;
  double n = km1 / (2.0 * options_.kld_epsilon) * c * c * c;
  if (n < options_.kld_min_particles) n = options_.kld_min_particles;
  if (n > options_.num_particles) n = options_.num_particles;
  return static_cast<std::uint32_t>(n);
}

// Low-variance resampling (Table 4.4); with KLD-sampling the sample count adapts to the number of
// occupied histogram bins; with injection, random particles replace draws with prob 1 − w_fast/w_slow.
void Mcl::resample(MclStepResult* out) {
  // Weights were normalised into cdf_ (cumulative, last = 1).
  const float inject_p = options_.random_injection && w_slow_ > 0.0f
                             ? (1.0f - w_fast_ / w_slow_ > 0.0f ? 1.0f - w_fast_ / w_slow_ : 0.0f)
                             : 0.0f;
  std::size_t target = n_;
  if (options_.kld_sampling) target = options_.num_particles;
  std::size_t m = 0;
  const double step = 1.0 / static_cast<double>(target);
  double u = main_rng_.uniform01() * step;
  std::size_t idx = 0;
  std::uint32_t bins = 0;
  const std::size_t table = 2 * kMaxParticles;
  if (options_.kld_sampling) {
    for (std::size_t i = 0; i < table; ++i) kld_keys_[i] = 0;
  }
  std::uint32_t injected = 0;
  std::size_t needed = target;
  while (m < target && m < needed) {
    Particle np;
    if (inject_p > 0.0f && main_rng_.uniform01f() < inject_p) {
      if (!sample_free(&main_rng_, &np).is_ok()) np = particles_[0];
      ++injected;
    } else {
      while (idx + 1 < n_ && cdf_[idx] < u) ++idx;
      np = particles_[idx];
      u += step;
      if (u > 1.0) u -= 1.0, idx = 0;
    }
    np.log_w = 0.0f;
    scratch_[m++] = np;
    if (options_.kld_sampling) {
      const std::int64_t bx = static_cast<std::int64_t>(std::floor(np.x / options_.kld_bin_xy_m));
      const std::int64_t by = static_cast<std::int64_t>(std::floor(np.y / options_.kld_bin_xy_m));
      const std::int64_t bt = static_cast<std::int64_t>(std::floor((np.theta + kPi) / options_.kld_bin_theta_rad));
      const std::uint64_t key = ((static_cast<std::uint64_t>(bx & 0xFFFFF) << 40) |
                                 (static_cast<std::uint64_t>(by & 0xFFFFF) << 20) |
                                 static_cast<std::uint64_t>(bt & 0xFFFFF)) + 1;  // 0 = empty slot
      std::size_t h = static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> 20) % table;
      while (kld_keys_[h] != 0 && kld_keys_[h] != key) h = (h + 1) % table;
      if (kld_keys_[h] == 0) {
        kld_keys_[h] = key;
        ++bins;
        needed = kld_bound(bins);
      }
    }
  }
  for (std::size_t i = 0; i < m; ++i) particles_[i] = scratch_[i];
  n_ = m;
  ++resamples_;
  out->resampled = true;
  out->injected = injected;
}

void Mcl::estimate(std::size_t best, MclStepResult* out) const {
  const Particle& pb = particles_[best];
  const float r2 = options_.estimate_radius_m * options_.estimate_radius_m;
  double sw = 0, sx = 0, sy = 0, ss = 0, sc = 0;
  for (std::size_t i = 0; i < n_; ++i) {
    const Particle& p = particles_[i];
    const float dx = p.x - pb.x, dy = p.y - pb.y;
    if (dx * dx + dy * dy > r2) continue;
    const double w = (i == 0 ? cdf_[0] : cdf_[i] - cdf_[i - 1]);
    sw += w;
    sx += w * p.x;
    sy += w * p.y;
    ss += w * std::sin(p.theta);
    sc += w * std::cos(p.theta);
  }
  out->mass_near_best = static_cast<float>(sw);
  if (sw <= 0.0) { out->pose = Se2f(pb.x, pb.y, pb.theta); return; }
  const double mx = sx / sw, my = sy / sw, mt = std::atan2(ss, sc);
  double cxx = 0, cyy = 0, cxy = 0, ctt = 0;
  for (std::size_t i = 0; i < n_; ++i) {
    const Particle& p = particles_[i];
    const float dx = p.x - pb.x, dy = p.y - pb.y;
    if (dx * dx + dy * dy > r2) continue;
    const double w = (i == 0 ? cdf_[0] : cdf_[i] - cdf_[i - 1]) / sw;
    const double ex = p.x - mx, ey = p.y - my, et = wrap_angle(p.theta - mt);
    cxx += w * ex * ex;
    cyy += w * ey * ey;
    cxy += w * ex * ey;
    ctt += w * et * et;
  }
  out->pose = Se2f(static_cast<float>(mx), static_cast<float>(my), static_cast<float>(mt));
  out->cov << static_cast<float>(cxx), static_cast<float>(cxy), 0.0f, static_cast<float>(cxy),
      static_cast<float>(cyy), 0.0f, 0.0f, 0.0f, static_cast<float>(ctt);
}

Status Mcl::step(const hal::LaserScan& scan, const Se2f& odom_delta, bool have_delta, MclStepResult* out) {
  if (!initialized_ || n_ == 0) return Status::error(Errc::kNotInitialized, "Mcl: step() before init/init_uniform");
  if (out == nullptr) return Status::error(Errc::kInvalidArgument, "Mcl: null result");
  if (scan.beam_count == 0 || scan.beam_count > hal::LaserScan::kMaxBeams || !std::isfinite(scan.angle_min) ||
      !std::isfinite(scan.angle_increment)) {
    return Status::error(Errc::kInvalidArgument, "Mcl: scan %u has a malformed header (beam_count %u)", scan.scan_id,
                         scan.beam_count);
  }
  if (have_delta && (!std::isfinite(odom_delta.x) || !std::isfinite(odom_delta.y) || !std::isfinite(odom_delta.theta))) {
    return Status::error(Errc::kInvalidArgument, "Mcl: non-finite odometry delta at scan %u", scan.scan_id);
  }
  *out = MclStepResult();
  // Select num_beams evenly spread beams; invalid readings (NaN, < min) are skipped, "no return"
  // readings become max-range readings.
  num_beams_ = 0;
  const float maxr = options_.max_range_m;
  for (std::uint32_t k = 0; k < options_.num_beams; ++k) {
    const std::uint32_t i = static_cast<std::uint32_t>((static_cast<std::uint64_t>(k) * 2 + 1) * scan.beam_count /
                                                       (2ull * options_.num_beams));
    float r = scan.ranges[i];
    if (!std::isfinite(r) && !(r > 0.0f)) continue;  // NaN / −inf
    if (r < scan.range_min) continue;
    if (r >= scan.range_max || r >= maxr || std::isinf(r)) r = maxr;
    beams_[num_beams_++] = Beam{r, scan.angle_min + scan.angle_increment * static_cast<float>(i)};
  }

  ++step_count_;
  ++updates_;
  delta_ = odom_delta;
  if (have_delta) run_chunks(&Mcl::motion_job);
  run_chunks(&Mcl::weight_job);

  // Normalise (merge chunk maxima in chunk order).
  double lmax = -1e300;
  for (std::size_t c = 0; c < kChunks; ++c) {
    std::size_t b, e;
    chunk_range(c, &b, &e);
    if (b < e && chunk_max_[c] > lmax) lmax = chunk_max_[c];
  }
  double sum = 0.0, sum_lw = 0.0;
  std::size_t best = 0;
  double best_w = -1.0;
  for (std::size_t i = 0; i < n_; ++i) {
    const double w = std::exp(static_cast<double>(particles_[i].log_w) - lmax);
    sum += w;
    cdf_[i] = sum;
    sum_lw += w * particles_[i].step_lw;
    particles_[i].log_w = static_cast<float>(particles_[i].log_w - lmax);
    if (w > best_w) { best_w = w; best = i; }
  }
  double sq = 0.0;
  for (std::size_t i = 0; i < n_; ++i) {
    const double w = (i == 0 ? cdf_[0] : cdf_[i] - cdf_[i - 1]) / sum;
    sq += w * w;
  }
  for (std::size_t i = 0; i < n_; ++i) cdf_[i] /= sum;
  cdf_[n_ - 1] = 1.0;
  out->neff = static_cast<float>(1.0 / sq);
  out->mean_beam_log_likelihood = num_beams_ > 0 ? static_cast<float>(sum_lw / sum / num_beams_) : 0.0f;
  // Augmented MCL (Table 8.3): averages of the per-beam geometric-mean likelihood.
  const float w_avg = num_beams_ > 0 ? std::exp(out->mean_beam_log_likelihood) : 0.0f;
  if (w_slow_ == 0.0f) {
    w_slow_ = w_fast_ = w_avg;
  } else {
    w_slow_ += options_.alpha_slow * (w_avg - w_slow_);
    w_fast_ += options_.alpha_fast * (w_avg - w_fast_);
  }

  estimate(best, out);

  // The thesis's localization constraint: variance of ‖x_best − g(x_best,prev, u)‖ over τ steps.
  const Se2f best_pose(particles_[best].x, particles_[best].y, particles_[best].theta);
  if (have_best_prev_ && have_delta) {
    const Se2f pred = best_prev_.compose(odom_delta);
    const float dx = best_pose.x - pred.x, dy = best_pose.y - pred.y;
    if (best_dist_.size() >= options_.tau) { float d; best_dist_.pop(&d); }
    best_dist_.push_overwrite(std::sqrt(dx * dx + dy * dy));
  }
  best_prev_ = best_pose;
  have_best_prev_ = true;
  if (best_dist_.size() >= options_.tau) {
    double m = 0.0;
    for (std::size_t i = 0; i < best_dist_.size(); ++i) m += best_dist_[i];
    m /= best_dist_.size();
    double v = 0.0;
    for (std::size_t i = 0; i < best_dist_.size(); ++i) v += (best_dist_[i] - m) * (best_dist_[i] - m);
    v /= best_dist_.size();
    out->best_distance_var = static_cast<float>(v);
    out->localized = v < options_.localized_variance_m2 && m < options_.localized_mean_m &&
                     out->mass_near_best >= options_.localized_min_mass;
  }

  if (out->neff < options_.resample_neff_ratio * static_cast<float>(n_) || options_.kld_sampling ||
      options_.resample_neff_ratio >= 1.0f) {
    resample(out);
  }
  out->particles = static_cast<std::uint32_t>(n_);
  return Status::ok();
}

}  // namespace mcl
}  // namespace fw
