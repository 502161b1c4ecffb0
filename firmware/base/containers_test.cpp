#include <gtest/gtest.h>

#include "firmware/base/arena.h"
#include "firmware/base/fault.h"
#include "firmware/base/ring_buffer.h"

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
