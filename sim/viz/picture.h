// A picture of a localization run — global map, ground-truth path, estimated path, hypotheses,
// markers and boxes — described once and rendered two ways: SVG (vector overlays on the map
// embedded as a PNG data URI, with text) and PNG (rasterized with libpng, a small built-in font).
// World coordinates in metres; y up.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim/io/ros_map.h"

namespace sim {

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
};

struct PicturePoint {
  double x = 0, y = 0;
};

struct Polyline {
  std::vector<PicturePoint> points;
  Rgb color;
  double width_px = 2.0;
  std::string label;  // legend entry (empty: none)
};

enum class PointShape { kDisc, kCross };

struct PointSet {
  std::vector<PicturePoint> points;
  Rgb color;
  double radius_px = 2.0;
  std::string label;
  PointShape shape = PointShape::kDisc;  // kCross: an × of half-size radius_px (e.g. failures)
};

// Circles with a radius in metres (e.g. the protection level around an estimate): outlines only.
struct WorldCircle {
  double x = 0, y = 0, radius_m = 0;
};
struct CircleSet {
  std::vector<WorldCircle> circles;
  Rgb color;
  double width_px = 1.0;
  std::string label;
};

struct Marker {  // a pose: circle with a heading tick, optional text
  double x = 0, y = 0, theta = 0;
  Rgb color;
  double radius_px = 6.0;
  std::string text;
};

struct BoxOverlay {  // e.g. the unknown area
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  Rgb color;
  std::string label;
};

struct Picture {
  std::string title;
  std::vector<std::string> notes;  // extra lines under the title
  const OccupancyGrid* map = nullptr;  // optional background
  // Extent shown when there is no map (or to override it): min/max in metres; all 0 = auto.
  double x_min = 0, y_min = 0, x_max = 0, y_max = 0;
  double pixels_per_metre = 0;  // 0 = fit the long side into ~1600 px
  std::vector<BoxOverlay> boxes;
  std::vector<Polyline> lines;
  std::vector<CircleSet> circle_sets;  // drawn under the point sets
  std::vector<PointSet> point_sets;
  std::vector<Marker> markers;
};

bool write_svg(const Picture& pic, const std::string& path, std::string* err);
bool write_png(const Picture& pic, const std::string& path, std::string* err);

// Helpers (exposed for tests): PNG bytes of an RGB image (row 0 = top), base64.
bool encode_png_rgb(int width, int height, const std::vector<std::uint8_t>& rgb, std::vector<std::uint8_t>* out,
                    std::string* err);
std::string base64(const std::vector<std::uint8_t>& bytes);

}  // namespace sim
