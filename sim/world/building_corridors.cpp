// The corridor families: office, hospital / hotel wing and lab share one layout — a vertical
// corridor crossing horizontal bands, each band a double-loaded corridor with rooms on both sides —
// and differ in corridor width, room size, whether rooms are identical, and furniture.
#include <algorithm>
#include <cmath>

#include "sim/world/building_geometry.h"
#include "sim/world/building_rooms.h"

namespace sim::building {

namespace {

struct CorridorStyle {
  BuildingFamily family;
  double corridor_w;  // m
  double room_depth;  // target, m
  double room_w;      // target (mean) width, m
  bool identical;     // look-alike rooms: one width, one door offset, one furniture layout
};

CorridorStyle draw_style(PlanBuilder* b, BuildingFamily family) {
  CorridorStyle s{family, 0, 0, 0, family == BuildingFamily::kHospitalWing};
  if (family == BuildingFamily::kHospitalWing) {
    s.corridor_w = b->uniform(2.2, 2.8);
    s.room_depth = b->uniform(4.0, 5.5);
    s.room_w = b->uniform(3.6, 4.6);
  } else if (family == BuildingFamily::kLab) {
    s.corridor_w = b->uniform(2.2, 3.0);
    s.room_depth = b->uniform(5.0, 8.0);
    s.room_w = b->uniform(5.0, 8.0);
  } else {
    s.corridor_w = b->uniform(2.0, 2.6);
    s.room_depth = b->uniform(4.0, 6.0);
    s.room_w = b->uniform(3.8, 5.5);
  }
  return s;
}

// Room boundaries between xa and xb: n rooms of the target width, equal for look-alike rooms,
// else each within ±25 % of the mean.
std::vector<double> room_bounds(PlanBuilder* b, double xa, double xb, const CorridorStyle& s) {
  const int n = std::max(1, static_cast<int>(std::lround((xb - xa) / s.room_w)));
  std::vector<double> weight(n, 1.0);
  double total = 0;
  for (int i = 0; i < n; ++i) {
    if (!s.identical) weight[i] = b->uniform(0.75, 1.25);
    total += weight[i];
  }
  std::vector<double> out{xa};
  for (int i = 0; i < n; ++i) out.push_back(out.back() + (xb - xa) * weight[i] / total);
  out.back() = xb;
  return out;
}

struct CorridorBand {
  double yb, yt, yc;            // band bottom, top and corridor centre line
  std::vector<int> line_nodes;  // nodes on the corridor centre line (chained at the end)
};

// One row of rooms on one side of a band's corridor, between xa and xb.
void corridor_room_row(PlanBuilder* b, const CorridorStyle& s, CorridorBand* band, double xa, double xb, int dir,
                       std::vector<RoomItem>* look_alike) {
  const double wall_y = band->yc + dir * s.corridor_w / 2;
  const double back_y = dir > 0 ? band->yt : band->yb;
  const std::vector<double> xs = room_bounds(b, xa, xb, s);
  for (size_t i = 0; i + 1 < xs.size(); ++i) {
    const RoomFrame room{xs[i], xs[i + 1], wall_y, std::fabs(back_y - wall_y), dir};
    const double w = room.width();
    const double door_u = s.identical ? std::max(0.8, 0.3 * w) : b->uniform(0.8, w - 0.8);
    const bool glass_front = b->chance(b->opt->glass_fraction);
    b->wall_with_doors(Vec2(room.x0, wall_y), Vec2(room.x1, wall_y), {door_u}, glass_front);
    if (i + 2 < xs.size()) {
      const bool glass_side = b->chance(b->opt->glass_fraction);
      b->partition(Vec2(room.x1, wall_y), Vec2(room.x1, back_y), glass_side);
    }
    const Vec2 door_c(room.x0 + door_u, band->yc);
    const Vec2 inset = room.to_world(door_u, kDoorInset);
    const Vec2 centre = room.to_world(w / 2, room.depth / 2);
    const int c = b->node(door_c);
    const int d = b->node(inset, RouteGraph::kDoorway);
    const int m = b->node(centre, RouteGraph::kRoom);
    b->connect(c, d);
    b->connect(d, m);
    band->line_nodes.push_back(c);
    const std::vector<Segment> edges{{door_c, inset}, {inset, centre}};
    if (!s.identical) {
      const std::vector<RoomItem> layout = draw_room_layout(b, room, edges, s.family);
      place_room_layout(b, room, edges, layout);
    } else {
      // Look-alike rooms: the first room's layout, mirrored with the room, in every room.
      if (look_alike->empty()) *look_alike = draw_room_layout(b, room, edges, s.family);
      place_room_layout(b, room, edges, *look_alike);
    }
  }
}

}  // namespace

int build_corridor_family(PlanBuilder* b, const Rect& r, BuildingFamily family, bool entrance) {
  CorridorStyle s = draw_style(b, family);
  const double cw = s.corridor_w;
  double xv = b->uniform(r.x0 + 0.3 * r.w(), r.x0 + 0.7 * r.w());  // the vertical corridor
  if (s.identical) {
    // Look-alike rooms on both sides of the vertical corridor: one room width that divides the
    // building's length, the corridor placed on a room boundary.
    const int n = std::max(2, static_cast<int>(std::lround((r.w() - cw) / s.room_w)));
    s.room_w = (r.w() - cw) / n;
    const int left = std::clamp(static_cast<int>(std::lround((xv - cw / 2 - r.x0) / s.room_w)), 1, n - 1);
    xv = r.x0 + left * s.room_w + cw / 2;
  }
  const int n_bands = std::max(1, static_cast<int>(std::lround(r.h() / (2 * s.room_depth + cw))));
  const double bh = r.h() / n_bands;
  // Outline: the bottom wall opens onto the vertical corridor when the wing has an entrance.
  b->wall_with_doors(Vec2(r.x0, r.y0), Vec2(r.x1, r.y0),
                     entrance ? std::vector<double>{xv - r.x0} : std::vector<double>{}, false, false, cw);
  b->wall(Vec2(r.x1, r.y0), Vec2(r.x1, r.y1));
  b->wall(Vec2(r.x1, r.y1), Vec2(r.x0, r.y1));
  b->wall(Vec2(r.x0, r.y1), Vec2(r.x0, r.y0));
  std::vector<double> openings;
  std::vector<int> vertical{b->node(Vec2(xv, r.y0 + 1.0)), b->node(Vec2(xv, r.y1 - 1.0))};
  std::vector<RoomItem> look_alike;
  for (int j = 0; j < n_bands; ++j) {
    CorridorBand band{r.y0 + j * bh, r.y0 + (j + 1) * bh, r.y0 + (j + 0.5) * bh, {}};
    openings.push_back(band.yc - r.y0);
    const double left_end = xv - cw / 2, right_start = xv + cw / 2;
    corridor_room_row(b, s, &band, r.x0, left_end, -1, &look_alike);
    corridor_room_row(b, s, &band, r.x0, left_end, +1, &look_alike);
    corridor_room_row(b, s, &band, right_start, r.x1, -1, &look_alike);
    corridor_room_row(b, s, &band, right_start, r.x1, +1, &look_alike);
    if (j + 1 < n_bands) {  // the back walls between this band and the next
      b->wall(Vec2(r.x0, band.yt), Vec2(left_end, band.yt));
      b->wall(Vec2(right_start, band.yt), Vec2(r.x1, band.yt));
    }
    const int junction = b->node(Vec2(xv, band.yc));
    vertical.push_back(junction);
    std::vector<int> left = {b->node(Vec2(r.x0 + 1.0, band.yc)), junction};
    std::vector<int> right = {junction, b->node(Vec2(r.x1 - 1.0, band.yc))};
    for (int n : band.line_nodes) (b->plan->structure.route.nodes[n].x() < xv ? left : right).push_back(n);
    b->chain(left);
    b->chain(right);
  }
  // The vertical corridor's walls, open where each band's corridor crosses it.
  b->wall_with_doors(Vec2(xv - cw / 2, r.y0), Vec2(xv - cw / 2, r.y1), openings, false, false, cw);
  b->wall_with_doors(Vec2(xv + cw / 2, r.y0), Vec2(xv + cw / 2, r.y1), openings, false, false, cw);
  b->chain(vertical);
  return entrance ? vertical.front() : -1;
}

}  // namespace sim::building
