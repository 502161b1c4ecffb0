// Tiny synthetic worlds (line segments) and an exact ray caster for the matcher tests.
#pragma once

#include <cmath>
#include <vector>

#include "firmware/base/se2.h"
#include "firmware/scan/scan_points.h"

namespace rbsm_test {

struct Segment {
  float x0, y0, x1, y1;
};

inline std::vector<Segment> box(float x0, float y0, float x1, float y1) {
  return {{x0, y0, x1, y0}, {x1, y0, x1, y1}, {x1, y1, x0, y1}, {x0, y1, x0, y0}};
}

// 361 beams over 180° (SICK LMS 200 at 0.5°), sensor-frame points of the first hits within max_range.
inline std::vector<fw::Point2f> cast_scan(const std::vector<Segment>& world, const fw::Se2f& pose,
                                          int beams = 361, float max_range = 8.0f) {
  std::vector<fw::Point2f> pts;
  for (int i = 0; i < beams; ++i) {
    const double a = -M_PI / 2 + M_PI * i / (beams - 1);
    const double ga = pose.theta + a;
    const double dx = std::cos(ga), dy = std::sin(ga);
    double best = max_range;
    for (const Segment& s : world) {
      const double ex = s.x1 - s.x0, ey = s.y1 - s.y0;
      const double den = dx * ey - dy * ex;
      if (std::fabs(den) < 1e-12) continue;
      const double qx = s.x0 - pose.x, qy = s.y0 - pose.y;
      const double t = (qx * ey - qy * ex) / den;   // along the ray
      const double u = (qx * dy - qy * dx) / den;   // along the segment
      if (t > 1e-6 && u >= 0.0 && u <= 1.0 && t < best) best = t;
    }
    if (best < max_range) pts.emplace_back(static_cast<float>(best * std::cos(a)), static_cast<float>(best * std::sin(a)));
  }
  return pts;
}

inline std::vector<Segment> corridor_world() {
  // 2 m wide, 10 m long corridor with closed ends and a door recess.
  std::vector<Segment> w = {{-5, -1, 5, -1}, {-5, 1, 2, 1}, {3, 1, 5, 1}, {2, 1, 2, 1.8f}, {3, 1, 3, 1.8f},
                            {2, 1.8f, 3, 1.8f}, {-5, -1, -5, 1}, {5, -1, 5, 1}};
  return w;
}
inline std::vector<Segment> l_corner_world() {
  // An L-shaped hallway: east arm 8 m, north arm 8 m, 2 m wide.
  return {{-2, -1, 6, -1}, {6, -1, 6, 7}, {6, 7, 4, 7}, {4, 7, 4, 1}, {4, 1, -2, 1}, {-2, 1, -2, -1}};
}
inline std::vector<Segment> room_world() {
  std::vector<Segment> w = box(-3, -2, 4, 3);
  const std::vector<Segment> b = box(1, 0.5f, 1.8f, 1.2f);  // a cabinet
  w.insert(w.end(), b.begin(), b.end());
  w.push_back({-3, 1.5f, -2, 1.5f});  // a shelf
  return w;
}

}  // namespace rbsm_test
