#include "sim/world/ray_cast.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sim {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// RayNearest distances along a ray by kind of surface; the hit is assembled the same way for the
// brute-force and the indexed cast so that both answer bit for bit alike.
struct RayNearest {
  double wall = kInf, glass = kInf, person = kInf;
};

void add_people_hits(const World& world, const Vec2& origin, const Vec2& dir, double t_s, RayNearest* n) {
  for (const Person& p : world.people) {
    n->person = std::min(n->person, ray_circle_distance(origin, dir, person_position(p, t_s), p.radius));
  }
}

RayHit assemble_hit(const RayNearest& n, double max_range) {
  // A person counts only when strictly nearer than every wall (as the loop over walls, then people,
  // always did); glass only when strictly nearer than walls and people.
  const bool person = n.person < n.wall;
  const double first = person ? n.person : n.wall;
  RayHit h;
  h.range = max_range;
  if (n.glass < first && n.glass <= max_range) {
    h.hit = h.glass = true;
    h.range = n.glass;
    if (first <= max_range) {
      h.behind_hit = true;
      h.behind_range = first;
    }
  } else if (first <= max_range) {
    h.hit = true;
    h.range = first;
    h.person = person;
  }
  return h;
}
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

RayHit cast_ray_brute_force(const World& world, const Vec2& origin, double angle, double max_range, double t_s,
                            bool include_people) {
  const Vec2 dir(std::cos(angle), std::sin(angle));
  RayNearest n;
  for (const Segment& s : world.walls) n.wall = std::min(n.wall, ray_segment_distance(origin, dir, s));
  for (const Segment& s : world.glass) n.glass = std::min(n.glass, ray_segment_distance(origin, dir, s));
  if (include_people) add_people_hits(world, origin, dir, t_s, &n);
  return assemble_hit(n, max_range);
}

WorldIndex::WorldIndex(const World& world, double cell_m) {
  wall_count = world.walls.size();
  glass_count = world.glass.size();
  const std::size_t total = wall_count + glass_count;
  if (total == 0) {
    cell_start.assign(1, 0);
    return;
  }
  auto seg = [&](std::size_t id) -> const Segment& {
    return id < wall_count ? world.walls[id] : world.glass[id - wall_count];
  };
  constexpr double kPad = 1e-6;  // a segment is listed in every cell it passes within 1 µm of
  double xa = kInf, ya = kInf, xb = -kInf, yb = -kInf;
  for (std::size_t i = 0; i < total; ++i) {
    for (const Vec2& p : {seg(i).a, seg(i).b}) {
      xa = std::min(xa, p.x());
      ya = std::min(ya, p.y());
      xb = std::max(xb, p.x());
      yb = std::max(yb, p.y());
    }
  }
  // At most 1024 cells a side: a huge world gets coarser cells rather than a huge grid.
  cell = std::max({cell_m, (xb - xa) / 1000.0, (yb - ya) / 1000.0});
  x0 = xa - 2 * kPad;
  y0 = ya - 2 * kPad;
  nx = static_cast<int>(std::floor((xb + 2 * kPad - x0) / cell)) + 1;
  ny = static_cast<int>(std::floor((yb + 2 * kPad - y0) / cell)) + 1;
  // Cells of one segment, row by row: the x extent of the segment within each row's band.
  auto for_cells = [&](const Segment& s, auto&& visit) {
    const Vec2 d = s.b - s.a;
    const int r0 = std::max(0, static_cast<int>(std::floor((std::min(s.a.y(), s.b.y()) - kPad - y0) / cell)));
    const int r1 = std::min(ny - 1, static_cast<int>(std::floor((std::max(s.a.y(), s.b.y()) + kPad - y0) / cell)));
    for (int r = r0; r <= r1; ++r) {
      double ua = 0, ub = 1;
      if (std::fabs(d.y()) > 1e-12) {
        const double va = (y0 + r * cell - kPad - s.a.y()) / d.y(), vb = (y0 + (r + 1) * cell + kPad - s.a.y()) / d.y();
        ua = std::clamp(std::min(va, vb), 0.0, 1.0);
        ub = std::clamp(std::max(va, vb), 0.0, 1.0);
      }
      const double xs0 = s.a.x() + ua * d.x(), xs1 = s.a.x() + ub * d.x();
      const int c0 = std::max(0, static_cast<int>(std::floor((std::min(xs0, xs1) - kPad - x0) / cell)));
      const int c1 = std::min(nx - 1, static_cast<int>(std::floor((std::max(xs0, xs1) + kPad - x0) / cell)));
      for (int c = c0; c <= c1; ++c) visit(r * nx + c);
    }
  };
  std::vector<int> count(static_cast<std::size_t>(nx) * ny + 1, 0);
  for (std::size_t i = 0; i < total; ++i) for_cells(seg(i), [&](int c) { ++count[c + 1]; });
  cell_start.assign(count.size(), 0);
  for (std::size_t c = 1; c < count.size(); ++c) cell_start[c] = cell_start[c - 1] + count[c];
  ids.assign(static_cast<std::size_t>(cell_start.back()), 0);
  std::vector<int> fill(cell_start.begin(), cell_start.end() - 1);
  for (std::size_t i = 0; i < total; ++i) for_cells(seg(i), [&](int c) { ids[fill[c]++] = static_cast<int>(i); });
}

