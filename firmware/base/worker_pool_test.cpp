#include "firmware/base/worker_pool.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "firmware/base/rng.h"

namespace fw {
namespace {

// A job whose result would depend on scheduling if merged in completion order: each worker
// draws from its own stream over its static partition; the caller merges in worker-index order.
struct SumJob {
  static constexpr int kItems = 10000;
  std::uint64_t seed = 0;
  double partial[WorkerPoolOptions::kMaxWorkers] = {};
  static void run(void* ctx, int w, int n) {
    auto* self = static_cast<SumJob*>(ctx);
    std::size_t b, e;
    WorkerPool::partition(kItems, w, n, &b, &e);
    double acc = 0;
    for (std::size_t i = b; i < e; ++i) {
      RandomStream r(self->seed, i);  // stream per item: independent of the worker count
      acc += r.gaussian() * 1e-3 + static_cast<double>(i);
    }
    self->partial[w] = acc;
  }
};

double run_sum(WorkerPool& pool, std::uint64_t seed) {
  SumJob job;
  job.seed = seed;
  pool.run(&SumJob::run, &job);
  double total = 0;
  for (int w = 0; w < pool.size(); ++w) total += job.partial[w];
  return total;
}

TEST(WorkerPoolTest, SameJobSet50TimesOn1And2WorkersIsReproducible) {
  for (int workers : {1, 2}) {
    WorkerPool pool;
    WorkerPoolOptions opt;
    opt.num_workers = workers;
    ASSERT_TRUE(pool.start(opt).is_ok());
    const double first = run_sum(pool, 99);
    for (int rep = 0; rep < 50; ++rep) {
      EXPECT_EQ(run_sum(pool, 99), first) << "workers=" << workers << " rep=" << rep;
    }
    pool.stop();
  }
}

TEST(WorkerPoolTest, EveryWorkerRunsOncePerJob) {
  WorkerPool pool;
  WorkerPoolOptions opt;
  opt.num_workers = 4;  // more workers than cores: pinning degrades with a warning, never fails
  ASSERT_TRUE(pool.start(opt).is_ok());
  struct Count {
    int hits[WorkerPoolOptions::kMaxWorkers] = {};
    static void run(void* ctx, int w, int) { ++static_cast<Count*>(ctx)->hits[w]; }
  } c;
  for (int i = 0; i < 100; ++i) pool.run(&Count::run, &c);
  for (int w = 0; w < 4; ++w) EXPECT_EQ(c.hits[w], 100);
}

TEST(WorkerPoolTest, RejectsBadWorkerCount) {
  WorkerPool pool;
  WorkerPoolOptions opt;
  opt.num_workers = 0;
  EXPECT_EQ(pool.start(opt).code(), Errc::kInvalidArgument);
  opt.num_workers = 99;
  EXPECT_EQ(pool.start(opt).code(), Errc::kInvalidArgument);
}

TEST(WorkerPoolTest, PartitionCoversRangeExactly) {
  for (int n = 1; n <= 5; ++n) {
    std::size_t covered = 0, prev_end = 0;
    for (int i = 0; i < n; ++i) {
      std::size_t b, e;
      WorkerPool::partition(103, i, n, &b, &e);
      EXPECT_EQ(b, prev_end);
      covered += e - b;
      prev_end = e;
    }
    EXPECT_EQ(covered, 103u);
  }
}

}  // namespace
}  // namespace fw
