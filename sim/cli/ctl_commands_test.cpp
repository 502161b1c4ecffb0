// mml-ctl's arguments: good ones become the codec's frames, bad ones an error naming the argument.
#include "sim/cli/ctl_commands.h"

#include <gtest/gtest.h>

#include "hal_can/codec.h"

namespace sim {
namespace {

TEST(CtlCommands, HintBecomesThreeClassicFramesOrOneFd) {
  CtlArgs a;
  std::string err;
  ASSERT_TRUE(parse_ctl_args({"--iface", "vcan0", "--seq", "7", "hint", "1.5", "-2", "90", "0.3", "10"}, &a, &err)) << err;
  EXPECT_EQ(a.command.kind, hal::CommandKind::kSetPoseHint);
  EXPECT_NEAR(a.command.hint.theta, 1.5707963f, 1e-6f);
  std::vector<hal::CanFrame> f;
  ASSERT_TRUE(ctl_frames(a, &f, &err)) << err;
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(cansend_arg(a.iface, f[0]), "vcan0 140#070000DC05000000");
  hal_can::Decoder d;
  hal_can::Decoded got = hal_can::Decoded::kNothing;
  for (const hal::CanFrame& x : f) got = d.feed(x);
  ASSERT_EQ(got, hal_can::Decoded::kCommand);
  EXPECT_NEAR(d.command().hint.y, -2.0f, 1e-3f);
  a.fd = true;
  ASSERT_TRUE(ctl_frames(a, &f, &err));
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(cansend_arg(a.iface, f[0]).substr(0, 14), "vcan0 540##107");
}

TEST(CtlCommands, SelectMapAndDumpLog) {
  CtlArgs a;
  std::string err;
  ASSERT_TRUE(parse_ctl_args({"select-map", "2"}, &a, &err)) << err;
  std::vector<hal::CanFrame> f;
  ASSERT_TRUE(ctl_frames(a, &f, &err));
  EXPECT_EQ(cansend_arg("can0", f[0]), "can0 148#000200");
  ASSERT_TRUE(parse_ctl_args({"select-map", "1", "--reload"}, &a, &err)) << err;
  ASSERT_TRUE(ctl_frames(a, &f, &err));
  EXPECT_EQ(cansend_arg("can0", f[0]), "can0 148#000101");
  EXPECT_FALSE(parse_ctl_args({"--reload", "dump-log"}, &a, &err));
  EXPECT_NE(err.find("--reload goes with select-map only"), std::string::npos) << err;
  ASSERT_TRUE(parse_ctl_args({"select-map", "1", "3", "4", "0"}, &a, &err)) << err;
  EXPECT_TRUE(a.command.has_hint);
  ASSERT_TRUE(parse_ctl_args({"--print", "dump-log"}, &a, &err)) << err;
  EXPECT_TRUE(a.print);
  ASSERT_TRUE(ctl_frames(a, &f, &err));
  EXPECT_EQ(cansend_arg("can0", f[0]), "can0 149#00");
}

TEST(CtlCommands, BadArgumentsAreNamed) {
  CtlArgs a;
  std::string err;
  EXPECT_FALSE(parse_ctl_args({"hint", "nan", "0", "0"}, &a, &err));
  EXPECT_NE(err.find("x"), std::string::npos) << err;
  EXPECT_FALSE(parse_ctl_args({"hint", "1", "2", "3", "0", "5"}, &a, &err));
  EXPECT_NE(err.find("sigma_m"), std::string::npos) << err;
  EXPECT_FALSE(parse_ctl_args({"hint", "1", "2"}, &a, &err));
  EXPECT_FALSE(parse_ctl_args({"select-map", "300"}, &a, &err));
  EXPECT_FALSE(parse_ctl_args({"reboot"}, &a, &err));
  EXPECT_NE(err.find("reboot"), std::string::npos) << err;
  EXPECT_FALSE(parse_ctl_args({}, &a, &err));
  EXPECT_FALSE(parse_ctl_args({"--bogus", "dump-log"}, &a, &err));
}

}  // namespace
}  // namespace sim
