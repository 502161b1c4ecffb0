#include "sim/world/ray_cast.h"

#include <cmath>
#include <limits>

namespace sim {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
}  // namespace

double ray_segment_distance(const Vec2& origin, const Vec2& dir, const Segment& s) {
  const Vec2 e = s.b - s.a;
  const double denom = cross(dir, e);
  if (std::fabs(denom) < 1e-12) return kInf;  // parallel (grazing a collinear wall is no return)
  const Vec2 w = s.a - origin;
  const double t = cross(w, e) / denom;    // along the ray
  const double u = cross(w, dir) / denom;  // along the segment
  if (t <= 1e-9 || u < 0.0 || u > 1.0) return kInf;
  return t;
}

double ray_circle_distance(const Vec2& origin, const Vec2& dir, const Vec2& centre, double radius) {
  const Vec2 m = origin - centre;
  const double c = m.squaredNorm() - radius * radius;
  if (c <= 0) return kInf;  // inside the person: the scanner is never inside an obstacle
  const double b = m.dot(dir);
  if (b > 0) return kInf;  // pointing away
  const double disc = b * b - c;
  if (disc < 0) return kInf;
  return -b - std::sqrt(disc);
}

RayHit cast_ray(const World& world, const Vec2& origin, double angle, double max_range, double t_s,
                bool include_people) {
  const Vec2 dir(std::cos(angle), std::sin(angle));
  double best = kInf;
  bool person = false;
  for (const Segment& s : world.walls) {
    const double d = ray_segment_distance(origin, dir, s);
    if (d < best) best = d;
  }
  if (include_people) {
    for (const Person& p : world.people) {
      const double d = ray_circle_distance(origin, dir, person_position(p, t_s), p.radius);
      if (d < best) {
        best = d;
        person = true;
      }
    }
  }
  RayHit h;
  if (best <= max_range) {
    h.hit = true;
    h.range = best;
    h.person = person;
  } else {
    h.range = max_range;
  }
  return h;
}

}  // namespace sim
