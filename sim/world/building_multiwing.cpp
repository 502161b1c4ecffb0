// Multi-wing buildings: 2–4 wings of the other families side by side, each opening onto one spine
// corridor that runs along the building's bottom wall.
#include <algorithm>
#include <cmath>

#include "sim/world/building_geometry.h"

namespace sim::building {

void build_multi_wing(PlanBuilder* b, const Rect& r) {
  constexpr double kSpine = 3.0;  // spine corridor width, m
  const int max_wings = std::clamp(static_cast<int>(r.w() / 25.0), 2, 4);
  const int wings = b->uniform_int(2, max_wings);
  std::vector<double> weight(wings);
  double total = 0;
  for (double& w : weight) {
    w = b->uniform(0.8, 1.2);
    total += w;
  }
  // The spine: the building's bottom wall and the two short end walls; its top is the wings' bottom.
  b->wall(Vec2(r.x0, r.y0), Vec2(r.x1, r.y0));
  b->wall(Vec2(r.x0, r.y0), Vec2(r.x0, r.y0 + kSpine));
  b->wall(Vec2(r.x1, r.y0), Vec2(r.x1, r.y0 + kSpine));
  const double spine_y = r.y0 + kSpine / 2;
  std::vector<int> spine{b->node(Vec2(r.x0 + 1.0, spine_y)), b->node(Vec2(r.x1 - 1.0, spine_y))};
  double x = r.x0;
  for (int i = 0; i < wings; ++i) {
    const double x_end = i + 1 == wings ? r.x1 : x + r.w() * weight[i] / total;
    const Rect wing{x, r.y0 + kSpine, x_end, r.y1};
    const auto family = static_cast<BuildingFamily>(b->uniform_int(0, static_cast<int>(BuildingFamily::kLab)));
    int door = -1;
    if (family == BuildingFamily::kOpenHall) {
      door = build_open_hall(b, wing, true);
    } else if (family == BuildingFamily::kWarehouse) {
      door = build_warehouse(b, wing, true);
    } else {
      door = build_corridor_family(b, wing, family, true);
    }
    const int joint = b->node(Vec2(b->plan->structure.route.nodes[door].x(), spine_y));
    b->connect(joint, door);
    spine.push_back(joint);
    x = x_end;
  }
  b->chain(spine);
}

}  // namespace sim::building
