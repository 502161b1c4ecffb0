#include <gtest/gtest.h>

#include "firmware/base/arena.h"
#include "firmware/base/fault.h"
#include "firmware/base/object_pool.h"
#include "firmware/base/ring_buffer.h"
#include "firmware/base/static_vector.h"

namespace fw {
namespace {

// Swaps the fatal handler for a counting one while a test provokes a fault on purpose.
struct FaultCatcher {
  static inline int count = 0;
  static void handler(Fault, std::uint32_t) { ++count; }
  FaultHandler prev;
  FaultCatcher() : prev(set_fault_handler(&handler)) { count = 0; clear_faults(); }
  ~FaultCatcher() { set_fault_handler(prev); clear_faults(); }
};

TEST(StaticVectorTest, FullReturnsStatusAndWritesNothing) {
  StaticVector<int, 3> v;
  EXPECT_TRUE(v.push_back(1).is_ok());
  EXPECT_TRUE(v.push_back(2).is_ok());
  EXPECT_TRUE(v.push_back(3).is_ok());
  Status s = v.push_back(4);
  EXPECT_EQ(s.code(), Errc::kCapacityExceeded);
  EXPECT_EQ(v.size(), 3u);
  EXPECT_EQ(v[2], 3);
  v.pop_back();
  EXPECT_EQ(v.size(), 2u);
  EXPECT_EQ(v.high_water(), 3u);
}

TEST(StaticVectorTest, OutOfBoundsIndexRaisesFault) {
  FaultCatcher catcher;
  StaticVector<int, 2> v;
  (void)v.push_back(7);
  (void)v[1];
  EXPECT_EQ(FaultCatcher::count, 1);
  EXPECT_NE(fault_bits() & static_cast<std::uint32_t>(Fault::kIndexOutOfBounds), 0u);
}

TEST(RingBufferTest, FifoOrderAndOverwrite) {
  RingBuffer<int, 3> r;
  EXPECT_TRUE(r.push(1).is_ok());
  EXPECT_TRUE(r.push(2).is_ok());
  EXPECT_TRUE(r.push(3).is_ok());
  EXPECT_EQ(r.push(4).code(), Errc::kCapacityExceeded);
  EXPECT_TRUE(r.push_overwrite(4));  // drops 1
  int out = 0;
  ASSERT_TRUE(r.pop(&out));
  EXPECT_EQ(out, 2);
  EXPECT_EQ(r[0], 3);
  EXPECT_EQ(r.newest(), 4);
  EXPECT_EQ(r.high_water(), 3u);
}

TEST(ObjectPoolTest, AcquireReleaseExhaust) {
  ObjectPool<double, 2> pool;
  auto a = pool.acquire(1.0);
  auto b = pool.acquire(2.0);
  ASSERT_TRUE(a && b);
  auto c = pool.acquire(3.0);
  EXPECT_EQ(c.status().code(), Errc::kCapacityExceeded);
  pool.release(*a);
  auto d = pool.acquire(4.0);
  ASSERT_TRUE(d);
  EXPECT_EQ(**d, 4.0);
  EXPECT_EQ(pool.high_water(), 2u);
}

TEST(ObjectPoolTest, DoubleReleaseRaisesFault) {
  FaultCatcher catcher;
  ObjectPool<int, 2> pool;
  auto a = pool.acquire(1);
  pool.release(*a);
  pool.release(*a);
  EXPECT_EQ(FaultCatcher::count, 1);
  int foreign = 0;
  pool.release(&foreign);
  EXPECT_EQ(FaultCatcher::count, 2);
}

TEST(ArenaTest, BumpAllocationThenSealed) {
  FaultCatcher catcher;
  alignas(64) static unsigned char block[1024];
  StartupArena arena;
  ASSERT_TRUE(arena.init(block, sizeof(block), "test-arena").is_ok());
  auto a = arena.allocate_array<float>(100, "floats");
  ASSERT_TRUE(a);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(*a) % alignof(float), 0u);
  auto big = arena.allocate(2000, 8, "too big");
  EXPECT_EQ(big.status().code(), Errc::kCapacityExceeded);
  arena.seal();
  auto late = arena.allocate(8, 8, "late");
  EXPECT_FALSE(late);
  EXPECT_EQ(FaultCatcher::count, 1);
}

TEST(ArenaTest, RewindReleasesScratchAndKeepsThePeak) {
  alignas(64) static unsigned char block[1024];
  StartupArena arena;
  ASSERT_TRUE(arena.init(block, sizeof(block), "rewind-arena").is_ok());
  ASSERT_TRUE(arena.allocate_array<float>(10, "kept"));
  const std::size_t mark = arena.mark();
  ASSERT_TRUE(arena.allocate_array<float>(200, "scratch"));
  EXPECT_EQ(arena.peak_used(), 840u);
  arena.rewind(mark);
  EXPECT_EQ(arena.used(), 40u);
  EXPECT_EQ(arena.peak_used(), 840u);
  arena.rewind(mark + 100);  // forward is ignored
  EXPECT_EQ(arena.used(), 40u);
  ASSERT_TRUE(arena.allocate_array<float>(200, "again"));  // the space is reused
  arena.seal();
  arena.rewind(mark);  // sealed: nothing is released
  EXPECT_EQ(arena.used(), 840u);
}

TEST(ArenaTest, MappedBlock) {
  StartupArena arena;
  ASSERT_TRUE(arena.init_mapped(1 << 20, false, "mapped-arena").is_ok());
  auto p = arena.allocate_array<int>(1000, "ints");
  ASSERT_TRUE(p);
  (*p)[999] = 5;
  EXPECT_EQ(arena.used(), 4000u);
}

}  // namespace
}  // namespace fw
