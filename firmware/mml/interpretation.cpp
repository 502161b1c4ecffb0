#include "firmware/mml/interpretation.h"

#include <Eigen/LU>
#include <cmath>

namespace fw {
namespace mml {
namespace {

constexpr float kDeg = 3.14159265358979f / 180.0f;

// Median of a small array (insertion sort on a copy; n ≤ kMaxMedianWindow).
float median_of(const float* v, std::size_t n) {
  float tmp[kMaxMedianWindow];
  for (std::size_t i = 0; i < n; ++i) {
    float x = v[i];
    std::size_t j = i;
    while (j > 0 && tmp[j - 1] > x) { tmp[j] = tmp[j - 1]; --j; }
    tmp[j] = x;
  }
  if (n == 0) return 0.0f;
  return (n % 2 == 1) ? tmp[n / 2] : 0.5f * (tmp[n / 2 - 1] + tmp[n / 2]);
}

}  // namespace

Status Interpreter::init(const MmlOptions& options) {
  FW_RETURN_IF_ERROR(options.validate());
  options_ = options;
  initialized_ = true;
  reset();
  return Status::ok();
}

void Interpreter::reset() {
  num_hyps_ = 0;
  num_clusters_ = 0;
  have_prev_ = false;
  d2_window_.clear();
  step_quality_window_.clear();
  thres_window_.clear();
  omega_thres_ = options_.omega_thres0;
  soft_active_ = false;
  blind_steps_ = 0;
  consistent_streak_ = 0;
  pooled_support_ = 0;
}

float Interpreter::circular_mean(const float* angles, std::size_t n) {
  double s = 0.0, c = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    s += std::sin(angles[i]);
    c += std::cos(angles[i]);
  }
  return static_cast<float>(std::atan2(s, c));
}

// Eq. 5.1 and 5.3: keep hypotheses at or above the matching threshold whose frames are not tilted
// or flipped (a flipped 2-D frame would put the robot "under the map", Fig. 5.2b).
void Interpreter::filter(const InterpretInput& in, InterpretResult* out) {
  num_hyps_ = 0;
  for (std::size_t i = 0; i < in.count; ++i) {
    const PoseHypothesis& h = in.hypotheses[i];
    if (!std::isfinite(h.x) || !std::isfinite(h.y) || !std::isfinite(h.theta) || !std::isfinite(h.quality)) continue;
    if (std::fabs(wrap_angle(h.roll)) >= options_.filter_max_roll_rad) continue;
    if (std::fabs(wrap_angle(h.pitch)) >= options_.filter_max_pitch_rad) continue;
    if (h.quality < omega_thres_) continue;
    if (num_hyps_ == kMaxHypotheses) break;
    hyps_[num_hyps_] = h;
    hyps_[num_hyps_].theta = wrap_angle(h.theta);
    ++num_hyps_;
  }
  out->hypotheses_in = static_cast<std::uint32_t>(in.count);
  out->hypotheses_valid = static_cast<std::uint32_t>(num_hyps_);
}

void Interpreter::compute_stats(Cluster* c) const {
  const std::size_t n = c->size();
  double sx = 0, sy = 0, ss = 0, sc = 0, sq = 0;
  for (std::uint32_t i = c->begin; i < c->end; ++i) {
    sx += hyps_[i].x;
    sy += hyps_[i].y;
    ss += std::sin(hyps_[i].theta);
    sc += std::cos(hyps_[i].theta);
    sq += hyps_[i].quality;
  }
  const double mx = sx / n, my = sy / n, mt = std::atan2(ss, sc);
  double vxx = 0, vyy = 0, vxy = 0, vrr = 0;
  for (std::uint32_t i = c->begin; i < c->end; ++i) {
    const double dx = hyps_[i].x - mx, dy = hyps_[i].y - my;
    const double dt = wrap_angle(static_cast<double>(hyps_[i].theta) - mt);
    vxx += dx * dx;
    vyy += dy * dy;
    vxy += dx * dy;
    vrr += dt * dt;
  }
  c->x = static_cast<float>(mx);
  c->y = static_cast<float>(my);
  c->theta = static_cast<float>(mt);
  c->sxx = static_cast<float>(vxx / n);
  c->syy = static_cast<float>(vyy / n);
  c->sxy = static_cast<float>(vxy / n);
  c->srr = static_cast<float>(vrr / n);
  c->mean_quality = static_cast<float>(sq / n);
}

// 2-means split of one cluster (one level of the hierarchical K-means, Sec. 5.3.1), either in the
// translation plane or in θ. Seeds: the member farthest from the mean and the member farthest
// from that one. The range is partitioned in place: [begin, mid) and [mid, end).
bool Interpreter::split(const Cluster& c, bool by_rotation, Cluster* a, Cluster* b) {
  auto dist2 = [&](std::uint32_t i, float px, float py, float pt) -> float {
    if (by_rotation) {
      const float d = wrap_angle(hyps_[i].theta - pt);
      return d * d;
    }
    const float dx = hyps_[i].x - px, dy = hyps_[i].y - py;
    return dx * dx + dy * dy;
  };
  std::uint32_t far1 = c.begin;
  float best = -1.0f;
  for (std::uint32_t i = c.begin; i < c.end; ++i) {
    const float d = dist2(i, c.x, c.y, c.theta);
    if (d > best) { best = d; far1 = i; }
  }
  std::uint32_t far2 = c.begin;
  best = -1.0f;
  for (std::uint32_t i = c.begin; i < c.end; ++i) {
    const float d = dist2(i, hyps_[far1].x, hyps_[far1].y, hyps_[far1].theta);
    if (d > best) { best = d; far2 = i; }
  }
  if (best <= 0.0f) return false;  // all members identical in this feature
  float cx[2] = {hyps_[far1].x, hyps_[far2].x}, cy[2] = {hyps_[far1].y, hyps_[far2].y};
  float ct[2] = {hyps_[far1].theta, hyps_[far2].theta};
  std::uint32_t count[2] = {0, 0};
  for (std::uint32_t it = 0; it < options_.kmeans_iterations; ++it) {
    bool changed = false;
    for (std::uint32_t i = c.begin; i < c.end; ++i) {
      const std::uint8_t l = dist2(i, cx[1], cy[1], ct[1]) < dist2(i, cx[0], cy[0], ct[0]) ? 1 : 0;
      if (it == 0 || labels_[i] != l) changed = true;
      labels_[i] = l;
    }
    if (!changed) break;
    double sx[2] = {0, 0}, sy[2] = {0, 0}, ss[2] = {0, 0}, sc[2] = {0, 0};
    count[0] = count[1] = 0;
    for (std::uint32_t i = c.begin; i < c.end; ++i) {
      const int l = labels_[i];
      sx[l] += hyps_[i].x;
      sy[l] += hyps_[i].y;
      ss[l] += std::sin(hyps_[i].theta);
      sc[l] += std::cos(hyps_[i].theta);
      ++count[l];
    }
    for (int k = 0; k < 2; ++k) {
      if (count[k] == 0) continue;
      cx[k] = static_cast<float>(sx[k] / count[k]);
      cy[k] = static_cast<float>(sy[k] / count[k]);
      ct[k] = static_cast<float>(std::atan2(ss[k], sc[k]));
    }
  }
  // Partition in place by label (label 0 first).
  std::uint32_t lo = c.begin, hi = c.end;
  while (lo < hi) {
    if (labels_[lo] == 0) { ++lo; continue; }
    --hi;
    const PoseHypothesis th = hyps_[lo]; hyps_[lo] = hyps_[hi]; hyps_[hi] = th;
    const std::uint8_t tl = labels_[lo]; labels_[lo] = labels_[hi]; labels_[hi] = tl;
  }
  if (lo == c.begin || lo == c.end) return false;
  a->begin = c.begin; a->end = lo;
  b->begin = lo; b->end = c.end;
  return true;
}

void Interpreter::cluster_all() {
  num_clusters_ = 0;
  if (num_hyps_ == 0) return;
  const float rot_max = options_.sigma2_rot_max_deg2 * kDeg * kDeg;
  std::size_t top = 0;
  stack_[top].begin = 0;
  stack_[top].end = static_cast<std::uint32_t>(num_hyps_);
  ++top;
  while (top > 0) {
    Cluster c = stack_[--top];
    compute_stats(&c);
    const bool trans_big = c.sxx > options_.sigma2_trans_max_m2 || c.syy > options_.sigma2_trans_max_m2;
    const bool rot_big = c.srr > rot_max;
    // Room for the two halves: one on the stack, one either on the stack or in the output.
    const bool room = top + 2 <= kMaxClusters && num_clusters_ + top + 2 <= kMaxClusters;
    if ((trans_big || rot_big) && c.size() >= 2 && room) {
      Cluster a, b;
      if (split(c, /*by_rotation=*/!trans_big, &a, &b)) {
        stack_[top++] = b;
        stack_[top++] = a;
        continue;
      }
    }
    clusters_[num_clusters_++] = c;
  }
}

// Eq. 5.4–5.7.
void Interpreter::rate() {
  const float rot_max = options_.sigma2_rot_max_deg2 * kDeg * kDeg;
  double sum = 0.0;
  for (std::size_t i = 0; i < num_clusters_; ++i) {
    Cluster& c = clusters_[i];
    const float w1 = static_cast<float>(c.size()) / static_cast<float>(num_hyps_);
    float w2 = 1.0f - (c.sxx + c.syy) / (2.0f * options_.sigma2_trans_max_m2);
    float w3 = 1.0f - c.srr / rot_max;
    float w4 = c.mean_quality;
    if (options_.stretch_quality) {  // Eq. 5.5
      const float den = 1.0f - omega_thres_;
      w4 = den > 1e-6f ? (w4 - omega_thres_) / den : 1.0f;
    }
    w2 = w2 < 0.0f ? 0.0f : w2;
    w3 = w3 < 0.0f ? 0.0f : w3;
    w4 = w4 < 0.0f ? 0.0f : (w4 > 1.0f ? 1.0f : w4);
    c.rating_raw = options_.alpha[0] * w1 + options_.alpha[1] * w2 + options_.alpha[2] * w3 + options_.alpha[3] * w4;
    sum += c.rating_raw;
  }
  for (std::size_t i = 0; i < num_clusters_; ++i) {
    clusters_[i].rating = sum > 0.0 ? static_cast<float>(clusters_[i].rating_raw / sum) : 0.0f;
  }
}

// Eq. 5.18–5.21: the next matching threshold. A step without hypotheses contributes the current
// threshold, so the lower band (at least δ_l below the mean) walks the threshold down.
void Interpreter::update_threshold() {
  float step_mean = omega_thres_;
  if (num_hyps_ > 0) {
    double s = 0.0;
    for (std::size_t i = 0; i < num_hyps_; ++i) s += hyps_[i].quality;
    step_mean = static_cast<float>(s / num_hyps_);
  } else if (!options_.bollinger) {
    step_mean = 0.0f;  // the pre-Bollinger rule of [21]: a zero quality enters the queue
  }
  if (step_quality_window_.size() >= options_.tau_tr) { float d; step_quality_window_.pop(&d); }
  step_quality_window_.push_overwrite(step_mean);
  double s = 0.0;
  for (std::size_t i = 0; i < step_quality_window_.size(); ++i) s += step_quality_window_[i];
  const float thres = static_cast<float>(s / step_quality_window_.size());  // Eq. 5.18
  float next = thres;
  if (options_.bollinger) {
    if (thres_window_.size() >= options_.tau_tr) { float d; thres_window_.pop(&d); }
    thres_window_.push_overwrite(thres);
    double e = 0.0;
    for (std::size_t i = 0; i < thres_window_.size(); ++i) e += thres_window_[i];
    e /= thres_window_.size();  // Eq. 5.20
    double v = 0.0;
    for (std::size_t i = 0; i < thres_window_.size(); ++i) v += (thres_window_[i] - e) * (thres_window_[i] - e);
    const float sigma = static_cast<float>(std::sqrt(v / thres_window_.size()));  // Eq. 5.19
    float band = options_.bollinger_k * sigma;
    const float upper = options_.bollinger_delta_u * thres;
    if (band < options_.bollinger_delta_l) band = options_.bollinger_delta_l;
    if (band > upper) band = upper;
    next = thres - band;  // Eq. 5.21
  }
  if (next < options_.omega_thres_min) next = options_.omega_thres_min;
  if (next > options_.omega_thres_max) next = options_.omega_thres_max;
  omega_thres_ = next;
}

Eigen::Matrix3f Interpreter::cluster_cov(const Cluster& c) const {
  Eigen::Matrix3f p = Eigen::Matrix3f::Zero();
  const float ft = options_.hyp_sigma_trans_floor_m, fr = options_.hyp_sigma_rot_floor_rad;
  p(0, 0) = c.sxx + ft * ft;
  p(1, 1) = c.syy + ft * ft;
  p(0, 1) = p(1, 0) = c.sxy;
  p(2, 2) = c.srr + fr * fr;
  return p;
}

Status Interpreter::interpret(const InterpretInput& in, InterpretResult* out) {
  if (!initialized_) return Status::error(Errc::kNotInitialized, "mml::Interpreter: interpret() before init()");
  if (out == nullptr) return Status::error(Errc::kInvalidArgument, "mml::Interpreter: null result");
  if (in.count > 0 && in.hypotheses == nullptr) {
    return Status::error(Errc::kInvalidArgument, "mml::Interpreter: %zu hypotheses but null pointer", in.count);
  }
  *out = InterpretResult();
  const float thres_used = omega_thres_;
  filter(in, out);
  cluster_all();
  out->cluster_count = static_cast<std::uint32_t>(num_clusters_);

  // Odometry prediction x_e = x_prev ⊕ x_r with P_e (Eq. 5.8–5.10).
  PoseWithCovariance<float> pred;
  const bool can_predict = have_prev_ && in.have_odom_delta;
  if (can_predict) {
    PoseWithCovariance<float> prev, u;
    prev.pose = prev_pose_;
    prev.cov = prev_cov_;
    u.pose = in.odom_delta;
    const float dist = std::sqrt(in.odom_delta.x * in.odom_delta.x + in.odom_delta.y * in.odom_delta.y);
    const float st = options_.odom_sigma_trans_per_m * dist + options_.odom_sigma_trans_floor_m;
    const float sr = options_.odom_sigma_rot_per_rad * std::fabs(in.odom_delta.theta) +
                     options_.odom_sigma_rot_per_m * dist + options_.odom_sigma_rot_floor_rad;
    u.cov = Eigen::Matrix3f::Zero();
    u.cov(0, 0) = u.cov(1, 1) = st * st;
    u.cov(2, 2) = sr * sr;
    pred = compose_with_covariance(prev, u);
  }

  if (num_hyps_ == 0) {
    // Nothing matched. In soft mode (Eq. 5.22) dead-reckon a few steps; otherwise search on.
    update_threshold();
    out->omega_thres_next = omega_thres_;
    if (soft_active_ && can_predict && blind_steps_ < options_.soft_max_blind_steps) {
      ++blind_steps_;
      prev_pose_ = pred.pose;
      prev_cov_ = pred.cov;
      out->status = hal::LocalizationStatus::kLocalized;
      out->pose = pred.pose;
      out->cov = pred.cov;
      out->soft = true;
      out->have_pose = true;
      return Status::ok();
    }
    soft_active_ = false;
    if (!options_.keep_support_across_empty_steps) {
      consistent_streak_ = 0;
      pooled_support_ = 0;
    }
    if (can_predict) {  // keep x_prev moving with the robot so the next d² is meaningful
      prev_pose_ = pred.pose;
      prev_cov_ = pred.cov;
    }
    out->status = hal::LocalizationStatus::kSearching;
    return Status::ok();
  }
  blind_steps_ = 0;
  rate();
  std::size_t best = 0;
  for (std::size_t i = 1; i < num_clusters_; ++i) {
    if (clusters_[i].rating > clusters_[best].rating) best = i;
  }
  const Cluster& cb = clusters_[best];
  PoseWithCovariance<float> h;
  h.pose = Se2f(cb.x, cb.y, cb.theta);
  h.cov = cluster_cov(cb);
  out->best_rating = cb.rating;
  const bool rating_alone = cb.rating > options_.delta_r;
  out->c_rating = rating_alone && cb.size() >= options_.min_cluster_hypotheses;

  // Eq. 5.11–5.14.
  if (can_predict) {
    const PoseWithCovariance<float> r = between_with_covariance(pred, h);
    const Eigen::Vector3f rv(r.pose.x, r.pose.y, r.pose.theta);
    Eigen::Matrix3f rc = r.cov;
    const float det = rc.determinant();
    if (std::isfinite(det) && det > 1e-20f) {
      const float d2 = rv.dot(rc.inverse() * rv);
      out->d2 = d2;
      if (d2_window_.size() >= options_.tau_m) { float d; d2_window_.pop(&d); }
      d2_window_.push_overwrite(d2);
      out->c_mahalanobis = d2 < options_.xi_r2;
    }
  }
  // Eq. 5.15–5.16.
  if (d2_window_.size() >= options_.med_min_samples) {
    float v[kMaxMedianWindow];
    const std::size_t n = d2_window_.size();
    for (std::size_t i = 0; i < n; ++i) v[i] = d2_window_[i];
    const float dmed = median_of(v, n);
    for (std::size_t i = 0; i < n; ++i) v[i] = std::fabs(v[i] - dmed);
    out->sigma_med = median_of(v, n);
    out->c_median = out->sigma_med < options_.xi_med;
  }
  consistent_streak_ = out->c_mahalanobis && out->c_median ? consistent_streak_ + 1 : 0;
  // Extension (pooled support): the Bollinger threshold (Eq. 5.18–5.21) settles just below the mean
  // quality of what it lets through, so once converged each step passes only 1–3 hypotheses and a
  // cluster never reaches min_cluster_hypotheses in one step (fr079: the right cluster alone, rated
  // 1.0 and consistent with the odometry for 100 steps, never localized). Each step's pRANSAM run
  // is an independent draw, so the members of the best cluster are pooled over the current run of
  // consecutive steps in which it was alone above δ_r and consistent (d², σ_med): a step with a
  // rival rated higher than 1 − δ_r, an inconsistent step or a step without hypotheses starts the
  // pool again. Off: the members of one step must reach the minimum alone.
  if (options_.pool_cluster_support && rating_alone && out->c_mahalanobis && out->c_median) {
    pooled_support_ += static_cast<std::uint32_t>(cb.size());
  } else if (options_.pool_cluster_support && options_.keep_support_across_contested_steps && out->c_mahalanobis &&
             out->c_median) {
    // Contested but consistent: the step adds nothing and takes nothing (MmlOptions).
  } else {
    pooled_support_ = 0;
  }
  out->pooled_support = pooled_support_;
  if (options_.pool_cluster_support && rating_alone && pooled_support_ >= options_.min_cluster_hypotheses) {
    out->c_rating = true;
  }
  const bool hard = out->c_rating && out->c_mahalanobis && out->c_median;  // Eq. 5.17
  // Extension: entering `localized` (not in soft mode) needs the consistency part of Eq. 5.17
  // (d² and σ_med) in `confirm_steps` consecutive steps, the rating in the last one. σ_med
  // (Eq. 5.16) is a median: right after a jump, a wrong cluster tracked for half of the τ_m window
  // passes it, and one lucky rating localized it (aces: 3.6 m off along a corridor).
  bool localized = hard && (soft_active_ || consistent_streak_ >= options_.confirm_steps);
  if (!hard && soft_active_) {  // Eq. 5.22
    localized = out->c_rating || (out->c_mahalanobis && out->c_median);
    out->soft = localized;
  }
  soft_active_ = localized && options_.soft_rule;

  prev_pose_ = h.pose;
  prev_cov_ = h.cov;
  have_prev_ = true;

  out->pose = h.pose;
  out->cov = h.cov;
  out->have_pose = true;
  out->status = localized ? hal::LocalizationStatus::kLocalized : hal::LocalizationStatus::kAmbiguous;
  (void)thres_used;
  update_threshold();
  out->omega_thres_next = omega_thres_;
  return Status::ok();
}

void Interpreter::report_unknown(float omega_prime, std::uint32_t observations, InterpretResult* out) {
  out->omega_unknown = omega_prime;
  if (!options_.detect_unknown || observations < options_.tau_up) return;
  if (omega_prime < options_.outside_map_contact) {
    out->status = hal::LocalizationStatus::kOutsideMap;
    soft_active_ = false;
  }
}

}  // namespace mml
}  // namespace fw
