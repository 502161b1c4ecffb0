// Synthetic scenes with known answers for pRANSAM tests and experiments (host code).
// 2-D: a walled floor plan (outer walls, inner walls, pillars) sampled as points every `spacing` m;
// the query is what a 180° laser at a known pose sees (ray cast against the same walls), so A and
// B are different point samples of the same geometry, as with a real scan vs a map.
// 3-D: a room with a bumpy ("textured") floor, walls with relief and a few boxes; two overlapping
// crops of it are the two clouds, the second moved by a known rigid transform.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "firmware/base/rng.h"
#include "firmware/base/se2.h"

namespace sim::pransam_scenes {

using P2 = Eigen::Matrix<float, 2, 1>;
using P3 = Eigen::Matrix<float, 3, 1>;

struct Segment {
  P2 a, b;
};

// N(0, σ²) in each coordinate, drawn last coordinate first: one draw per declarator, because a
// constructor's argument order is unspecified (x86-64 GCC drew the last argument first, aarch64 and
// clang the first); the order is x86-64 GCC's, with which every recorded figure was measured.
inline P3 gaussian3f(fw::RandomStream& r, float sigma) {
  const float z = r.gaussianf(0, sigma), y = r.gaussianf(0, sigma), x = r.gaussianf(0, sigma);
  return P3(x, y, z);
}

// Robot positions kept free of clutter (tests and experiments put the sensor there).
inline const std::vector<P2>& free_spots() {
  static const std::vector<P2> spots = {P2(4, 4),   P2(12, 12.5f), P2(20, 9),  P2(5, 12), P2(10, 3),
                                        P2(4, 12),  P2(12, 4),     P2(20, 13), P2(3, 7),  P2(13, 8),
                                        P2(21, 2.5f), P2(19, 14)};
  return spots;
}

inline std::vector<Segment> floor_plan(std::uint64_t seed) {
  std::vector<Segment> s;
  auto box = [&](float x0, float y0, float x1, float y1) {
    s.push_back({P2(x0, y0), P2(x1, y0)});
    s.push_back({P2(x1, y0), P2(x1, y1)});
    s.push_back({P2(x1, y1), P2(x0, y1)});
    s.push_back({P2(x0, y1), P2(x0, y0)});
  };
  box(0, 0, 24, 16);
  // Inner walls with door gaps, then seeded clutter (pillars, cabinets) to break symmetry.
  s.push_back({P2(8, 0), P2(8, 6)});
  s.push_back({P2(8, 8), P2(8, 16)});
  s.push_back({P2(16, 0), P2(16, 9)});
  s.push_back({P2(16, 11), P2(16, 16)});
  s.push_back({P2(0, 10), P2(5, 10)});
  s.push_back({P2(6.5f, 10), P2(8, 10)});
  s.push_back({P2(16, 5), P2(21, 5)});
  fw::RandomStream r(seed, 7);
  for (int i = 0; i < 28;) {
    const float x = r.uniform(1.0f, 23.0f), y = r.uniform(1.0f, 15.0f);
    const float w = r.uniform(0.3f, 1.2f), h = r.uniform(0.3f, 1.2f);
    bool clear = true;  // keep the robot spots used by tests free
    for (const P2& f : free_spots()) {
      if (f(0) > x - 1.0f && f(0) < x + w + 1.0f && f(1) > y - 1.0f && f(1) < y + h + 1.0f) clear = false;
    }
    if (!clear) continue;
    box(x, y, x + w, y + h);
    ++i;
  }
  return s;
}

inline std::vector<P2> sample_segments(const std::vector<Segment>& segs, float spacing) {
  std::vector<P2> pts;
  for (const Segment& g : segs) {
    const float len = (g.b - g.a).norm();
    const int n = std::max(1, static_cast<int>(std::floor(len / spacing)));
    for (int i = 0; i <= n; ++i) pts.push_back(g.a + (g.b - g.a) * (static_cast<float>(i) / static_cast<float>(n)));
  }
  return pts;
}

// Ray-cast scan from `pose` (181 beams over 180°), points in the sensor frame, Gaussian range noise.
inline std::vector<P2> cast_scan(const std::vector<Segment>& segs, const fw::Se2f& pose, float max_range, float sigma,
                                 fw::RandomStream& rng, int beams = 181) {
  std::vector<P2> out;
  const P2 o(pose.x, pose.y);
  for (int i = 0; i < beams; ++i) {
    const float a = -1.5707963f + 3.1415927f * static_cast<float>(i) / static_cast<float>(beams - 1);
    const P2 d(std::cos(pose.theta + a), std::sin(pose.theta + a));
    float best = max_range;
    for (const Segment& g : segs) {
      const P2 e = g.b - g.a;
      const float den = d(0) * e(1) - d(1) * e(0);
      if (std::fabs(den) < 1e-9f) continue;
      const P2 w = g.a - o;
      const float t = (w(0) * e(1) - w(1) * e(0)) / den;
      const float u = (w(0) * d(1) - w(1) * d(0)) / den;
      if (t > 0.05f && u >= 0.0f && u <= 1.0f && t < best) best = t;
    }
    if (best >= max_range) continue;
    const float r = best + sigma * static_cast<float>(rng.gaussian());
    out.push_back(P2(r * std::cos(a), r * std::sin(a)));
  }
  return out;
}

// 3-D textured room: floor and walls carry a smooth relief of ±0.3 m (the "texture" that makes the
// geometry distinctive; flat walls on a regular grid give countless congruent triangles), plus a
// few boxes. Points are drawn uniformly at random on the surfaces (`density` per m²) from `rng`,
// so two calls give two independent samplings of the same scene, like two 3-D scans.
inline std::vector<P3> textured_room(float density, fw::RandomStream& rng) {
  std::vector<P3> pts;
  const float X = 8.0f, Y = 6.0f, Z = 3.0f;
  auto floor_h = [](float x, float y) {
    return 0.25f * std::sin(1.1f * x) * std::cos(0.8f * y) + 0.1f * std::sin(2.3f * x + 1.7f * y);
  };
  auto relief = [](float u, float z, float phase) {
    return 0.2f * std::sin(1.3f * u + phase) * std::sin(1.1f * z + 0.5f * phase) + 0.08f * std::cos(2.9f * u - phase);
  };
  auto count = [&](float area) { return static_cast<int>(area * density); };
  for (int i = 0, n = count(X * Y); i < n; ++i) {
    const float x = rng.uniform(0, X), y = rng.uniform(0, Y);
    pts.push_back(P3(x, y, floor_h(x, y)));
  }
  for (int i = 0, n = count(X * Z); i < n; ++i) {
    const float u = rng.uniform(0, X), z = rng.uniform(0, Z);
    pts.push_back(P3(u, relief(u, z, 0.0f), z));
    const float u2 = rng.uniform(0, X), z2 = rng.uniform(0, Z);
    pts.push_back(P3(u2, Y + relief(u2, z2, 2.0f), z2));
  }
  for (int i = 0, n = count(Y * Z); i < n; ++i) {
    const float u = rng.uniform(0, Y), z = rng.uniform(0, Z);
    pts.push_back(P3(relief(u, z, 1.0f), u, z));
    const float u2 = rng.uniform(0, Y), z2 = rng.uniform(0, Z);
    pts.push_back(P3(X + relief(u2, z2, 3.0f), u2, z2));
  }
  // One draw per declarator: a constructor's argument order is unspecified (x86-64 GCC drew the
  // last argument first, aarch64 and clang the first); the order below is x86-64 GCC's, with
  // which every recorded figure was measured.
  auto box = [&](float x0, float y0, float x1, float y1, float h) {
    const float top = (x1 - x0) * (y1 - y0), sx = (x1 - x0) * h, sy = (y1 - y0) * h;
    for (int i = 0, n = count(top); i < n; ++i) {
      const float y = rng.uniform(y0, y1), x = rng.uniform(x0, x1);
      pts.push_back(P3(x, y, h));
    }
    for (int i = 0, n = count(sx); i < n; ++i) {
      for (const float y : {y0, y1}) {
        const float z = rng.uniform(0, h), x = rng.uniform(x0, x1);
        pts.push_back(P3(x, y, z));
      }
    }
    for (int i = 0, n = count(sy); i < n; ++i) {
      for (const float x : {x0, x1}) {
        const float z = rng.uniform(0, h), y = rng.uniform(y0, y1);
        pts.push_back(P3(x, y, z));
      }
    }
  };
  box(1.0f, 1.0f, 2.2f, 1.8f, 0.8f);
  box(5.0f, 3.5f, 5.6f, 5.2f, 1.4f);
  box(3.0f, 4.2f, 3.6f, 4.8f, 2.0f);
  box(6.4f, 0.6f, 7.4f, 1.2f, 0.5f);
  return pts;
}

// Points of `pts` inside the axis-aligned box [lo, hi].
inline std::vector<P3> crop(const std::vector<P3>& pts, const P3& lo, const P3& hi) {
  std::vector<P3> out;
  for (const P3& p : pts)
    if ((p.array() >= lo.array()).all() && (p.array() <= hi.array()).all()) out.push_back(p);
  return out;
}

}  // namespace sim::pransam_scenes
