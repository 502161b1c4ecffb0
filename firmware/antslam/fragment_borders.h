// Fragment borders and the convex hull (dissertation Sec. 3.4, Fig. 3.3–3.4, Eq. 3.6–3.8): which
// map fragment the robot is in.
//
// When the robot leaves a fragment, a border is cut across its path: two of the fragment's points,
// b1 to the left of the robot and b2 to its right, each the point minimising
//   w(p_j)_{1,2} = α η1 ‖p_j − R‖ + (1 − α) η2 |∠(p_j − R) − Θ_r ∓ π/2|      (Eq. 3.6, 3.7)
// (R, Θ_r the robot's position and heading; η1 = 1 / the largest distance, η2 = 1/π map both terms
// to [0, 1]): nearly orthogonal to the heading and short. The border is oriented Δ = b1 → b2, so the
// fragment being left lies to its right; the fragment being entered gets the same points in the
// opposite orientation. The robot is in fragment f when its position is right of every border of f
// (the sign of h, Eq. 3.8) and inside f's convex hull (Graham scan): the borders alone would also
// hold far beyond the fragment (Fig. 3.4).
//
// Plain geometry on caller-provided storage: no allocation, no state.
#pragma once

#include <cstddef>

#include "firmware/base/se2.h"
#include "firmware/scan/scan_points.h"

namespace fw::antslam {

// Eq. 3.8: h(p0, p1, p2) = (x1 − x0)(y2 − y0) − (x2 − x0)(y1 − y0); < 0 when p2 is right of p0 → p1,
// 0 when collinear, > 0 when left.
inline double signed_area(double x0, double y0, double x1, double y1, double x2, double y2) {
  return (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
}

// A border b1 → b2 in its fragment's frame; the fragment lies to its right.
struct Border {
  double x1 = 0, y1 = 0, x2 = 0, y2 = 0;
  Border reversed() const { return Border{x2, y2, x1, y1}; }
  // The same border in another frame: `to_other` is this fragment's frame expressed in the other's.
  Border transformed(const Se2d& to_other) const;
  double length() const;
};

struct BorderOptions {
  // α of Eq. 3.6: the weight of the distance against the orthogonality (the dissertation leaves its
  // value open; 0.5 weighs both normalised terms alike).
  double alpha = 0.5;
  // Only points within this angle of the orthogonal are candidates: a "left" point behind or ahead
  // of the robot would give a border along the path, which separates nothing.
  double max_angle_off_rad = 1.0471975511965976;  // 60°
};

// Eq. 3.6–3.7 on the fragment's points (its frame) for the robot at `robot` (same frame). False when
// either side has no candidate point (open space: the dissertation notes borders are hard to
// define there), and then `out` is untouched.
bool select_border(const Point2f* points, std::size_t n, const Se2d& robot, const BorderOptions& options,
                   Border* out);

// Graham scan: the convex hull of `points` counter-clockwise into `hull` (at most `capacity`
// vertices, collinear points dropped). `scratch` holds n points. Returns the number of vertices, 0
// when the hull does not fit `capacity` or n < 3 or all points are collinear.
std::size_t convex_hull(const Point2f* points, std::size_t n, Point2f* scratch, Point2f* hull,
                        std::size_t capacity);

// Inside (or on the edge of) a counter-clockwise convex polygon of m ≥ 3 vertices.
bool inside_convex_hull(const Point2f* hull, std::size_t m, double x, double y);

// Right of (or on) every border (Eq. 3.8: h ≤ 0); true for no borders.
bool right_of_borders(const Border* borders, std::size_t count, double x, double y);

// The membership test of Sec. 3.4: right of all borders and inside the hull.
inline bool inside_fragment(const Border* borders, std::size_t num_borders, const Point2f* hull, std::size_t hull_size,
                            double x, double y) {
  return hull_size >= 3 && right_of_borders(borders, num_borders, x, y) && inside_convex_hull(hull, hull_size, x, y);
}

}  // namespace fw::antslam
