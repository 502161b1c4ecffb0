// TaskRunner: a fixed table of periodic tasks (PX4 work-queue style), run in lockstep with the
// stepped clock by the sim backend (hal_sim::SimTaskRunner). There is no Linux backend: mmlfw's
// threads are the execution contexts of firmware/runtime/execution_contexts.h (sensor, global,
// workers), created once at start-up and pinned.
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
