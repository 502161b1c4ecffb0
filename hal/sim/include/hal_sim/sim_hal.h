// SimHal: the whole simulation backend set wired into one hal::Hal (ArduPilot's SITL HAL): stepped
// clock, sensor rings, pose sink, log ring and task runner. ~100 KiB (the scan ring dominates):
// create it once (static or on the host heap), never on a small stack.
#pragma once

#include "hal/hal.h"
#include "hal_sim/sim_log_sink.h"
#include "hal_sim/sim_sensor_io.h"
#include "hal_sim/sim_task_runner.h"
#include "hal_sim/stepped_clock.h"

namespace hal_sim {

struct SimHal {
  SteppedClock clock;
  SimLaserSource laser;
  SimOdometrySource odometry;
  SimPoseSink pose_sink;
  SimLogSink log;
  SimTaskRunner tasks{clock};
  hal::Hal hal;

  SimHal() {
    hal.clock = &clock;
    hal.log = &log;
    hal.laser = &laser;
    hal.odometry = &odometry;
    hal.pose_sink = &pose_sink;
    hal.tasks = &tasks;
  }
  SimHal(const SimHal&) = delete;
  SimHal& operator=(const SimHal&) = delete;
};

}  // namespace hal_sim
