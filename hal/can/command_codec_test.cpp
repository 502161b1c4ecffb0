// Issue 60: operator commands on the bus, the reply, CanNode's command queue and its black box.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "hal_can/black_box.h"
#include "hal_can/can_node.h"
#include "hal_can/codec.h"
#include "hal_sim/sim_can_bus.h"
#include "hal_sim/stepped_clock.h"

namespace hal_can {
namespace {

hal::Command hint_command(std::uint8_t seq) {
  hal::Command c;
  c.kind = hal::CommandKind::kSetPoseHint;
  c.seq = seq;
  c.has_hint = true;
  c.hint.x = 12.345f;
  c.hint.y = -7.5f;
  c.hint.theta = -3.1f;
  c.hint.sigma_xy_m = 0.25f;
  c.hint.sigma_theta_rad = 0.05f;
  c.hint.map_id = 0;
  return c;
}

TEST(CommandCodec, HintRoundTripsOnClassicAndFd) {
  for (bool fd : {false, true}) {
    hal::CanFrame f[kMaxParts];
    std::size_t n = 0;
    ASSERT_TRUE(encode_command(hint_command(17), fd, f, kMaxParts, &n).is_ok());
    Decoder d;
    Decoded got = Decoded::kNothing;
    for (std::size_t i = 0; i < n; ++i) got = d.feed(f[i]);
    ASSERT_EQ(got, Decoded::kCommand) << fd;
    const hal::Command& c = d.command();
    EXPECT_EQ(c.kind, hal::CommandKind::kSetPoseHint);
    EXPECT_EQ(c.seq, 17);
    EXPECT_TRUE(c.has_hint);
    EXPECT_NEAR(c.hint.x, 12.345f, 1e-3f);
    EXPECT_NEAR(c.hint.y, -7.5f, 1e-3f);
    EXPECT_NEAR(c.hint.theta, -3.1f, 1e-6f);
    EXPECT_GE(c.hint.sigma_xy_m, 0.25f - 1e-6f);  // rounded up: an uncertainty never shrinks
    EXPECT_GE(c.hint.sigma_theta_rad, 0.05f - 1e-6f);
    EXPECT_EQ(d.stats().commands_ok, 1u);
  }
}

TEST(CommandCodec, SelectMapWithAndWithoutHintAndDumpLog) {
  hal::CanFrame f[kMaxParts];
  std::size_t n = 0;
  hal::Command c = hint_command(3);
  c.kind = hal::CommandKind::kSelectMap;
  c.map_id = 2;
  ASSERT_TRUE(encode_command(c, false, f, kMaxParts, &n).is_ok());
  Decoder d;
  Decoded got = Decoded::kNothing;
  for (std::size_t i = 0; i < n; ++i) got = d.feed(f[i]);
  ASSERT_EQ(got, Decoded::kCommand);
  EXPECT_EQ(d.command().kind, hal::CommandKind::kSelectMap);
  EXPECT_EQ(d.command().map_id, 2);
  EXPECT_TRUE(d.command().has_hint);
  c.has_hint = false;
  ASSERT_TRUE(encode_command(c, false, f, kMaxParts, &n).is_ok());
  ASSERT_EQ(n, 1u);
  ASSERT_EQ(d.feed(f[0]), Decoded::kCommand);
  EXPECT_FALSE(d.command().has_hint);
  EXPECT_EQ(d.command().map_id, 2);
  EXPECT_FALSE(d.command().reload);
  // The reload flag: on the plain frame (byte 2) and in a hint record (flags bit 1).
  c.reload = true;
  ASSERT_TRUE(encode_command(c, false, f, kMaxParts, &n).is_ok());
  ASSERT_EQ(d.feed(f[0]), Decoded::kCommand);
  EXPECT_TRUE(d.command().reload);
  f[0].data[2] = 0x80;  // a reserved flag
  EXPECT_EQ(d.feed(f[0]), Decoded::kNothing);
  f[0].len = 2;         // an older sender's 2-byte frame: no reload
  ASSERT_EQ(d.feed(f[0]), Decoded::kCommand);
  EXPECT_FALSE(d.command().reload);
  c.has_hint = true;
  ASSERT_TRUE(encode_command(c, true, f, kMaxParts, &n).is_ok());
  for (std::size_t i = 0; i < n; ++i) got = d.feed(f[i]);
  ASSERT_EQ(got, Decoded::kCommand);
  EXPECT_TRUE(d.command().reload);
  EXPECT_TRUE(d.command().has_hint);
  c.reload = false;
  c.kind = hal::CommandKind::kDumpLog;
  c.seq = 99;
  ASSERT_TRUE(encode_command(c, true, f, kMaxParts, &n).is_ok());
  ASSERT_EQ(d.feed(f[0]), Decoded::kCommand);
  EXPECT_EQ(d.command().kind, hal::CommandKind::kDumpLog);
  EXPECT_EQ(d.command().seq, 99);
}

TEST(CommandCodec, EncoderRefusesHintsItCannotCarry) {
  hal::CanFrame f[kMaxParts];
  std::size_t n = 0;
  hal::Command c = hint_command(1);
  c.hint.x = NAN;
  fw::Status s = encode_command(c, false, f, kMaxParts, &n);
  EXPECT_FALSE(s.is_ok());
  EXPECT_NE(std::string(s.message()).find("x"), std::string::npos) << s.message();
  c = hint_command(1);
  c.hint.sigma_xy_m = 0.0f;
  s = encode_command(c, false, f, kMaxParts, &n);
  EXPECT_FALSE(s.is_ok());
  EXPECT_NE(std::string(s.message()).find("sigma_xy"), std::string::npos) << s.message();
  c = hint_command(1);
  c.hint.sigma_theta_rad = 7.0f;
  EXPECT_FALSE(encode_command(c, false, f, kMaxParts, &n).is_ok());
  EXPECT_EQ(n, 0u);
}

TEST(CommandCodec, BrokenCommandFramesAreCountedNeverDelivered) {
  hal::CanFrame f[kMaxParts];
  std::size_t n = 0;
  ASSERT_TRUE(encode_command(hint_command(5), false, f, kMaxParts, &n).is_ok());
  Decoder d;
  EXPECT_EQ(d.feed(f[0]), Decoded::kNothing);
  EXPECT_EQ(d.feed(f[2]), Decoded::kNothing);  // part 1 lost
  EXPECT_EQ(d.stats().commands_ok, 0u);
  EXPECT_GE(d.stats().broken_records, 1u);
  hal::CanFrame bad;
  bad.id = kSelectMapId;
  bad.len = 1;  // no map id
  EXPECT_EQ(d.feed(bad), Decoded::kNothing);
  bad.id = kCommandReplyId;
  bad.len = 4;
  bad.data[1] = 1;
  bad.data[2] = 200;  // no such result
  EXPECT_EQ(d.feed(bad), Decoded::kNothing);
  EXPECT_EQ(d.stats().malformed_commands, 2u);
  // Reserved flags of a hint record.
  ASSERT_TRUE(encode_command(hint_command(6), false, f, kMaxParts, &n).is_ok());
  f[0].data[2] = 0x80;  // flags
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(d.feed(f[i]), Decoded::kNothing);
  EXPECT_EQ(d.stats().malformed_commands, 3u);
}

TEST(CommandCodec, ReplyRoundTrips) {
  hal::CommandReply r;
  r.seq = 200;
  r.kind = hal::CommandKind::kDumpLog;
  r.result = hal::CommandResult::kFailed;
  r.detail = 3;
  hal::CanFrame f;
  encode_reply(r, &f);
  Decoder d;
  ASSERT_EQ(d.feed(f), Decoded::kReply);
  EXPECT_EQ(d.reply().seq, 200);
  EXPECT_EQ(d.reply().kind, hal::CommandKind::kDumpLog);
  EXPECT_EQ(d.reply().result, hal::CommandResult::kFailed);
  EXPECT_EQ(d.reply().detail, 3);
}

// CanNode queues commands for the runtime, sends replies, and records both in its black box.
TEST(CanNodeCommands, QueuedRepliedAndRecorded) {
  hal_sim::SimCanBus bus;
  hal_sim::SteppedClock clock;
  clock.set_ns(5'000'123'456ull);
  CanNode node;
  node.init(&bus, &clock, false);
  std::vector<BlackBoxEntry> storage(16);
  BlackBox box;
  box.init(storage.data(), storage.size());
  node.attach_black_box(&box);
  hal::CanFrame f[kMaxParts];
  std::size_t n = 0;
  ASSERT_TRUE(encode_command(hint_command(8), false, f, kMaxParts, &n).is_ok());
  for (std::size_t i = 0; i < n; ++i) {
    f[i].timestamp_ns = 1'000'000'999ull;  // kept to the µs
    ASSERT_TRUE(bus.send(f[i]));
  }
  hal::Command c;
  ASSERT_TRUE(node.commands().poll(&c));
  EXPECT_EQ(c.seq, 8);
  EXPECT_FALSE(node.commands().poll(&c));
  hal::CommandReply r;
  r.seq = 8;
  r.kind = hal::CommandKind::kSetPoseHint;
  node.pose_sink().publish_reply(r);
  ASSERT_EQ(box.size(), 4u);
  char line[BlackBox::kMaxLineBytes];
  ASSERT_GT(box.format_line(0, line, sizeof(line)), 0u);
  EXPECT_STREQ(line, "(1.000000) rx 140#0800003930000000\n");
  ASSERT_GT(box.format_line(3, line, sizeof(line)), 0u);
  EXPECT_STREQ(line, "(5.000123) tx 14F#08010000\n");
  EXPECT_EQ(BlackBox::frame_of(box.entry(0)).timestamp_ns, 1'000'000'000ull);
}

TEST(BlackBoxTest, KeepsTheNewestFramesAndFormatsFd) {
  std::vector<BlackBoxEntry> storage(3);
  BlackBox box;
  box.init(storage.data(), storage.size());
  hal::CanFrame f;
  f.fd = f.brs = true;
  f.len = 12;
  for (int i = 0; i < 5; ++i) {
    f.id = 0x500 + static_cast<std::uint32_t>(i);
    box.record(f, static_cast<std::uint64_t>(i) * 1'500'000'000ull, i % 2 == 1);
  }
  EXPECT_EQ(box.size(), 3u);
  EXPECT_EQ(box.recorded(), 5u);
  EXPECT_EQ(box.overwritten(), 2u);
  EXPECT_EQ(box.entry(0).id, 0x502u);
  char line[BlackBox::kMaxLineBytes];
  ASSERT_GT(box.format_line(1, line, sizeof(line)), 0u);
  EXPECT_STREQ(line, "(4.500000) tx 503##1000000000000000000000000\n");
  EXPECT_EQ(box.format_line(3, line, sizeof(line)), 0u);  // beyond the kept entries
  BlackBox off;
  off.record(f, 1, false);  // never initialised: off, records nothing
  EXPECT_EQ(off.size(), 0u);
}

}  // namespace
}  // namespace hal_can
