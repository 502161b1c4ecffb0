#include "sim/world/raster.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "firmware/map/global_map.h"

namespace sim {

bool rasterize_world(const World& world, const RasterOptions& opt, OccupancyGrid* out, std::string* err) {
  const double res = opt.resolution == 0 ? world.default_resolution : opt.resolution;
  if (!(res >= 0.01 && res <= 1.0)) {
    if (err) *err = "map resolution " + std::to_string(res) + " m outside [0.01, 1]";
    return false;
  }
  if (!(opt.margin >= 0 && opt.margin <= 100)) {
    if (err) *err = "map margin must be in [0, 100] m";
    return false;
  }
  fw::GridGeometry& g = out->geometry;
  g.resolution = static_cast<float>(res);
  g.origin_x = static_cast<float>(world.bounds.min.x() - opt.margin);
  g.origin_y = static_cast<float>(world.bounds.min.y() - opt.margin);
  g.width = static_cast<std::uint32_t>(std::ceil((world.bounds.max.x() + opt.margin - g.origin_x) / res));
  g.height = static_cast<std::uint32_t>(std::ceil((world.bounds.max.y() + opt.margin - g.origin_y) / res));
  out->cells.assign(g.cell_count(), fw::kCellFree);
  auto centre = [&](std::int32_t cx, std::int32_t cy) {
    const fw::Point2f c = g.cell_center(cx, cy);
    return Vec2(c.x(), c.y());
  };
  const auto w = static_cast<std::int32_t>(g.width), h = static_cast<std::int32_t>(g.height);
  // Outside the building outline: unknown (never observed).
  for (std::int32_t cy = 0; cy < h; ++cy) {
    for (std::int32_t cx = 0; cx < w; ++cx) {
      if (!world.bounds.contains(centre(cx, cy))) out->cells[g.index(cx, cy)] = fw::kCellUnknown;
    }
  }
  // Glass panes are drawn like walls: the map is drawn from the plan, whatever a laser makes of them.
  std::vector<const Segment*> drawn;
  for (const Segment& s : world.walls) drawn.push_back(&s);
  for (const Segment& s : world.glass) drawn.push_back(&s);
  for (const Segment* sp : drawn) {
    const Segment& s = *sp;
    const double len = (s.b - s.a).norm();
    const int n = std::max(1, static_cast<int>(std::ceil(len / (res / 8))));
    for (int i = 0; i <= n; ++i) {
      const Vec2 p = s.a + (s.b - s.a) * (static_cast<double>(i) / n);
      std::int32_t cx, cy;
      if (g.world_to_cell(static_cast<float>(p.x()), static_cast<float>(p.y()), &cx, &cy)) {
        out->cells[g.index(cx, cy)] = fw::kCellOccupied;
      }
    }
  }
  if (opt.erase_unknown_areas) {
    for (const Box& b : world.unknown_areas) {
      for (std::int32_t cy = 0; cy < h; ++cy) {
        for (std::int32_t cx = 0; cx < w; ++cx) {
          if (b.contains(centre(cx, cy))) out->cells[g.index(cx, cy)] = fw::kCellUnknown;
        }
      }
    }
  }
  return true;
}

}  // namespace sim
