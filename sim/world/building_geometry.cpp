#include "sim/world/building_geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sim::building {

namespace {
double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
}  // namespace

double point_segment_distance(const Vec2& p, const Segment& s) {
  const Vec2 e = s.b - s.a;
  const double len2 = e.squaredNorm();
  const double u = len2 > 0 ? std::clamp((p - s.a).dot(e) / len2, 0.0, 1.0) : 0.0;
  return (s.a + u * e - p).norm();
}

bool segments_intersect(const Segment& a, const Segment& b) {
  const Vec2 r = a.b - a.a, s = b.b - b.a;
  const double d1 = cross2(r, b.a - a.a), d2 = cross2(r, b.b - a.a);
  const double d3 = cross2(s, a.a - b.a), d4 = cross2(s, a.b - b.a);
  // Proper crossings only; touching and collinear cases are caught by the endpoint distances.
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

double segment_distance(const Segment& a, const Segment& b) {
  if (segments_intersect(a, b)) return 0;
  return std::min(std::min(point_segment_distance(a.a, b), point_segment_distance(a.b, b)),
                  std::min(point_segment_distance(b.a, a), point_segment_distance(b.b, a)));
}

double clearance(const Segment& edge, const std::vector<Segment>& obstacles) {
  double best = std::numeric_limits<double>::infinity();
  const double ex0 = std::min(edge.a.x(), edge.b.x()), ex1 = std::max(edge.a.x(), edge.b.x());
  const double ey0 = std::min(edge.a.y(), edge.b.y()), ey1 = std::max(edge.a.y(), edge.b.y());
  for (const Segment& s : obstacles) {
    // Bounding boxes farther apart than the best so far cannot be nearer.
    const double gx = std::max({0.0, std::min(s.a.x(), s.b.x()) - ex1, ex0 - std::max(s.a.x(), s.b.x())});
    const double gy = std::max({0.0, std::min(s.a.y(), s.b.y()) - ey1, ey0 - std::max(s.a.y(), s.b.y())});
    if (gx >= best || gy >= best) continue;
    best = std::min(best, segment_distance(edge, s));
  }
  return best;
}

bool clearance_ok(const std::vector<Segment>& outline, const std::vector<Segment>& obstacles, double gap) {
  for (const Segment& s : outline) {
    if (clearance(s, obstacles) < gap) return false;
  }
  return true;
}

std::vector<Segment> box_outline(const Vec2& centre, double sx, double sy, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const Vec2 ux(c * sx / 2, s * sx / 2), uy(-s * sy / 2, c * sy / 2);
  const Vec2 p[4] = {centre - ux - uy, centre + ux - uy, centre + ux + uy, centre - ux + uy};
  return {{p[0], p[1]}, {p[1], p[2]}, {p[2], p[3]}, {p[3], p[0]}};
}

std::vector<Segment> octagon_outline(const Vec2& centre, double r) {
  std::vector<Segment> out;
  for (int i = 0; i < 8; ++i) {
    const double a0 = i * M_PI / 4, a1 = (i + 1) * M_PI / 4;
    out.push_back({centre + r * Vec2(std::cos(a0), std::sin(a0)), centre + r * Vec2(std::cos(a1), std::sin(a1))});
  }
  return out;
}

Furniture make_furniture(std::vector<Segment> outline) {
  Furniture f;
  Vec2 sum = Vec2::Zero();
  for (const Segment& s : outline) sum += s.a;
  f.centre = outline.empty() ? sum : Vec2(sum / static_cast<double>(outline.size()));
  f.outline = std::move(outline);
  return f;
}

bool point_in_outline(const Vec2& p, const std::vector<Segment>& outline) {
  bool inside = false;
  for (const Segment& s : outline) {
    if ((s.a.y() > p.y()) != (s.b.y() > p.y())) {
      const double x = s.a.x() + (p.y() - s.a.y()) / (s.b.y() - s.a.y()) * (s.b.x() - s.a.x());
      if (x > p.x()) inside = !inside;
    }
  }
  return inside;
}

std::vector<Segment> route_edges(const RouteGraph& g) {
  std::vector<Segment> out;
  for (size_t a = 0; a < g.nodes.size(); ++a) {
    for (int b : g.adjacent[a]) {
      if (static_cast<int>(a) < b) out.push_back({g.nodes[a], g.nodes[b]});
    }
  }
  return out;
}

RouteGraph largest_component(const RouteGraph& g) {
  const int n = static_cast<int>(g.nodes.size());
  std::vector<int> comp(n, -1);
  int best = -1, best_size = 0;
  for (int s = 0, c = 0; s < n; ++s) {
    if (comp[s] >= 0) continue;
    std::vector<int> stack{s};
    comp[s] = c;
    int size = 0;
    while (!stack.empty()) {
      const int u = stack.back();
      stack.pop_back();
      ++size;
      for (int v : g.adjacent[u]) {
        if (comp[v] < 0) {
          comp[v] = c;
          stack.push_back(v);
        }
      }
    }
    if (size > best_size) {
      best_size = size;
      best = c;
    }
    ++c;
  }
  RouteGraph out;
  if (best_size < 2) return out;  // no edge left: nothing to drive on
  std::vector<int> renum(n, -1);
  for (int i = 0; i < n; ++i) {
    if (comp[i] != best) continue;
    renum[i] = static_cast<int>(out.nodes.size());
    out.nodes.push_back(g.nodes[i]);
    out.kinds.push_back(g.kinds[i]);
    out.adjacent.emplace_back();
  }
  for (int i = 0; i < n; ++i) {
    if (renum[i] < 0) continue;
    for (int v : g.adjacent[i]) out.adjacent[renum[i]].push_back(renum[v]);
  }
  return out;
}

void PlanBuilder::rect_walls(const Rect& r) {
  wall(Vec2(r.x0, r.y0), Vec2(r.x1, r.y0));
  wall(Vec2(r.x1, r.y0), Vec2(r.x1, r.y1));
  wall(Vec2(r.x1, r.y1), Vec2(r.x0, r.y1));
  wall(Vec2(r.x0, r.y1), Vec2(r.x0, r.y0));
}

void PlanBuilder::partition(const Vec2& a, const Vec2& b, bool as_glass) {
  if (as_glass) {
    plan->glass.push_back({a, b});
  } else {
    wall(a, b);
  }
}

void PlanBuilder::wall_with_doors(const Vec2& a, const Vec2& b, const std::vector<double>& door_at, bool as_glass,
                                  bool real_doors, double gap) {
  const double len = (b - a).norm();
  if (len <= 0) return;
  const Vec2 u = (b - a) / len;
  std::vector<double> at = door_at;
  std::sort(at.begin(), at.end());
  double s = 0;
  for (double c : at) {
    const double lo = std::max(0.0, c - gap / 2), hi = std::min(len, c + gap / 2);
    if (lo > s) partition(a + s * u, a + lo * u, as_glass);
    if (real_doors) {
      Door d;
      d.leaf = {a + lo * u, a + hi * u};
      d.closed = chance(opt->closed_door_fraction);
      plan->doors.push_back(d);
    }
    s = std::max(s, hi);
  }
  if (s < len) partition(a + s * u, b, as_glass);
}

void PlanBuilder::chain(std::vector<int> nodes) {
  const RouteGraph& g = plan->structure.route;
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  if (nodes.size() < 2) return;
  // The nodes lie on one axis-parallel line: order them along its longer extent.
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (int n : nodes) {
    x0 = std::min(x0, g.nodes[n].x());
    x1 = std::max(x1, g.nodes[n].x());
    y0 = std::min(y0, g.nodes[n].y());
    y1 = std::max(y1, g.nodes[n].y());
  }
  const bool along_x = x1 - x0 >= y1 - y0;
  std::stable_sort(nodes.begin(), nodes.end(), [&](int a, int b) {
    return along_x ? g.nodes[a].x() < g.nodes[b].x() : g.nodes[a].y() < g.nodes[b].y();
  });
  for (size_t i = 1; i < nodes.size(); ++i) connect(nodes[i - 1], nodes[i]);
}

bool PlanBuilder::free_for_furniture(const std::vector<Segment>& outline, const Rect& room,
                                     const std::vector<Segment>& edges, double route_gap, double margin,
                                     const std::vector<Segment>* nearby) const {
  for (const Segment& s : outline) {
    for (const Vec2& p : {s.a, s.b}) {
      if (p.x() < room.x0 + margin || p.x() > room.x1 - margin || p.y() < room.y0 + margin ||
          p.y() > room.y1 - margin) {
        return false;
      }
    }
  }
  for (const Segment& e : edges) {
    if (point_in_outline(e.a, outline) || point_in_outline(e.b, outline)) return false;
  }
  if (!clearance_ok(outline, edges, route_gap)) return false;
  if (nearby != nullptr) return clearance_ok(outline, *nearby, 0.1);
  if (!clearance_ok(outline, plan->structure.walls, 0.1) || !clearance_ok(outline, plan->glass, 0.1)) return false;
  for (const Furniture& f : plan->furniture) {
    // Clear of its outline and not standing inside it (or around it).
    if (!clearance_ok(outline, f.outline, 0.1) || point_in_outline(outline.front().a, f.outline) ||
        point_in_outline(f.outline.front().a, outline)) {
      return false;
    }
  }
  return true;
}

std::vector<Segment> PlanBuilder::obstacles_near(const Rect& r, double grow) const {
  std::vector<Segment> out;
  auto take = [&](const Segment& s) {
    if (std::max(s.a.x(), s.b.x()) >= r.x0 - grow && std::min(s.a.x(), s.b.x()) <= r.x1 + grow &&
        std::max(s.a.y(), s.b.y()) >= r.y0 - grow && std::min(s.a.y(), s.b.y()) <= r.y1 + grow) {
      out.push_back(s);
    }
  };
  for (const Segment& s : plan->structure.walls) take(s);
  for (const Segment& s : plan->glass) take(s);
  for (const Furniture& f : plan->furniture) {
    for (const Segment& s : f.outline) take(s);
  }
  return out;
}

}  // namespace sim::building
