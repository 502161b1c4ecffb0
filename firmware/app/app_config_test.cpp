#include "firmware/app/app_config.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>

namespace fw {
namespace {

Status parse(const std::string& s, AppConfig* c) { return parse_app_config("t.conf", s.data(), s.size(), c); }

TEST(AppConfig, ParsesAllKeys) {
  AppConfig c;
  Status s = parse(
      "# robot\nlaser = socketcan:vcan0\nodometry=socketcan:vcan0\noutput = socketcan:vcan0  # same bus\n"
      "can_fd = true\nlocalizer = mml\nmap = /tmp/aces.mmap\nworkers = 3\ncores = 0, 1 ,2\nrealtime = false\n"
      "arena_mib = 64\nstep_deadline_ms = 13.3\nhealth_period_ms = 100\nseed = 7\nlog_level = warning\nmml_preset = 2\n",
      &c);
  ASSERT_TRUE(s.is_ok()) << s.message();
  EXPECT_STREQ(c.laser, "socketcan:vcan0");
  EXPECT_EQ(c.can_fd, 1);
  EXPECT_STREQ(c.localizer, "mml");
  EXPECT_EQ(c.workers, 3);
  EXPECT_EQ(c.num_cores, 3);
  EXPECT_EQ(c.cores[2], 2);
  EXPECT_EQ(c.arena_mib, 64u);
  EXPECT_NEAR(c.step_deadline_ms, 13.3, 1e-9);
  EXPECT_EQ(c.seed, 7u);
  EXPECT_EQ(c.log_level, 2);
  EXPECT_EQ(c.mml_preset, 2);
}

TEST(AppConfig, ErrorsNameTheKey) {
  struct Case {
    const char* text;
    const char* must_contain;
  } cases[] = {
      {"odometry = none\n", "key 'laser' is required"},
      {"laser = can0\n", "key 'laser'"},
      {"laser = socketcan:vcan0\nworkers = 0\n", "key 'workers'"},
      {"laser = socketcan:vcan0\nworkers = two\n", "line 2: key 'workers'"},
      {"laser = socketcan:vcan0\ncan_fd = maybe\n", "key 'can_fd'"},
      {"laser = socketcan:vcan0\nlocalizer = magic\n", "key 'localizer'"},
      {"laser = socketcan:vcan0\nlocalizer = mml\n", "key 'map' is required"},
      {"laser = socketcan:vcan0\nmml_preset = 5\n", "line 2: key 'mml_preset'"},
      {"laser = socketcan:vcan0\nfrobnicate = 1\n", "unknown key 'frobnicate'"},
      {"laser = socketcan:vcan0\nstep_deadline_ms = nan\n", "key 'step_deadline_ms'"},
      {"laser = socketcan:vcan0\ncores = 0,x\n", "key 'cores'"},
      {"laser = socketcan:vcan0\nworkers = 4\ncores = 0,1\nlocalizer = odom\n", "key 'cores'"},
      {"laser = socketcan:vcan0\n", "key 'map' is required for localizer 'mml-track'"},
      {"laser = socketcan:vcan0\njust some words\n", "line 2"},
      {"laser =\n", "key 'laser': empty value"},
      {"laser = socketcan:vcan0\noutput = serial:/dev/ttyS0\n", "key 'output'"},
  };
  for (const Case& k : cases) {
    AppConfig c;
    Status s = parse(k.text, &c);
    ASSERT_FALSE(s.is_ok()) << k.text;
    EXPECT_NE(std::strstr(s.message(), k.must_contain), nullptr) << s.message();
  }
}

TEST(AppConfig, MissingFileNamesThePath) {
  AppConfig c;
  Status s = load_app_config("/nonexistent/mmlfw.conf", &c);
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(std::strstr(s.message(), "/nonexistent/mmlfw.conf"), nullptr);
}

}  // namespace
}  // namespace fw
