// SimTaskRunner: the fixed task table (PX4 work-queue style) run in lockstep with a clock the
// simulator steps. run_once() runs every due task once, in registration order, so the same clock
// sequence always gives the same call sequence. A task that fell behind by several periods runs
// once and is rescheduled on its period grid (missed activations are counted, not replayed).
#pragma once

#include <cstddef>
#include <cstdint>

#include "hal/clock.h"
#include "hal/task_runner.h"

namespace hal_sim {

class SimTaskRunner final : public hal::TaskRunner {
 public:
  static constexpr std::size_t kMaxTasks = 16;

  explicit SimTaskRunner(const hal::Clock& clock) : clock_(clock) {}

  // period_ns == 0 runs the task on every run_once(). The first activation is due immediately.
  bool add_task(const char* name, hal::TaskFn fn, void* context, std::uint64_t period_ns) override;
  void run_once() override;

  std::size_t task_count() const { return count_; }
  const char* task_name(std::size_t i) const { return i < count_ ? tasks_[i].name : nullptr; }
  std::uint64_t runs(std::size_t i) const { return i < count_ ? tasks_[i].runs : 0; }
  std::uint64_t missed(std::size_t i) const { return i < count_ ? tasks_[i].missed : 0; }

 private:
  struct Task {
    const char* name = nullptr;
    hal::TaskFn fn = nullptr;
    void* context = nullptr;
    std::uint64_t period_ns = 0;
    std::uint64_t next_due_ns = 0;
    std::uint64_t runs = 0;
    std::uint64_t missed = 0;
  };
  const hal::Clock& clock_;
  Task tasks_[kMaxTasks];
  std::size_t count_ = 0;
};

}  // namespace hal_sim
