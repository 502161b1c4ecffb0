#include "hal_sim/sim_task_runner.h"

namespace hal_sim {

bool SimTaskRunner::add_task(const char* name, hal::TaskFn fn, void* context, std::uint64_t period_ns) {
  if (count_ == kMaxTasks || fn == nullptr) return false;
  Task& t = tasks_[count_++];
  t.name = name;
  t.fn = fn;
  t.context = context;
  t.period_ns = period_ns;
  t.next_due_ns = clock_.now_ns();
  return true;
}

void SimTaskRunner::run_once() {
  const std::uint64_t now = clock_.now_ns();
  for (std::size_t i = 0; i < count_; ++i) {
    Task& t = tasks_[i];
    if (t.period_ns != 0 && now < t.next_due_ns) continue;
    t.fn(t.context);
    ++t.runs;
    if (t.period_ns != 0) {
      // Stay on the period grid: skip (and count) activations that are already in the past.
      const std::uint64_t behind = (now - t.next_due_ns) / t.period_ns;
      t.missed += behind;
      t.next_due_ns += (behind + 1) * t.period_ns;
    }
  }
}

}  // namespace hal_sim
