// WorkerPool: N threads created once at start-up, each pinned to a configured core (PX4's fixed
// work-queue idea). run() hands one job to every worker and waits for all of them: a barrier.
// Reproducibility is the caller's contract made easy: a job receives its worker index and the
// worker count, partitions work statically by index, writes per-worker results into slot [index],
// and the caller merges slots in index order — so results never depend on scheduling.
// Dispatch allocates nothing (function pointer + context); threads are raw pthreads because
// std::thread allocates its state on the heap.
#pragma once

#include <pthread.h>

#include <atomic>
#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"

namespace fw {

struct WorkerPoolOptions {
  static constexpr int kMaxWorkers = 16;
  int num_workers = 2;
  // Core for worker i; -1 = cores[i] := i. On machines with fewer online CPUs the worker is
  // pinned to (core mod online) with a warning (e.g. the single-CPU user-mode kernel).
  int cores[kMaxWorkers] = {-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1};
  bool realtime = false;   // request SCHED_FIFO (warn and continue when not permitted ...
  bool require_realtime = false;  // ... unless this is set: then start() fails with the reason)
  int priority = 50;       // SCHED_FIFO priority when realtime
  bool pin = true;         // pthread_setaffinity_np
  // Spin-then-block hand-over: a worker that finished polls for the next job this long before it
  // sleeps on the condition variable (run() itself sleeps at once). pRANSAM runs ~17 rounds per MML
  // step; a condition-variable wake costs 0.1-0.5 ms on a virtual machine, so sleeping between
  // rounds tripled the 2-thread step time there (aces p50 15.8 → 4.7 ms). 0 = always block.
  int spin_us = 200;
};

class WorkerPool {
 public:
  using JobFn = void (*)(void* context, int worker_index, int num_workers);

  WorkerPool() = default;
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;
  ~WorkerPool() { stop(); }

  // Creates and pins the threads. Warnings (pinning degraded, no SCHED_FIFO) are counted and the
  // last one is kept in warning(); they are not errors.
  Status start(const WorkerPoolOptions& options);
  void stop();
  bool running() const { return started_; }
  int size() const { return num_workers_; }

  // Runs fn(context, i, N) on every worker i and returns when all have finished.
  // Must not be called from inside a job (raises Fault::kThreading).
  void run(JobFn fn, void* context);

  // Static partition of [0, n) for worker i of N: [begin, end).
  static void partition(std::size_t n, int i, int num, std::size_t* begin, std::size_t* end) {
    *begin = n * static_cast<std::size_t>(i) / static_cast<std::size_t>(num);
    *end = n * static_cast<std::size_t>(i + 1) / static_cast<std::size_t>(num);
  }

  int warning_count() const { return warning_count_; }
  const char* warning() const { return warning_; }
  int core_of(int worker) const { return core_of_[worker]; }

 private:
  struct WorkerArg {
    WorkerPool* pool;
    int index;
  };
  static void* thread_main(void* arg);
  void worker_loop(int index);
  void warn(const char* fmt, ...) __attribute__((format(printf, 2, 3)));

  pthread_t threads_[WorkerPoolOptions::kMaxWorkers] = {};
  WorkerArg args_[WorkerPoolOptions::kMaxWorkers] = {};
  int core_of_[WorkerPoolOptions::kMaxWorkers] = {};
  int num_workers_ = 0;
  bool started_ = false;

  pthread_mutex_t mutex_ = PTHREAD_MUTEX_INITIALIZER;
  pthread_cond_t start_cv_ = PTHREAD_COND_INITIALIZER;
  pthread_cond_t done_cv_ = PTHREAD_COND_INITIALIZER;
  std::atomic<std::uint64_t> generation_{0};  // incremented per job (under mutex_)
  std::atomic<int> remaining_{0};
  int spin_us_ = 50;
  bool stopping_ = false;
  JobFn job_ = nullptr;
  void* job_context_ = nullptr;
  std::atomic<bool> in_run_{false};

  int warning_count_ = 0;
  char warning_[160] = {0};
};

}  // namespace fw
