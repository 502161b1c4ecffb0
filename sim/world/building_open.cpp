// The open families: halls / atria (a walkable grid between pillars, an atrium void behind
// balustrades, walls partly beyond a laser's range) and warehouses (long rows of identical racks
// with aisles between them).
#include <algorithm>
#include <cmath>

#include "sim/world/building_geometry.h"

namespace sim::building {

namespace {

// The bottom wall of `r`, with a 2 m opening at ex when the wing has an entrance.
void bottom_wall(PlanBuilder* b, const Rect& r, bool entrance, double ex) {
  b->wall_with_doors(Vec2(r.x0, r.y0), Vec2(r.x1, r.y0),
                     entrance ? std::vector<double>{ex - r.x0} : std::vector<double>{}, false, false, 2.0);
  b->wall(Vec2(r.x1, r.y0), Vec2(r.x1, r.y1));
  b->wall(Vec2(r.x1, r.y1), Vec2(r.x0, r.y1));
  b->wall(Vec2(r.x0, r.y1), Vec2(r.x0, r.y0));
}

// Coordinates lo + step·(k + offset) for k = 0, 1, … up to hi.
std::vector<double> grid_lines(double lo, double hi, double step, double offset) {
  std::vector<double> out;
  for (int k = 0; lo + step * (k + offset) <= hi + 1e-9; ++k) out.push_back(lo + step * (k + offset));
  return out;
}

bool inside_rect(const Rect& r, const Vec2& p, double grow) {
  return p.x() >= r.x0 - grow && p.x() <= r.x1 + grow && p.y() >= r.y0 - grow && p.y() <= r.y1 + grow;
}

// An atrium void in the middle of a large hall, behind balustrades (mostly glass: an atrium's
// balustrade is, each side glass with probability min(1, 5 × glass_fraction)). Empty when none.
Rect atrium_void(PlanBuilder* b, const Rect& r) {
  if (r.w() < 30 || r.h() < 25 || !b->chance(0.6)) return {};
  const double w = r.w() * b->uniform(0.2, 0.35), h = r.h() * b->uniform(0.2, 0.35);
  const Vec2 c = r.centre();
  const Rect v{c.x() - w / 2, c.y() - h / 2, c.x() + w / 2, c.y() + h / 2};
  const Vec2 p[4] = {Vec2(v.x0, v.y0), Vec2(v.x1, v.y0), Vec2(v.x1, v.y1), Vec2(v.x0, v.y1)};
  for (int i = 0; i < 4; ++i) {
    const bool glass = b->chance(std::min(1.0, 5 * b->opt->glass_fraction));
    b->partition(p[i], p[(i + 1) % 4], glass);
  }
  return v;
}

void hall_furniture(PlanBuilder* b, const Rect& r, const Rect& void_r) {
  const std::vector<Segment> edges = route_edges(b->plan->structure.route);
  const int items = static_cast<int>(r.w() * r.h() / 150);
  for (int i = 0; i < items; ++i) {
    const double sx = b->uniform(0.5, 2.0), sy = b->uniform(0.5, 1.2);
    const double x = b->uniform(r.x0 + 1, r.x1 - 1), y = b->uniform(r.y0 + 1, r.y1 - 1);
    const std::vector<Segment> outline = box_outline(Vec2(x, y), sx, sy);
    if (void_r.w() > 0 && inside_rect(void_r, Vec2(x, y), 1.5)) continue;
    if (b->free_for_furniture(outline, r, edges, 0.5, 0.3)) b->furniture(outline);
  }
}

}  // namespace

int build_open_hall(PlanBuilder* b, const Rect& r, bool entrance) {
  const double s = b->uniform(6.0, 9.0);
  const std::vector<double> cols = grid_lines(r.x0, r.x1 - 1.0, s, 0.5), rows = grid_lines(r.y0, r.y1 - 1.0, s, 0.5);
  const double ex = cols[b->uniform_int(0, static_cast<int>(cols.size()) - 1)];
  bottom_wall(b, r, entrance, ex);
  const Rect void_r = atrium_void(b, r);
  const bool has_void = void_r.w() > 0;
  // Pillars between the route's grid lines, all of one shape (the structure repeats).
  const bool octagon = b->chance(0.5);
  const double size = b->uniform(0.4, 0.8);
  for (double px : grid_lines(r.x0, r.x1 - 1.5, s, 1.0)) {
    for (double py : grid_lines(r.y0, r.y1 - 1.5, s, 1.0)) {
      if (has_void && inside_rect(void_r, Vec2(px, py), 0.5)) continue;
      const std::vector<Segment> pillar =
          octagon ? octagon_outline(Vec2(px, py), size / 2) : box_outline(Vec2(px, py), size, size);
      for (const Segment& seg : pillar) b->wall(seg.a, seg.b);
    }
  }
  std::vector<std::vector<int>> id(cols.size(), std::vector<int>(rows.size(), -1));
  for (size_t i = 0; i < cols.size(); ++i) {
    for (size_t j = 0; j < rows.size(); ++j) {
      const Vec2 p(cols[i], rows[j]);
      if (!(has_void && inside_rect(void_r, p, 1.0))) id[i][j] = b->node(p);
    }
  }
  const std::vector<Segment> balustrade =
      has_void ? box_outline(void_r.centre(), void_r.w(), void_r.h()) : std::vector<Segment>{};
  auto link = [&](int a, int c) {
    if (a < 0 || c < 0) return;
    const Segment e{b->plan->structure.route.nodes[a], b->plan->structure.route.nodes[c]};
    if (clearance(e, balustrade) >= 1.0) b->connect(a, c);
  };
  for (size_t i = 0; i < cols.size(); ++i) {
    for (size_t j = 0; j < rows.size(); ++j) {
      if (i + 1 < cols.size()) link(id[i][j], id[i + 1][j]);
      if (j + 1 < rows.size()) link(id[i][j], id[i][j + 1]);
    }
  }
  int door = -1;
  if (entrance) {  // linked before the furniture is placed, which keeps clear of every route edge
    const size_t col = static_cast<size_t>(std::find(cols.begin(), cols.end(), ex) - cols.begin());
    door = b->node(Vec2(ex, r.y0 + 1.0));
    if (id[col][0] >= 0) b->connect(door, id[col][0]);
  }
  hall_furniture(b, r, void_r);
  return door;
}

int build_warehouse(PlanBuilder* b, const Rect& r, bool entrance) {
  const double side = b->uniform(3.0, 4.0), front = b->uniform(3.5, 5.0), back = b->uniform(2.5, 3.5);
  const double rack_d = b->uniform(1.0, 1.4), aisle = b->uniform(2.4, 3.2), cross = b->uniform(3.0, 4.0);
  const int n_racks = std::max(1, static_cast<int>(std::floor((r.h() - front - back + aisle) / (rack_d + aisle))));
  const int n_seg = std::max(1, static_cast<int>(std::lround((r.w() - 2 * side) / 30.0)));
  const double seg_len = (r.w() - 2 * side - (n_seg - 1) * cross) / n_seg;
  const double ex = r.x0 + side / 2;
  bottom_wall(b, r, entrance, ex);
  // Vertical route lines: the two side aisles and the cross aisles; horizontal: the front aisle, the
  // aisles between racks and the back aisle.
  std::vector<double> xs{ex};
  for (int k = 1; k < n_seg; ++k) xs.push_back(r.x0 + side + k * seg_len + (k - 0.5) * cross);
  xs.push_back(r.x1 - side / 2);
  std::vector<double> ys{r.y0 + front / 2};
  for (int k = 0; k < n_racks; ++k) {
    const double y = r.y0 + front + k * (rack_d + aisle);
    for (int m = 0; m < n_seg; ++m) {
      const double x = r.x0 + side + m * (seg_len + cross);
      b->furniture(box_outline(Vec2(x + seg_len / 2, y + rack_d / 2), seg_len, rack_d));
    }
    ys.push_back(k + 1 < n_racks ? y + rack_d + aisle / 2 : 0.5 * (y + rack_d + r.y1));
  }
  std::vector<std::vector<int>> vertical(xs.size());
  for (double y : ys) {
    std::vector<int> line;
    for (size_t i = 0; i < xs.size(); ++i) {
      const int n = b->node(Vec2(xs[i], y));
      line.push_back(n);
      vertical[i].push_back(n);
    }
    b->chain(line);
  }
  const int door = entrance ? b->node(Vec2(ex, r.y0 + 1.0)) : -1;
  if (door >= 0) vertical[0].push_back(door);
  for (const std::vector<int>& v : vertical) b->chain(v);
  return door;
}

}  // namespace sim::building
