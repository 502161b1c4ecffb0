// TaskRunner: a fixed table of periodic tasks (PX4 work-queue style). The Linux backend runs them
// on a loop with real time; the sim backend runs them in lockstep with the stepped clock.
#pragma once

#include <cstdint>

namespace hal {

using TaskFn = void (*)(void* context);

class TaskRunner {
 public:
  virtual ~TaskRunner() = default;
  // Registers a task at start-up; false when the fixed table is full.
  virtual bool add_task(const char* name, TaskFn fn, void* context, std::uint64_t period_ns) = 0;
  // Runs due tasks once (sim: advances nothing; the caller steps the clock).
  virtual void run_once() = 0;
};

}  // namespace hal
