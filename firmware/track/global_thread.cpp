#include "firmware/track/global_thread.h"

#include "firmware/runtime/rt_thread.h"
#include "firmware/track/global_context.h"

namespace fw {
namespace track {

Status GlobalThread::start(const ExecutionContext& context, bool realtime) {
  if (running_) return Status::error(Errc::kInvalidArgument, "global thread: already started");
  stopping_ = false;
  const int rc = pthread_create(&thread_, nullptr, &GlobalThread::thread_main, this);
  if (rc != 0) return Status::error(Errc::kIoError, "global context: pthread_create failed (%d)", rc);
  running_ = true;
  char warning[160];
  const Status s = apply_execution_context(thread_, context, realtime, warning);
  if (!s) {
    stop();
    return s;
  }
  return Status::ok();
}

void GlobalThread::stop() {
  if (!running_) return;
  pthread_mutex_lock(&mutex_);
  stopping_ = true;
  pthread_cond_broadcast(&cv_);
  pthread_mutex_unlock(&mutex_);
  pthread_join(thread_, nullptr);
  running_ = false;
}

void GlobalThread::serve(GlobalContext* ctx) {
  pthread_mutex_lock(&mutex_);
  served_ = ctx;
  pthread_cond_broadcast(&cv_);  // it may have a job queued already
  pthread_mutex_unlock(&mutex_);
}

void GlobalThread::notify() {
  // Under the mutex: the loop tests the mailbox under it, so the wake-up cannot fall between its
  // test and its wait.
  pthread_mutex_lock(&mutex_);
  pthread_cond_signal(&cv_);
  pthread_mutex_unlock(&mutex_);
}

void* GlobalThread::thread_main(void* self) {
  static_cast<GlobalThread*>(self)->loop();
  return nullptr;
}

void GlobalThread::loop() {
  for (;;) {
    pthread_mutex_lock(&mutex_);
    while (!stopping_ && (served_ == nullptr || !served_->job_queued())) pthread_cond_wait(&cv_, &mutex_);
    GlobalContext* const ctx = stopping_ ? nullptr : served_;
    pthread_mutex_unlock(&mutex_);
    if (ctx == nullptr) return;
    ctx->run_queued_job();
  }
}

}  // namespace track
}  // namespace fw
