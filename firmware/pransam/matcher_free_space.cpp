// Free-space test of a hypothesis: the share of scene beams that would pass through the model.
#include "firmware/pransam/matcher.h"

#include <cmath>

namespace fw::pransam {

template <int D>
float Matcher<D>::blocked_fraction(const Hypothesis<D>& h) const {
  Point<D> sensor;
  for (int a = 0; a < D; ++a) sensor(a) = params_.scene_sensor[a];
  const Point<D> origin = h.apply(sensor);  // the sensor (A's origin unless given) in B
  const float res = field_.options().resolution;
  const float block = params_.free_space_block_radius > 0.0f ? params_.free_space_block_radius : 0.5f * res;
  std::uint32_t blocked_n = 0;
  for (std::uint32_t i = 0; i < scene_n_; ++i) {
    const Point<D> p = h.rotation * scene_[i] + h.translation;
    const Point<D> ray = p - origin;
    const float len = ray.norm();
    const float free_len = len - params_.free_space_margin;
    if (!(free_len > 0.0f)) continue;
    // Sphere tracing on B's distance field: a step never jumps over a point of B; the beam is
    // blocked when it enters a cell that holds a point of B.
    const Point<D> dir = ray / len;
    // Start where the beam enters the field's box (a 3-D sensor usually sees B from outside it).
    float s = 0.0f, s_exit = free_len;
    for (int a = 0; a < D; ++a) {
      const float lo = field_.origin()(a), hi = lo + static_cast<float>(field_.dim(a)) * res;
      if (dir(a) == 0.0f) {
        if (origin(a) < lo || origin(a) > hi) s = s_exit + 1.0f;  // parallel outside: never enters
        continue;
      }
      float t0 = (lo - origin(a)) / dir(a), t1 = (hi - origin(a)) / dir(a);
      if (t0 > t1) { const float tmp = t0; t0 = t1; t1 = tmp; }
      if (t0 > s) s = t0;
      if (t1 < s_exit) s_exit = t1;
    }
    while (s < s_exit) {
      const float d = field_.distance(origin + dir * s);
      if (!(d < 1e30f)) break;  // left the field: free
      if (d < block) { ++blocked_n; break; }
      s += d - 0.75f * res > 0.5f * res ? d - 0.75f * res : 0.5f * res;
    }
  }
  return static_cast<float>(blocked_n) / static_cast<float>(scene_n_);
}

template float Matcher<2>::blocked_fraction(const Hypothesis<2>& h) const;
template float Matcher<3>::blocked_fraction(const Hypothesis<3>& h) const;

}  // namespace fw::pransam
