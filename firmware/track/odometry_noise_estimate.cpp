#include "firmware/track/odometry_noise_estimate.h"

#include <cmath>

namespace fw {
namespace track {

float chi2_lower_quantile(float k, float z) {
  const float a = 2.0f / (9.0f * k);
  const float c = 1.0f - a + z * std::sqrt(a);
  return c > 0.0f ? k * c * c * c : 0.0f;
}

void OdometryNoiseEstimate::configure(std::uint32_t window, std::uint32_t min_samples, float min_scale,
                                      float max_scale, float risk) {
  window_ = window > kMaxWindow ? kMaxWindow : window;
  min_samples_ = min_samples < 2 ? 2 : min_samples;
  min_scale_ = min_scale;
  max_scale_ = max_scale;
  // One-sided normal quantile of the risk (Abramowitz–Stegun 26.2.23, |error| < 4.5e-4).
  const float p = risk > 0.0f && risk < 0.5f ? risk : 1e-3f;
  const float t = std::sqrt(-2.0f * std::log(p));
  z_ = t - (2.515517f + 0.802853f * t + 0.010328f * t * t) / (1.0f + 1.432788f * t + 0.189269f * t * t + 0.001308f * t * t * t);
  clear();
}

void OdometryNoiseEstimate::clear() {
  trans_ = Ring();
  rot_ = Ring();
  scale_ = OdometryNoiseScale();
}

void OdometryNoiseEstimate::push(Ring* r, float ratio) {
  if (window_ == 0 || !std::isfinite(ratio) || ratio < 0.0f) return;
  r->ratio[r->next] = ratio;
  r->next = (r->next + 1) % window_;
  if (r->count < window_) ++r->count;
}

void OdometryNoiseEstimate::add_translation(float residual_sq, float model_var) {
  if (model_var > 0.0f) push(&trans_, residual_sq / model_var);
  update();
}

void OdometryNoiseEstimate::add_rotation(float residual_sq, float model_var) {
  if (model_var > 0.0f) push(&rot_, residual_sq / model_var);
  update();
}

// Σ r²/v ~ s²·χ²(dof·n) if the wheels follow the model scaled by s: s² ≤ Σ / χ²_risk(dof·n).
// Summed over the ring in index order every time (no running sum: the same samples, the same bits).
float OdometryNoiseEstimate::bound(const Ring& r, float dof_per_sample) const {
  if (window_ == 0 || r.count < min_samples_) return 1.0f;
  float sum = 0.0f;
  for (std::uint32_t i = 0; i < r.count; ++i) sum += r.ratio[i];
  const float q = chi2_lower_quantile(dof_per_sample * static_cast<float>(r.count), -z_);
  if (!(q > 0.0f)) return max_scale_;
  const float s = std::sqrt(sum / q);
  return std::fmin(std::fmax(s, min_scale_), max_scale_);
}

void OdometryNoiseEstimate::update() {
  scale_.trans = bound(trans_, 2.0f);
  scale_.rot = bound(rot_, 1.0f);
  scale_.trans_samples = trans_.count;
  scale_.rot_samples = rot_.count;
}

}  // namespace track
}  // namespace fw
