// Sensor profiles (issue 55): the 2-D lidars robots carry, each from its data sheet (cited in
// sensor_profiles.cpp): field of view, angular step, range, rate, range noise and quantisation,
// no-return behaviour, dropouts, glass. Every profile goes through the same HAL path and the same
// wire resolution as the simulated laser (hal::LaserScan, regular angles: a sensor that measures at
// irregular angles is resampled onto its nominal grid as its driver would, laser_model.h).
#pragma once

#include <string>
#include <vector>

#include "sim/world/laser_model.h"

namespace sim {

struct SensorProfile {
  std::string name;     // "lms200", "utm30lx", "tim571", "rplidar-a1"
  std::string source;   // the data sheet it follows
  LaserModelOptions laser;
  double rate_hz = 0;   // the sensor's own scan rate
};

const std::vector<SensorProfile>& sensor_profiles();
// nullptr for an unknown name.
const SensorProfile* find_sensor_profile(const std::string& name);

}  // namespace sim
