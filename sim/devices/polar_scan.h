// PolarScan: a recorded or simulated scan as the device models resample it for the geometry of
// the sensor they play (a Hokuyo's steps, an RPLIDAR's sample angles): nearest beam at an angle.
#pragma once

#include <cmath>
#include <vector>

namespace sim {

struct PolarScan {
  double angle_min = 0.0;        // rad, counter-clockwise
  double angle_increment = 0.0;  // rad
  double max_range = 0.0;        // m; readings at/above are no return
  std::vector<float> ranges;     // m

  // The reading of the beam nearest to angle a (rad, CCW); false outside the field of view or
  // for no return.
  bool at(double a, double* r) const {
    if (ranges.empty() || !(angle_increment > 0.0)) return false;
    const double k = std::round((a - angle_min) / angle_increment);
    if (k < 0.0 || k >= static_cast<double>(ranges.size())) return false;
    const double v = ranges[static_cast<size_t>(k)];
    if (!(v > 0.0) || v >= max_range) return false;
    *r = v;
    return true;
  }
};

}  // namespace sim
