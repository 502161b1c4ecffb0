// Rooms of the corridor families (office, hospital wing, lab): the furniture inside one room,
// placed in the room's own frame (u along the door wall, v from it into the room) so that a
// hospital's look-alike rooms can repeat one layout exactly. Internal to sim/world.
#pragma once

#include <vector>

#include "sim/world/building_geometry.h"

namespace sim::building {

// A room off a corridor: door wall at y = door_wall_y, the room extending by `depth` in direction
// `dir` (+1 up, −1 down) between x0 and x1.
struct RoomFrame {
  double x0, x1, door_wall_y, depth;
  int dir;
  double width() const { return x1 - x0; }
  Vec2 to_world(double u, double v) const { return Vec2(x0 + u, door_wall_y + dir * v); }
  Rect rect() const {
    const double ya = door_wall_y, yb = door_wall_y + dir * depth;
    return {x0, std::min(ya, yb), x1, std::max(ya, yb)};
  }
};

// One piece of furniture in room coordinates: an axis-aligned box (su × sv) or, with octagon, an
// octagon of radius su/2.
struct RoomItem {
  double cu, cv, su, sv;
  bool octagon = false;
};

// Draws a layout of furniture for a room of this family: desks and cabinets along the walls for an
// office, a bed and a locker for a hospital room, benches plus dense small clutter for a lab.
// Items that would come nearer than 0.5 m to the room's route edges are not placed.
std::vector<RoomItem> draw_room_layout(PlanBuilder* b, const RoomFrame& room, const std::vector<Segment>& edges,
                                       BuildingFamily style);
// Places the items that fit (same rule); returns how many were placed.
int place_room_layout(PlanBuilder* b, const RoomFrame& room, const std::vector<Segment>& edges,
                      const std::vector<RoomItem>& items);

}  // namespace sim::building
