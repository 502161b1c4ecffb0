#include "sim/world/world.h"

#include <algorithm>
#include <cmath>

namespace sim {

Vec2 person_position(const Person& p, double t) {
  if (p.path.size() < 2) return p.path.empty() ? Vec2(0, 0) : p.path.front();
  double total = 0;
  for (size_t i = 1; i < p.path.size(); ++i) total += (p.path[i] - p.path[i - 1]).norm();
  if (total <= 0) return p.path.front();
  // Ping-pong: distance along the path folded into [0, total].
  double d = std::fmod((t + p.phase_s) * p.speed, 2.0 * total);
  if (d < 0) d += 2.0 * total;
  if (d > total) d = 2.0 * total - d;
  for (size_t i = 1; i < p.path.size(); ++i) {
    const double len = (p.path[i] - p.path[i - 1]).norm();
    if (d <= len || i + 1 == p.path.size()) {
      const double s = len > 0 ? std::min(1.0, d / len) : 0.0;
      return p.path[i - 1] + s * (p.path[i] - p.path[i - 1]);
    }
    d -= len;
  }
  return p.path.back();
}

int RouteGraph::add_node(const Vec2& p, int kind) {
  for (size_t i = 0; i < nodes.size(); ++i) {
    if ((nodes[i] - p).norm() < 1e-6) return static_cast<int>(i);
  }
  nodes.push_back(p);
  kinds.push_back(kind);
  adjacent.emplace_back();
  return static_cast<int>(nodes.size() - 1);
}

void RouteGraph::connect(int a, int b) {
  if (a == b) return;
  if (std::find(adjacent[a].begin(), adjacent[a].end(), b) == adjacent[a].end()) adjacent[a].push_back(b);
  if (std::find(adjacent[b].begin(), adjacent[b].end(), a) == adjacent[b].end()) adjacent[b].push_back(a);
}

void add_segment(World* w, double x0, double y0, double x1, double y1) {
  w->walls.push_back({Vec2(x0, y0), Vec2(x1, y1)});
}

void add_rect(World* w, double x0, double y0, double x1, double y1) {
  add_segment(w, x0, y0, x1, y0);
  add_segment(w, x1, y0, x1, y1);
  add_segment(w, x1, y1, x0, y1);
  add_segment(w, x0, y1, x0, y0);
}

void add_wall_with_doors(World* w, const Vec2& from, const Vec2& to, const std::vector<double>& door_centres,
                         double door_width) {
  const Vec2 dir = to - from;
  const double len = dir.norm();
  if (len <= 0) return;
  const Vec2 u = dir / len;
  // Door centres are given as the coordinate along the wall's axis (x for horizontal walls, y for
  // vertical ones); convert them to distances from `from`.
  const bool horizontal = std::fabs(dir.x()) >= std::fabs(dir.y());
  std::vector<std::pair<double, double>> gaps;
  for (double c : door_centres) {
    const double s = horizontal ? (c - from.x()) / u.x() : (c - from.y()) / u.y();
    gaps.push_back({s - door_width / 2, s + door_width / 2});
  }
  std::sort(gaps.begin(), gaps.end());
  double s = 0;
  for (const auto& g : gaps) {
    const double a = std::max(0.0, g.first), b = std::min(len, g.second);
    if (a > s) w->walls.push_back({from + s * u, from + a * u});
    s = std::max(s, b);
  }
  if (s < len) w->walls.push_back({from + s * u, to});
}

}  // namespace sim