RayHit cast_ray(const World& world, const WorldIndex& index, const Vec2& origin, double angle, double max_range,
                double t_s, bool include_people) {
  const Vec2 dir(std::cos(angle), std::sin(angle));
  RayNearest n;
  // Clip the ray to the grid's box (slabs); a ray that misses it meets no wall.
  const double gx1 = index.x0 + index.nx * index.cell, gy1 = index.y0 + index.ny * index.cell;
  double t0 = 0, t1 = max_range;
  const double o[2] = {origin.x(), origin.y()}, d[2] = {dir.x(), dir.y()};
  const double lo[2] = {index.x0, index.y0}, hi[2] = {gx1, gy1};
  bool misses = index.nx == 0;
  for (int k = 0; k < 2 && !misses; ++k) {
    if (d[k] == 0) {
      misses = o[k] < lo[k] || o[k] > hi[k];
      continue;
    }
    const double ta = (lo[k] - o[k]) / d[k], tb = (hi[k] - o[k]) / d[k];
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  if (!misses && t0 <= t1) {
    const Vec2 p = origin + t0 * dir;
    int ix = std::clamp(static_cast<int>(std::floor((p.x() - index.x0) / index.cell)), 0, index.nx - 1);
    int iy = std::clamp(static_cast<int>(std::floor((p.y() - index.y0) / index.cell)), 0, index.ny - 1);
    const int step_x = dir.x() > 0 ? 1 : -1, step_y = dir.y() > 0 ? 1 : -1;
    auto next_t = [&](int i, double o_k, double d_k, double g0) {
      if (d_k == 0) return kInf;
      return (g0 + (i + (d_k > 0 ? 1 : 0)) * index.cell - o_k) / d_k;
    };
    double t_x = next_t(ix, origin.x(), dir.x(), index.x0), t_y = next_t(iy, origin.y(), dir.y(), index.y0);
    const double dt_x = dir.x() == 0 ? kInf : index.cell / std::fabs(dir.x());
    const double dt_y = dir.y() == 0 ? kInf : index.cell / std::fabs(dir.y());
    for (;;) {
      const int c = iy * index.nx + ix;
      for (int k = index.cell_start[c]; k < index.cell_start[c + 1]; ++k) {
        const auto id = static_cast<std::size_t>(index.ids[k]);
        if (id < index.wall_count) {
          n.wall = std::min(n.wall, ray_segment_distance(origin, dir, world.walls[id]));
        } else {
          n.glass = std::min(n.glass, ray_segment_distance(origin, dir, world.glass[id - index.wall_count]));
        }
      }
      // Anything in a later cell lies beyond this cell's far side: stop once a wall is nearer, or
      // past the range.
      const double t_exit = std::min(t_x, t_y);
      if (n.wall <= t_exit || t_exit > max_range) break;
      if (t_x < t_y) {
        ix += step_x;
        t_x += dt_x;
      } else {
        iy += step_y;
        t_y += dt_y;
      }
      if (ix < 0 || iy < 0 || ix >= index.nx || iy >= index.ny) break;
    }
  }
  if (include_people) add_people_hits(world, origin, dir, t_s, &n);
  return assemble_hit(n, max_range);
}

RayHit cast_ray(const World& world, const Vec2& origin, double angle, double max_range, double t_s,
                bool include_people) {
  return cast_ray_brute_force(world, origin, angle, max_range, t_s, include_people);
}

}  // namespace sim
