// The CAN black box's global records (issue 60): one ring entry each, written as
// "(SEC.USEC) global take|drop SEC.USEC ROUNDS" between the frames, never taken for a frame.
#include "hal_can/black_box.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>

namespace hal_can {
namespace {

std::string line(const BlackBox& box, std::size_t i) {
  char buf[BlackBox::kMaxLineBytes];
  const std::size_t n = box.format_line(i, buf, sizeof(buf));
  return std::string(buf, n);
}

TEST(BlackBoxGlobalTest, RecordsAreLinesOfTheRing) {
  BlackBoxEntry storage[4];
  BlackBox box;
  box.init(storage, 4);
  hal::CanFrame f;
  f.id = 0x118;
  f.len = 2;
  f.data[0] = 0xAB;
  f.data[1] = 0x01;
  box.record(f, 1765432100013300000ull, false);
  hal::GlobalRecord r;
  r.scan_ns = 1765432100413300123ull;  // the µs are kept, the ns below them dropped
  r.job_scan_ns = 1765432100013300000ull;
  r.deadline_rounds = 7;
  box.record_global(r);
  r.dropped = true;
  r.deadline_rounds = 0;
  box.record_global(r);
  ASSERT_EQ(box.size(), 3u);
  EXPECT_EQ(line(box, 0), "(1765432100.013300) rx 118#AB01\n");
  EXPECT_EQ(line(box, 1), "(1765432100.413300) global take 1765432100.013300 7\n");
  EXPECT_EQ(line(box, 2), "(1765432100.413300) global drop 1765432100.013300 0\n");
  EXPECT_TRUE(box.entry(1).is_global());
  EXPECT_FALSE(box.entry(0).is_global());
  const hal::GlobalRecord back = BlackBox::global_of(box.entry(1));
  EXPECT_EQ(back.scan_ns, 1765432100413300123ull);
  EXPECT_EQ(back.job_scan_ns, 1765432100013300000ull);
  EXPECT_EQ(back.deadline_rounds, 7u);
  EXPECT_FALSE(back.dropped);
  EXPECT_TRUE(BlackBox::global_of(box.entry(2)).dropped);
}

TEST(BlackBoxGlobalTest, OverwrittenWithTheFrames) {
  BlackBoxEntry storage[2];
  BlackBox box;
  box.init(storage, 2);
  hal::GlobalRecord r;
  r.scan_ns = 2000000000ull;
  r.job_scan_ns = 1000000000ull;
  box.record_global(r);
  hal::CanFrame f;
  f.id = 0x120;
  f.len = 1;
  box.record(f, 3000000000ull, true);
  box.record(f, 4000000000ull, true);
  EXPECT_EQ(box.size(), 2u);
  EXPECT_EQ(box.overwritten(), 1u);
  EXPECT_FALSE(box.entry(0).is_global());
  BlackBox off;
  off.init(nullptr, 0);
  off.record_global(r);  // off: ignored
  EXPECT_EQ(off.size(), 0u);
}

}  // namespace
}  // namespace hal_can
