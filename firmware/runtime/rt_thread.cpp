#include "firmware/runtime/rt_thread.h"

#include <sched.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>

namespace fw {

Status apply_execution_context(pthread_t thread, const ExecutionContext& c, bool realtime, char* warning) {
  if (warning != nullptr) warning[0] = '\0';
  long online = sysconf(_SC_NPROCESSORS_ONLN);
  if (online < 1) online = 1;
  int core = c.core;
  if (core >= online) {
    if (warning != nullptr) {
      std::snprintf(warning, 160, "context %s: core %d not online (%ld CPUs), pinned to core %ld", c.name, core, online,
                    static_cast<long>(core) % online);
    }
    core = static_cast<int>(core % online);
  }
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(core, &set);
  const int prc = pthread_setaffinity_np(thread, sizeof(set), &set);
  if (prc != 0 && warning != nullptr) {
    std::snprintf(warning, 160, "context %s: pinning to core %d failed: %s", c.name, core, std::strerror(prc));
  }
  if (!realtime) return Status::ok();
  sched_param sp{};
  sp.sched_priority = c.priority;
  const int rc = pthread_setschedparam(thread, SCHED_FIFO, &sp);
  if (rc != 0) {
    return Status::error(Errc::kIoError,
                         "context %s: realtime = true but SCHED_FIFO priority %d was refused: %s (needs CAP_SYS_NICE or "
                         "an RLIMIT_RTPRIO of at least %d; set realtime = false to run without)",
                         c.name, c.priority, std::strerror(rc), c.priority);
  }
  return Status::ok();
}

}  // namespace fw
