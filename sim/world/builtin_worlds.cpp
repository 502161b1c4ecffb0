#include "sim/world/builtin_worlds.h"

#include <algorithm>
#include <cmath>

namespace sim {

namespace {

constexpr double kDoor = 1.0;        // door width, m
constexpr double kDoorInset = 1.0;   // route node this far inside a room from its door

// Route bookkeeping while a world is built: corridor centre lines collect nodes that are later
// linked in order along the line.
struct CorridorLine {
  bool horizontal;
  double fixed;        // y of a horizontal line, x of a vertical one
  double lo, hi;       // extent along the line
  std::vector<int> nodes;
};

struct Builder {
  World* w;
  std::vector<CorridorLine> lines;

  int corridor(bool horizontal, double fixed, double lo, double hi) {
    lines.push_back({horizontal, fixed, lo, hi, {}});
    const int id = static_cast<int>(lines.size() - 1);
    on_line(id, lo);
    on_line(id, hi);
    return id;
  }
  // Node on corridor line `id` at coordinate `s` along it.
  int on_line(int id, double s) {
    CorridorLine& l = lines[id];
    const Vec2 p = l.horizontal ? Vec2(s, l.fixed) : Vec2(l.fixed, s);
    const int n = w->route.add_node(p);
    if (std::find(l.nodes.begin(), l.nodes.end(), n) == l.nodes.end()) l.nodes.push_back(n);
    return n;
  }
  // A junction node shared by a horizontal and a vertical line.
  void junction(int h, int v) {
    const Vec2 p(lines[v].fixed, lines[h].fixed);
    on_line(h, p.x());
    on_line(v, p.y());
  }
  // A room whose door is at (door_x, wall_y) on a horizontal wall, opening towards the corridor
  // line `line` (dir = +1 if the corridor is above the wall, −1 below); centre (cx, cy).
  void room_route(int line, double door_x, double wall_y, int dir, const Vec2& centre) {
    const int c = on_line(line, door_x);
    const int inner = w->route.add_node(Vec2(door_x, wall_y - dir * kDoorInset), RouteGraph::kDoorway);
    const int room = w->route.add_node(centre, RouteGraph::kRoom);
    w->route.connect(c, inner);
    w->route.connect(inner, room);
  }
  void finish() {
    for (CorridorLine& l : lines) {
      std::sort(l.nodes.begin(), l.nodes.end(), [&](int a, int b) {
        const Vec2& pa = w->route.nodes[a];
        const Vec2& pb = w->route.nodes[b];
        return l.horizontal ? pa.x() < pb.x() : pa.y() < pb.y();
      });
      for (size_t i = 1; i < l.nodes.size(); ++i) w->route.connect(l.nodes[i - 1], l.nodes[i]);
    }
  }
};

void box(World* w, double cx, double cy, double sx, double sy) {
  add_rect(w, cx - sx / 2, cy - sy / 2, cx + sx / 2, cy + sy / 2);
}

// Furniture kinds (placed against the back wall, away from the door→centre route line):
// 0 none, 1 desk back-left, 2 cabinet back-right, 3 desk + cabinet, 4 round table (octagon).
void furnish(World* w, int kind, double x0, double x1, double y_back, int dir_into_room) {
  // dir_into_room: +1 if the room extends to +y from its door wall (back wall at larger y).
  const double s = static_cast<double>(-dir_into_room);  // from back wall towards the door
  const double w_room = x1 - x0;
  if (kind == 1 || kind == 3) box(w, x0 + 0.3 + 0.8, y_back + s * 0.5, 1.6, 0.8);
  if (kind == 2 || kind == 3) box(w, x1 - 0.3 - 0.3, y_back + s * 1.2, 0.6, 2.0);
  if (kind == 4) {
    const double cx = x0 + 0.25 * w_room, cy = y_back + s * 2.2, r = 0.6;
    for (int i = 0; i < 8; ++i) {
      const double a0 = i * M_PI / 4, a1 = (i + 1) * M_PI / 4;
      add_segment(w, cx + r * std::cos(a0), cy + r * std::sin(a0), cx + r * std::cos(a1), cy + r * std::sin(a1));
    }
  }
}

// A row of rooms between x0 and x1 of depth between wall_y (door wall) and back_y, doors on
// wall_y opening to corridor `line`. `kinds` gives the furniture of each room (cycled).
// Dividers are drawn unless `merge` says room i and i+1 form one hall.
void room_row(Builder* b, int line, double x0, double x1, int n, double wall_y, double back_y,
              const std::vector<int>& kinds, const std::vector<int>& no_divider_after = {}) {
  World* w = b->w;
  const double width = (x1 - x0) / n;
  const int dir = back_y > wall_y ? +1 : -1;  // corridor is at −dir from the wall
  std::vector<double> doors;
  for (int i = 0; i < n; ++i) {
    const double rx0 = x0 + i * width, rx1 = rx0 + width;
    // Door offset towards the room's left third: same in every room ⇒ rooms look alike.
    const double door_x = rx0 + 0.35 * width;
    doors.push_back(door_x);
    if (i + 1 < n && std::find(no_divider_after.begin(), no_divider_after.end(), i) == no_divider_after.end()) {
      add_segment(w, rx1, wall_y, rx1, back_y);
    }
    furnish(w, kinds.empty() ? 0 : kinds[i % kinds.size()], rx0, rx1, back_y, dir);
    b->room_route(line, door_x, wall_y, -dir, Vec2(door_x + 0.15 * width, 0.5 * (wall_y + back_y)));
  }
  add_wall_with_doors(w, Vec2(x0, wall_y), Vec2(x1, wall_y), doors, kDoor);
}

void build_large_office(World* w) {
  w->name = "large-office";
  w->bounds = {Vec2(0, 0), Vec2(81, 47)};
  w->default_resolution = 0.06;  // the dissertation's 6 cm (Sec. 5.7.1)
  add_rect(w, 0, 0, 81, 47);
  Builder b{w, {}};
  // Three 2 m corridors along the whole building and three cross corridors (left, middle, right).
  const int h1 = b.corridor(true, 11, 1, 80), h2 = b.corridor(true, 24, 1, 80), h3 = b.corridor(true, 36, 1, 80);
  const int vl = b.corridor(false, 1, 11, 36), vm = b.corridor(false, 40.5, 11, 36), vr = b.corridor(false, 80, 11, 36);
  for (int h : {h1, h2, h3}) {
    for (int v : {vl, vm, vr}) b.junction(h, v);
  }
  // Band A (y 0–10): 12 rooms opening up to corridor 1; the rightmost two are the unknown area.
  room_row(&b, h1, 0, 81, 12, 10, 0, {0, 0, 1, 0, 0, 0, 0, 2, 0, 0, 3, 0});
  // Band D (y 37–47): 12 rooms opening down to corridor 3; rooms 4–6 form a pillared hall.
  room_row(&b, h3, 0, 81, 12, 37, 47, {0, 0, 0, 0, 0, 0, 0, 0, 4, 0, 0, 0}, {3, 4});
  for (double px : {26.0, 33.0, 39.5}) {
    for (double py : {40.5, 43.5}) box(w, px, py, 0.4, 0.4);
  }
  // Bands B (y 12–23) and C (y 25–35): four blocks of 2 × 6 rooms back to back; the block side walls
  // face the cross corridors bare.
  const double blocks[2][2] = {{2, 39.5}, {41.5, 79}};
  for (const auto& bx : blocks) {
    add_segment(w, bx[0], 12, bx[0], 23);
    add_segment(w, bx[1], 12, bx[1], 23);
    add_segment(w, bx[0], 25, bx[0], 35);
    add_segment(w, bx[1], 25, bx[1], 35);
    add_segment(w, bx[0], 17.5, bx[1], 17.5);
    add_segment(w, bx[0], 30, bx[1], 30);
  }
  room_row(&b, h1, 2, 39.5, 6, 12, 17.5, {0});
  room_row(&b, h1, 41.5, 79, 6, 12, 17.5, {0, 0, 0, 0, 1, 0});
  room_row(&b, h2, 2, 39.5, 6, 23, 17.5, {0});
  room_row(&b, h2, 41.5, 79, 6, 23, 17.5, {0});
  room_row(&b, h2, 2, 39.5, 6, 25, 30, {0, 2, 0, 0, 0, 0});
  room_row(&b, h2, 41.5, 79, 6, 25, 30, {0});
  room_row(&b, h3, 2, 39.5, 6, 35, 30, {0});
  room_row(&b, h3, 41.5, 79, 6, 35, 30, {0, 0, 0, 4, 0, 0});
  // The unmapped rooms: inside the building outline and the corridor wall, so those stay mapped.
  w->unknown_areas.push_back({Vec2(67.6, 0.1), Vec2(80.9, 9.9)});
  b.finish();
}

void build_small_office(World* w) {
  w->name = "small-office";
  w->bounds = {Vec2(0, 0), Vec2(20, 12)};
  w->default_resolution = 0.05;
  add_rect(w, 0, 0, 20, 12);
  Builder b{w, {}};
  const int h = b.corridor(true, 6, 1, 19);
  // Four rooms below (two alike, one furnished, one with a table), three above.
  room_row(&b, h, 0, 20, 4, 5, 0, {0, 0, 3, 4});
  room_row(&b, h, 0, 14, 2, 7, 12, {1, 0});
  // A third room above, unmapped (unknown area).
  add_segment(w, 14, 7, 14, 12);
  add_wall_with_doors(w, Vec2(14, 7), Vec2(20, 7), {16}, kDoor);
  b.room_route(h, 16, 7, -1, Vec2(17, 9.5));
  box(w, 18.5, 11, 1.2, 0.6);
  w->unknown_areas.push_back({Vec2(14.1, 7.1), Vec2(19.9, 11.9)});
  b.finish();
}

void build_corridor(World* w) {
  w->name = "corridor";
  w->bounds = {Vec2(0, 0), Vec2(30, 2)};
  w->default_resolution = 0.05;
  add_rect(w, 0, 0, 30, 2);
  Builder b{w, {}};
  const int h = b.corridor(true, 1, 1, 29);
  for (double x = 5; x < 29; x += 5) b.on_line(h, x);
  b.finish();
}

}  // namespace

std::vector<std::string> builtin_world_names() { return {"small-office", "large-office", "corridor"}; }

bool make_builtin_world(const std::string& name, World* out, std::string* err) {
  *out = World();
  if (name == "large-office") {
    build_large_office(out);
  } else if (name == "small-office") {
    build_small_office(out);
  } else if (name == "corridor") {
    build_corridor(out);
  } else {
    std::string names;
    for (const auto& n : builtin_world_names()) names += (names.empty() ? "" : ", ") + n;
    if (err) *err = "unknown world '" + name + "' (built-in worlds: " + names + ")";
    return false;
  }
  return true;
}

}  // namespace sim
