// Unit conversions of the host tools' reports (degrees are for people; the firmware works in radians).
#pragma once

namespace sim {

inline constexpr double kRadToDeg = 57.29577951308232;  // 180 / π

}  // namespace sim
