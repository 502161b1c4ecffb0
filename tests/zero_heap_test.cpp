// Proof of "no heap allocation after start-up": initialise, then run the steady-state code of
// every firmware module under the allocation counter and require exactly zero allocations.
// Modules add their steady-state loops here (or in their own tests linking mmlfw_alloc_counter).
#include <gtest/gtest.h>

#include <cmath>

#include "firmware/base/arena.h"
#include "firmware/base/memory_report.h"
#include "firmware/base/perf_counter.h"
#include "firmware/base/ring_buffer.h"
#include "firmware/base/rng.h"
#include "firmware/base/se2.h"
#include "firmware/base/worker_pool.h"
#include "firmware/map/edt.h"
#include "firmware/scan/scan_points.h"
#include "hal_sim/stepped_clock.h"
#include "tests/alloc_counter.h"

namespace {

using mmlfw_test::AllocCounter;

TEST(AllocCounterTest, CountsHeapAllocations) {
  if (!AllocCounter::available()) GTEST_SKIP() << "allocation counter unavailable under sanitizers";
  AllocCounter::begin();
  int* p = new int(3);
  void* q = std::malloc(16);
  // Keep the compiler from eliding the new/delete and malloc/free pairs (allowed since C++14).
  asm volatile("" : : "r"(p), "r"(q) : "memory");
  const long n = AllocCounter::end();
  delete p;
  std::free(q);
  EXPECT_EQ(n, 2);  // the counter itself must see allocations, or the zero below proves nothing
}

struct PoolJob {
  float out[16] = {};
  fw::RandomStream streams[16];
  static void run(void* ctx, int w, int) {
    auto* self = static_cast<PoolJob*>(ctx);
    float acc = 0;
    for (int i = 0; i < 1000; ++i) acc += self->streams[w].gaussianf(0.0f, 1.0f);
    self->out[w] = acc;
  }
};

TEST(ZeroHeapTest, BaseScanAndMapSteadyStateAllocateNothing) {
  if (!AllocCounter::available()) GTEST_SKIP() << "allocation counter unavailable under sanitizers";
  // ---- init (heap allowed) ----
  fw::WorkerPool pool;
  fw::WorkerPoolOptions opt;
  opt.num_workers = 2;
  ASSERT_TRUE(pool.start(opt).is_ok());
  static PoolJob job;
  for (int w = 0; w < 2; ++w) job.streams[w].reseed(5, static_cast<std::uint64_t>(w));
  static fw::RingBuffer<fw::Se2f, 512> poses;
  static fw::RingBuffer<float, 64> window;
  fw::StartupArena arena;
  ASSERT_TRUE(arena.init_mapped(1 << 20, false, "zero-heap").is_ok());
  auto grid_r = arena.allocate_array<float>(64 * 64, "grid");
  ASSERT_TRUE(grid_r);
  float* grid = *grid_r;
  static int v[64];
  static float z[65], f[64], d[64];
  const fw::EdtScratch scratch{v, z, f, d, 64};
  arena.seal();
  static hal::LaserScan scan;
  scan.beam_count = 181;
  scan.angle_min = -1.5708f;
  scan.angle_increment = 0.017453f;
  scan.range_min = 0.05f;
  scan.range_max = 8.0f;
  static fw::Point2f pts[hal::LaserScan::kMaxBeams];
  hal_sim::SteppedClock clock;
  fw::PerfCounter perf("zero-heap-step");
  fw::RandomStream rng(1, 2);

  // ---- steady state (must not allocate) ----
  AllocCounter::begin();
  for (int step = 0; step < 200; ++step) {
    fw::PerfScope scope(perf, clock);
    clock.advance_ns(1000);
    pool.run(&PoolJob::run, &job);
    poses.clear();
    fw::Se2f pose;
    for (int i = 0; i < 500; ++i) {
      pose = pose.compose(fw::Se2f(0.01f, 0.0f, rng.gaussianf(0.0f, 0.01f)));
      (void)poses.push(pose);
    }
    window.push_overwrite(pose.x);
    for (std::uint32_t b = 0; b < scan.beam_count; ++b) scan.ranges[b] = 1.0f + rng.uniform01f();
    fw::ScanPointsResult res;
    (void)fw::scan_to_points(scan, {}, pts, hal::LaserScan::kMaxBeams, &res);
    for (int c = 0; c < 64 * 64; ++c) grid[c] = (c % 97 == 0) ? 0.0f : fw::kEdtInf;
    const std::size_t dims[2] = {64, 64};
    fw::squared_edt<2>(grid, dims, scratch);
  }
  const long allocations = AllocCounter::end();
  EXPECT_EQ(allocations, 0) << "heap allocations after init: " << allocations << " (" << AllocCounter::bytes()
                            << " bytes)";
  EXPECT_EQ(perf.stats().count, 200u);
}

}  // namespace
