#include "firmware/base/worker_pool.h"

#include <sched.h>
#include <unistd.h>

#include <cerrno>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <ctime>

#include "firmware/base/fault.h"

namespace fw {
namespace {

inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__) || defined(__arm__)
  asm volatile("yield" ::: "memory");
#endif
}

std::uint64_t monotonic_ns() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000000ull + static_cast<std::uint64_t>(ts.tv_nsec);
}

// Polls done() for up to spin_us microseconds (yielding now and then, so a thread sharing the core
// can run); true when it became true.
template <typename Done>
bool spin_until(Done done, int spin_us) {
  if (spin_us <= 0) return done();
  const std::uint64_t end = monotonic_ns() + static_cast<std::uint64_t>(spin_us) * 1000ull;
  for (std::uint32_t i = 1;; ++i) {
    if (done()) return true;
    cpu_relax();
    if ((i & 63u) == 0) {
      if (monotonic_ns() >= end) return done();
      sched_yield();
    }
  }
}

}  // namespace

void WorkerPool::warn(const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(warning_, sizeof(warning_), fmt, args);
  va_end(args);
  ++warning_count_;
  std::fprintf(stderr, "warning: worker pool: %s\n", warning_);
}

Status WorkerPool::start(const WorkerPoolOptions& options) {
  if (started_) return Status::error(Errc::kInvalidArgument, "worker pool: start called twice");
  if (options.num_workers < 1 || options.num_workers > WorkerPoolOptions::kMaxWorkers) {
    return Status::error(Errc::kInvalidArgument, "worker pool: num_workers %d outside [1, %d]",
                         options.num_workers, WorkerPoolOptions::kMaxWorkers);
  }
  long online = sysconf(_SC_NPROCESSORS_ONLN);
  if (online < 1) online = 1;
  num_workers_ = options.num_workers;
  stopping_ = false;
  generation_.store(0);
  spin_us_ = options.spin_us < 0 ? 0 : options.spin_us;
  for (int i = 0; i < num_workers_; ++i) {
    int core = options.cores[i] >= 0 ? options.cores[i] : i;
    if (core >= online) {
      warn("worker %d: core %d not online (%ld CPUs), pinned to core %ld instead", i, core, online,
           static_cast<long>(core) % online);
      core = static_cast<int>(core % online);
    }
    core_of_[i] = core;
    args_[i] = WorkerArg{this, i};
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    if (options.realtime) {
      sched_param sp{};
      sp.sched_priority = options.priority;
      pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED);
      pthread_attr_setschedpolicy(&attr, SCHED_FIFO);
      pthread_attr_setschedparam(&attr, &sp);
    }
    int rc = pthread_create(&threads_[i], &attr, &WorkerPool::thread_main, &args_[i]);
    if (rc == EPERM && options.realtime && options.require_realtime) {
      pthread_attr_destroy(&attr);
      num_workers_ = i;
      started_ = num_workers_ > 0;
      stop();
      return Status::error(Errc::kIoError,
                           "worker pool: realtime = true but SCHED_FIFO priority %d was refused for worker %d (needs "
                           "CAP_SYS_NICE or RLIMIT_RTPRIO; set realtime = false to run without)",
                           options.priority, i);
    }
    if (rc == EPERM && options.realtime) {
      warn("worker %d: SCHED_FIFO not permitted (EPERM); running with the default scheduler", i);
      pthread_attr_setinheritsched(&attr, PTHREAD_INHERIT_SCHED);
      rc = pthread_create(&threads_[i], &attr, &WorkerPool::thread_main, &args_[i]);
    }
    pthread_attr_destroy(&attr);
    if (rc != 0) {
      num_workers_ = i;
      started_ = num_workers_ > 0;
      stop();
      return Status::error(Errc::kIoError, "worker pool: pthread_create for worker %d failed: %s", i, std::strerror(rc));
    }
    if (options.pin) {
      cpu_set_t set;
      CPU_ZERO(&set);
      CPU_SET(core, &set);
      const int prc = pthread_setaffinity_np(threads_[i], sizeof(set), &set);
      if (prc != 0) warn("worker %d: pinning to core %d failed: %s", i, core, std::strerror(prc));
    }
  }
  started_ = true;
  return Status::ok();
}

void WorkerPool::stop() {
  if (!started_) return;
  pthread_mutex_lock(&mutex_);
  stopping_ = true;
  generation_.fetch_add(1);
  pthread_cond_broadcast(&start_cv_);
  pthread_mutex_unlock(&mutex_);
  for (int i = 0; i < num_workers_; ++i) pthread_join(threads_[i], nullptr);
  started_ = false;
  num_workers_ = 0;
}

void* WorkerPool::thread_main(void* arg) {
  WorkerArg* a = static_cast<WorkerArg*>(arg);
  a->pool->worker_loop(a->index);
  return nullptr;
}

void WorkerPool::worker_loop(int index) {
  std::uint64_t seen = 0;
  for (;;) {
    spin_until([&] { return generation_.load(std::memory_order_acquire) != seen; }, spin_us_);
    pthread_mutex_lock(&mutex_);
    while (generation_.load() == seen) pthread_cond_wait(&start_cv_, &mutex_);
    seen = generation_.load();
    if (stopping_) {
      pthread_mutex_unlock(&mutex_);
      return;
    }
    JobFn fn = job_;
    void* ctx = job_context_;
    const int n = num_workers_;
    pthread_mutex_unlock(&mutex_);

    fn(ctx, index, n);

    // The last worker wakes run(); run() re-checks remaining_ under mutex_ before it sleeps, so
    // signalling under the mutex cannot be lost.
    if (remaining_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
      pthread_mutex_lock(&mutex_);
      pthread_cond_signal(&done_cv_);
      pthread_mutex_unlock(&mutex_);
    }
  }
}

void WorkerPool::run(JobFn fn, void* context) {
  if (!started_) {
    // No threads (e.g. a 0-worker configuration): run inline as worker 0 of 1.
    fn(context, 0, 1);
    return;
  }
  bool expected = false;
  if (!in_run_.compare_exchange_strong(expected, true)) {
    raise_fault(Fault::kThreading);
    return;
  }
  pthread_mutex_lock(&mutex_);
  job_ = fn;
  job_context_ = context;
  remaining_.store(num_workers_);
  generation_.fetch_add(1);  // seq_cst: job_, job_context_ and remaining_ are visible with it
  pthread_cond_broadcast(&start_cv_);
  // The caller only waits: it sleeps at once and leaves the cores to the pinned workers (its
  // spinning would steal a worker's core on a 2-core board); the workers spin between jobs.
  while (remaining_.load() > 0) pthread_cond_wait(&done_cv_, &mutex_);
  pthread_mutex_unlock(&mutex_);
  in_run_.store(false);
}

}  // namespace fw
