#include "hal_sim/sim_sensor_io.h"

namespace hal_sim {

bool SimLaserSource::push(const hal::LaserScan& scan) {
  if (!ring_.push(scan).is_ok()) {
    ++stats_.dropped;
    return false;
  }
  ++stats_.pushed;
  return true;
}

bool SimLaserSource::poll(hal::LaserScan* out) {
  if (!ring_.pop(out)) return false;
  ++stats_.polled;
  return true;
}

bool SimOdometrySource::push(const hal::Odometry& odom) {
  if (!ring_.push(odom).is_ok()) {
    ++stats_.dropped;
    return false;
  }
  ++stats_.pushed;
  return true;
}

bool SimOdometrySource::poll(hal::Odometry* out) {
  if (!ring_.pop(out)) return false;
  ++stats_.polled;
  return true;
}

void SimPoseSink::publish(const hal::PoseEstimate& estimate) {
  if (ring_.push_overwrite(estimate)) ++stats_.dropped;
  ++stats_.pushed;
}

void SimPoseSink::publish_health(const hal::Health& health) {
  health_ = health;
  ++health_count_;
}

bool SimPoseSink::pop(hal::PoseEstimate* out) {
  if (!ring_.pop(out)) return false;
  ++stats_.polled;
  return true;
}

}  // namespace hal_sim
