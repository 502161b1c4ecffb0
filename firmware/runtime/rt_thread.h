// Thread set-up from the execution-context table (execution_contexts.h): pin to the context's core
// and, when realtime, SCHED_FIFO at its priority. Policy (issue 14): `realtime = true` is a promise
// to the user, so a refusal of SCHED_FIFO (EPERM: no CAP_SYS_NICE / RLIMIT_RTPRIO) is an error
// that stops start-up with the reason; a core that is not online degrades to (core mod online)
// with a warning, as the worker pool does.
#pragma once

#include <pthread.h>

#include "firmware/base/status.h"
#include "firmware/runtime/execution_contexts.h"

namespace fw {

// `warning` (may be null, ≥ 160 bytes) receives a non-fatal note ("" when none).
Status apply_execution_context(pthread_t thread, const ExecutionContext& context, bool realtime, char* warning);
inline Status apply_execution_context_here(const ExecutionContext& context, bool realtime, char* warning) {
  return apply_execution_context(pthread_self(), context, realtime, warning);
}

}  // namespace fw
