// GlobalThread: the `global` execution context's thread (execution_contexts.h), created once at
// start-up and pinned, serving the GlobalContext it is given. One GlobalContext owns one (the
// single-map firmware, the tools); several maps share one (firmware/app/map_set.h): only the active
// map's MML runs, so one thread serves whichever map is active, and a map rebuilt by a reload after
// start-up is served by the same thread instead of needing a new one.
#pragma once

#include <pthread.h>

#include "firmware/base/status.h"
#include "firmware/runtime/execution_contexts.h"

namespace fw {
namespace track {

class GlobalContext;

class GlobalThread {
 public:
  GlobalThread() = default;
  GlobalThread(const GlobalThread&) = delete;
  GlobalThread& operator=(const GlobalThread&) = delete;
  ~GlobalThread() { stop(); }

  // Start-up only: creates the thread (pinned, SCHED_FIFO when realtime, as the context says).
  Status start(const ExecutionContext& context, bool realtime);
  // Joins the thread after the job it runs, if any.
  void stop();
  bool running() const { return running_; }
  // From now on run the jobs `ctx` queues (null: none). The caller makes sure the context served
  // before has no job in flight (GlobalContext::job_in_flight): a job is never moved.
  void serve(GlobalContext* ctx);
  // A job was queued by the served context (after its mailbox says so).
  void notify();

 private:
  static void* thread_main(void* self);
  void loop();

  pthread_t thread_{};
  pthread_mutex_t mutex_ = PTHREAD_MUTEX_INITIALIZER;
  pthread_cond_t cv_ = PTHREAD_COND_INITIALIZER;
  bool running_ = false;
  bool stopping_ = false;
  GlobalContext* served_ = nullptr;  // under mutex_
};

}  // namespace track
}  // namespace fw
