// The HAL object (ArduPilot's `hal`): one struct of references, filled once at start-up by the
// chosen backend set. The firmware receives it and never includes a backend.
#pragma once

#include "hal/can_bus.h"
#include "hal/clock.h"
#include "hal/log_sink.h"
#include "hal/sensor_io.h"
#include "hal/serial_port.h"
#include "hal/task_runner.h"

namespace hal {

struct Hal {
  Clock* clock = nullptr;
  LogSink* log = nullptr;
  LaserScanSource* laser = nullptr;
  OdometrySource* odometry = nullptr;
  PoseSink* pose_sink = nullptr;
  CommandSource* commands = nullptr;  // optional: operator commands (hal/msg/command.h)
  TaskRunner* tasks = nullptr;
};

}  // namespace hal
