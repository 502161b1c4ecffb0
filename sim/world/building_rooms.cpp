#include "sim/world/building_rooms.h"

#include <algorithm>
#include <cmath>

namespace sim::building {

namespace {

constexpr double kWallGap = 0.12;  // furniture stands this far off a wall
constexpr double kRouteGap = 0.5;  // and this far from the room's route edges (test: ≥ 0.4)

std::vector<Segment> item_outline(const RoomFrame& room, const RoomItem& it) {
  const Vec2 c = room.to_world(it.cu, it.cv);
  return it.octagon ? octagon_outline(c, it.su / 2) : box_outline(c, it.su, it.sv);
}

// What a room's furniture must keep clear of: its route edges, the walls and furniture around it
// (gathered once per room), and the items kept in it so far.
struct RoomContext {
  const RoomFrame& room;
  const std::vector<Segment>& edges;
  std::vector<Segment> nearby;
  std::vector<std::vector<Segment>> kept;
};

RoomContext make_context(PlanBuilder* b, const RoomFrame& room, const std::vector<Segment>& edges) {
  return RoomContext{room, edges, b->obstacles_near(room.rect(), 0.5), {}};
}

bool fits(PlanBuilder* b, const RoomContext& ctx, const RoomItem& it) {
  const std::vector<Segment> outline = item_outline(ctx.room, it);
  if (!b->free_for_furniture(outline, ctx.room.rect(), ctx.edges, kRouteGap, 0.05, &ctx.nearby)) return false;
  for (const std::vector<Segment>& k : ctx.kept) {  // not standing inside another item, nor around it
    if (point_in_outline(outline.front().a, k) || point_in_outline(k.front().a, outline)) return false;
  }
  return true;
}

void keep(PlanBuilder* b, RoomContext* ctx, const RoomItem& it) {
  std::vector<Segment> outline = item_outline(ctx->room, it);
  ctx->nearby.insert(ctx->nearby.end(), outline.begin(), outline.end());
  ctx->kept.push_back(outline);
  b->furniture(std::move(outline));
}

// A box of `len` × `thick` against a wall drawn at random: the back wall or a side wall (the door
// wall stays free, it is where people walk in).
RoomItem against_wall(PlanBuilder* b, const RoomFrame& room, double len, double thick) {
  const int side = b->uniform_int(0, 2);
  const double w = room.width(), d = room.depth;
  RoomItem it{};
  if (side == 0) {  // back wall
    it.su = std::min(len, w - 2 * kWallGap);
    it.sv = thick;
    it.cu = b->uniform(it.su / 2 + kWallGap, w - it.su / 2 - kWallGap);
    it.cv = d - thick / 2 - kWallGap;
  } else {
    it.su = thick;
    it.sv = std::min(len, d - 2 * kWallGap);
    it.cv = b->uniform(it.sv / 2 + kWallGap, d - it.sv / 2 - kWallGap);
    it.cu = side == 1 ? thick / 2 + kWallGap : w - thick / 2 - kWallGap;
  }
  return it;
}

RoomItem anywhere(PlanBuilder* b, const RoomFrame& room, double size, bool octagon) {
  RoomItem it{};
  it.su = size;
  it.sv = octagon ? size : b->uniform(0.3, 0.8);
  it.octagon = octagon;
  it.cu = b->uniform(it.su / 2 + kWallGap, room.width() - it.su / 2 - kWallGap);
  it.cv = b->uniform(it.sv / 2 + kWallGap, room.depth - it.sv / 2 - kWallGap);
  return it;
}

// Tries `tries` draws of `draw()` and keeps the first that fits beside the items kept so far.
template <class Draw>
void keep_first_fit(PlanBuilder* b, RoomContext* ctx, int tries, Draw draw, std::vector<RoomItem>* kept) {
  for (int t = 0; t < tries; ++t) {
    const RoomItem it = draw();
    if (!fits(b, *ctx, it)) continue;
    keep(b, ctx, it);
    kept->push_back(it);
    return;
  }
}

}  // namespace

std::vector<RoomItem> draw_room_layout(PlanBuilder* b, const RoomFrame& room, const std::vector<Segment>& edges,
                                       BuildingFamily style) {
  std::vector<RoomItem> kept;
  const size_t first_furniture = b->plan->furniture.size();
  RoomContext ctx = make_context(b, room, edges);
  if (style == BuildingFamily::kHospitalWing) {
    keep_first_fit(
        b, &ctx, 12, [&] { return against_wall(b, room, 2.0, 1.0); }, &kept);  // bed
    keep_first_fit(
        b, &ctx, 12, [&] { return against_wall(b, room, 0.6, 0.5); }, &kept);  // locker
    keep_first_fit(
        b, &ctx, 12, [&] { return against_wall(b, room, 0.8, 0.45); }, &kept);  // table
  } else if (style == BuildingFamily::kLab) {
    const int benches = b->uniform_int(1, 3), clutter = b->uniform_int(8, 18);
    for (int i = 0; i < benches; ++i) {
      const double len = b->uniform(1.5, 3.0);
      keep_first_fit(
          b, &ctx, 10, [&] { return against_wall(b, room, len, 0.75); }, &kept);
    }
    for (int i = 0; i < clutter; ++i) {
      const double size = b->uniform(0.3, 0.8);
      const bool octagon = b->chance(0.3);
      keep_first_fit(
          b, &ctx, 6, [&] { return anywhere(b, room, size, octagon); }, &kept);
    }
  } else {
    const int desks = b->uniform_int(1, 3), cabinets = b->uniform_int(0, 2);
    for (int i = 0; i < desks; ++i) {
      const double len = b->uniform(1.2, 1.8), thick = b->uniform(0.6, 0.8);
      keep_first_fit(
          b, &ctx, 10, [&] { return against_wall(b, room, len, thick); }, &kept);
    }
    for (int i = 0; i < cabinets; ++i) {
      const double len = b->uniform(0.8, 1.2), thick = b->uniform(0.4, 0.6);
      keep_first_fit(
          b, &ctx, 10, [&] { return against_wall(b, room, len, thick); }, &kept);
    }
  }
  // The caller decides what goes into the plan (a template room is placed like any other).
  b->plan->furniture.resize(first_furniture);
  return kept;
}

int place_room_layout(PlanBuilder* b, const RoomFrame& room, const std::vector<Segment>& edges,
                      const std::vector<RoomItem>& items) {
  RoomContext ctx = make_context(b, room, edges);
  int placed = 0;
  for (const RoomItem& it : items) {
    if (!fits(b, ctx, it)) continue;
    keep(b, &ctx, it);
    ++placed;
  }
  return placed;
}

}  // namespace sim::building
