// Unit conversions of the host tools' reports (degrees are for people; the firmware works in radians).
#pragma once

namespace sim {

inline constexpr double kRadToDeg = 57.29577951308232;  // 180 / π
inline constexpr double kDegToRad = 0.017453292519943295;

}  // namespace sim
