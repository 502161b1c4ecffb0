#include "firmware/app/app_config.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstring>
#include <initializer_list>
#include <string>

namespace fw {
namespace {

Status parse(const std::string& s, AppConfig* c) { return parse_app_config("t.conf", s.data(), s.size(), c); }

// A value of `key` (line 3 of a minimal config) and what its refusal must say.
struct RefusedValue {
  const char* value;
  const char* must_contain;
};
void expect_refused(const char* key, std::initializer_list<RefusedValue> cases) {
  for (const RefusedValue& k : cases) {
    AppConfig c;
    const std::string text = std::string("laser = socketcan:vcan0\nlocalizer = odom\n") + key + " = " + k.value + "\n";
    const Status s = parse(text, &c);
    ASSERT_FALSE(s.is_ok()) << key << " = " << k.value;
    EXPECT_NE(std::strstr(s.message(), k.must_contain), nullptr) << s.message();
  }
}

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

// Issue 13 reproducers: input that used to be accepted silently (or reported wrongly).
TEST(AppConfig, BaudOverflowIsAnErrorNamingLineAndKey) {
  AppConfig c;
  // 4295005696 = 2^32 + 38400: it used to wrap around and run at 38400 Bd.
  Status s = parse("localizer = odom\nlaser = serial:/dev/ttyUSB0@4295005696\n", &c);
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(std::strstr(s.message(), "line 2: key 'laser'"), nullptr) << s.message();
  EXPECT_NE(std::strstr(s.message(), "baud '4295005696'"), nullptr) << s.message();
  for (const char* bad : {"@", "@-9600", "@9600x", "@12345", "@99999999999999999999999", "@0"}) {
    s = parse(std::string("localizer = odom\nlaser = serial:/dev/ttyS0") + bad + "\n", &c);
    EXPECT_FALSE(s.is_ok()) << bad;
    EXPECT_NE(std::strstr(s.message(), "key 'laser'"), nullptr) << s.message();
  }
  for (const char* good : {"", "@9600", "@38400", "@500000"}) {
    s = parse(std::string("localizer = odom\nlaser = serial:/dev/ttyS0") + good + "\n", &c);
    EXPECT_TRUE(s.is_ok()) << good << ": " << s.message();
  }
}

TEST(AppConfig, DuplicateKeysAreAnErrorNamingBothLines) {
  AppConfig c;
  Status s = parse("laser = socketcan:vcan0\nlocalizer = odom\nlaser = socketcan:vcan1\n", &c);
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(std::strstr(s.message(), "line 3: key 'laser' set again (first set on line 1)"), nullptr) << s.message();
  s = parse("laser = socketcan:vcan0\nlocalizer = odom\nworkers = 2\n# comment\nworkers = 3\n", &c);
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(std::strstr(s.message(), "line 5: key 'workers' set again (first set on line 3)"), nullptr) << s.message();
}

TEST(AppConfig, LineWithNulIsAnErrorNotDropped) {
  AppConfig c;
  // A line starting with NUL used to vanish (here: the localizer would silently stay mml-track).
  const std::string text = std::string("laser = socketcan:vcan0\nmap = /tmp/x.mmap\n") + '\0' + "localizer = odom\n";
  Status s = parse(text, &c);
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(std::strstr(s.message(), "line 3: NUL byte at column 1"), nullptr) << s.message();
  const std::string mid = std::string("laser = socketcan:vcan0\nlocalizer = odom") + '\0' + "x\n";
  s = parse(mid, &c);
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(std::strstr(s.message(), "line 2: NUL byte at column 17"), nullptr) << s.message();
}

TEST(AppConfig, LongPathNeverCutsLineKeyOrProblem) {
  AppConfig c;
  const std::string dir = "/very/long/deployment/path/" + std::string(180, 'd') + "/";
  const std::string path = dir + "robot.conf";
  const std::string text = "laser = socketcan:vcan0\nlocalizer = odom\nstep_deadline_ms = not-a-number\n";
  Status s = parse_app_config(path.c_str(), text.data(), text.size(), &c);
  ASSERT_FALSE(s.is_ok());
  const std::string m = s.message();
  EXPECT_NE(m.find("robot.conf' line 3: key 'step_deadline_ms': 'not-a-number' is not a number in 0.1..1000"),
            std::string::npos)
      << m;
  EXPECT_LT(m.size(), Status::kMessageCapacity - 1) << m;  // nothing cut
  // A long map path (the map key allows 255 characters) with the problem after it still fits.
  const std::string map_path = "/" + std::string(250, 'm');
  Status t = Status::error(Errc::kCorruptData, "map image '%s': header says %llu bytes, the file has %llu (truncated, "
                           "padded or still being written)", map_path.c_str(), 123456789ull, 4096ull);
  EXPECT_NE(std::strstr(t.message(), "still being written)"), nullptr) << t.message();
}

TEST(AppConfig, LongLaserValueIsReportedAsTooLong) {
  AppConfig c;
  // 96..127 characters: accepted (the board keeps 127), not "not KIND:ARG".
  const std::string dev100 = "serial:/dev/serial/by-id/" + std::string(75, 'u');
  ASSERT_EQ(dev100.size(), 100u);
  Status s = parse("localizer = odom\nlaser = " + dev100 + "\n", &c);
  ASSERT_TRUE(s.is_ok()) << s.message();
  EXPECT_STREQ(c.laser, dev100.c_str());
  // 128 and more: "value too long", naming the line and key.
  const std::string dev140 = "serial:/dev/serial/by-id/" + std::string(115, 'u');
  s = parse("localizer = odom\nlaser = " + dev140 + "\n", &c);
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(std::strstr(s.message(), "line 2: key 'laser': value too long (140 characters, at most 127)"), nullptr)
      << s.message();
  s = parse("localizer = odom\nlaser = socketcan:a_very_long_can_interface\n", &c);
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(std::strstr(s.message(), "interface name too long (25 characters, at most 15)"), nullptr) << s.message();
}

TEST(AppConfig, LaserTimeoutKey) {
  AppConfig c;
  ASSERT_TRUE(parse("laser = socketcan:vcan0\nlocalizer = odom\n", &c).is_ok());
  EXPECT_EQ(c.laser_timeout_ms, 500u);
  ASSERT_TRUE(parse("laser = socketcan:vcan0\nlocalizer = odom\nlaser_timeout_ms = 250\n", &c).is_ok());
  EXPECT_EQ(c.laser_timeout_ms, 250u);
  Status s = parse("laser = socketcan:vcan0\nlocalizer = odom\nlaser_timeout_ms = 0\n", &c);
  EXPECT_NE(std::strstr(s.message(), "line 3: key 'laser_timeout_ms'"), nullptr) << s.message();
}

// odom_noise: the tracker's odometry noise model, AMCL's four α (defaults 0.2); malformed values name
// the line, the key and which of the four numbers is wrong.
TEST(AppConfig, OdomNoiseKey) {
  AppConfig c;
  ASSERT_TRUE(parse("laser = socketcan:vcan0\nlocalizer = odom\n", &c).is_ok());
  for (const float a : c.odom_noise) EXPECT_FLOAT_EQ(a, 0.2f);
  ASSERT_TRUE(parse("laser = socketcan:vcan0\nlocalizer = odom\nodom_noise = 0.1, 0.05,0.3 , 0.25\n", &c).is_ok());
  EXPECT_FLOAT_EQ(c.odom_noise[0], 0.1f);
  EXPECT_FLOAT_EQ(c.odom_noise[1], 0.05f);
  EXPECT_FLOAT_EQ(c.odom_noise[2], 0.3f);
  EXPECT_FLOAT_EQ(c.odom_noise[3], 0.25f);
  expect_refused("odom_noise",
                 {{"0.1, 0.2, 0.3", "line 3: key 'odom_noise': '0.1, 0.2, 0.3' is not 4 numbers TT, TR, RR, RT"},
                  {"0.1,0.2,0.3,0.4,0.5", "is not 4 numbers TT, TR, RR, RT"},
                  {"0.1,x,0.3,0.4", "number 2 'x' is not in 0..10"},
                  {"-1,0,0,0", "number 1 '-1' is not in 0..10"},
                  {"0.1,0.2,0.3,11", "number 4 '11' is not in 0..10"},
                  {"0.1,0.2,0.3,nan", "number 4 'nan'"}});
}

// blackbox = PATH | off and blackbox_frames (issue 60): off by default; the ring's size is bounded.
TEST(AppConfig, BlackBoxKeys) {
  AppConfig c;
  ASSERT_TRUE(parse("laser = socketcan:vcan0\nlocalizer = odom\n", &c).is_ok());
  EXPECT_EQ(c.blackbox[0], '\0');
  EXPECT_EQ(c.blackbox_frames, 65536u);
  ASSERT_TRUE(parse("laser = socketcan:vcan0\nlocalizer = odom\nblackbox = /var/lib/mmlfw/bb.log\nblackbox_frames = 1000\n",
                    &c).is_ok());
  EXPECT_STREQ(c.blackbox, "/var/lib/mmlfw/bb.log");
  EXPECT_EQ(c.blackbox_frames, 1000u);
  ASSERT_TRUE(parse("laser = socketcan:vcan0\nlocalizer = odom\nblackbox = off\n", &c).is_ok());
  EXPECT_EQ(c.blackbox[0], '\0');
  expect_refused("blackbox_frames", {{"-1", "line 3: key 'blackbox_frames': '-1' is not an integer in 0..4194304"},
                                     {"99999999", "is not an integer"},
                                     {"x", "is not an integer"}});
  // A serial laser's ring (its chunks of up to 64 bytes).
  EXPECT_EQ(c.blackbox_serial_chunks, 65536u);
  ASSERT_TRUE(parse("laser = sick:/dev/ttyS0\nlocalizer = odom\nblackbox = /tmp/bb.log\nblackbox_serial_chunks = 2000\n",
                    &c).is_ok());
  EXPECT_EQ(c.blackbox_serial_chunks, 2000u);
  expect_refused("blackbox_serial_chunks", {{"-1", "key 'blackbox_serial_chunks': '-1' is not an integer in 0..4194304"}});
  expect_refused("blackbox_size", {{"1", "unknown key 'blackbox_size'"}});
  expect_refused("blackbox", {{std::string(300, 'a').c_str(), "path longer than 255 characters"}});
}

// odom_slip: declared wheel slips per 100 m and the largest (default none: 0, 1 m).
TEST(AppConfig, OdomSlipKey) {
  AppConfig c;
  ASSERT_TRUE(parse("laser = socketcan:vcan0\nlocalizer = odom\n", &c).is_ok());
  EXPECT_FLOAT_EQ(c.odom_slip[0], 0.0f);
  EXPECT_FLOAT_EQ(c.odom_slip[1], 1.0f);
  ASSERT_TRUE(parse("laser = socketcan:vcan0\nlocalizer = odom\nodom_slip = 2, 0.8\n", &c).is_ok());
  EXPECT_FLOAT_EQ(c.odom_slip[0], 2.0f);
  EXPECT_FLOAT_EQ(c.odom_slip[1], 0.8f);
  expect_refused("odom_slip", {{"2", "line 3: key 'odom_slip': '2' is not 2 numbers RATE, MAX_M"},
                               {"2,200", "number 2 '200' is not in 0..100"},
                               {"-1,1", "number 1 '-1'"}});
}

// odom_noise_per_step: σ per scan step that does not follow the motion (metres, degrees; default 0, 0).
TEST(AppConfig, OdomNoisePerStepKey) {
  AppConfig c;
  ASSERT_TRUE(parse("laser = socketcan:vcan0\nlocalizer = odom\n", &c).is_ok());
  EXPECT_FLOAT_EQ(c.odom_noise_per_step[0], 0.0f);
  EXPECT_FLOAT_EQ(c.odom_noise_per_step[1], 0.0f);
  ASSERT_TRUE(parse("laser = socketcan:vcan0\nlocalizer = odom\nodom_noise_per_step = 0.04, 4\n", &c).is_ok());
  EXPECT_FLOAT_EQ(c.odom_noise_per_step[0], 0.04f);
  EXPECT_FLOAT_EQ(c.odom_noise_per_step[1], 4.0f);
  expect_refused("odom_noise_per_step", {{"0.04", "line 3: key 'odom_noise_per_step': '0.04' is not 2 numbers M, DEG"},
                                         {"0.04,4,1", "is not 2 numbers"},
                                         {"2,4", "number 1 '2' is not in 0..1 (M, DEG)"},
                                         {"0.04,30", "number 2 '30' is not in 0..28"},
                                         {"0.04,-1", "number 2 '-1'"},
                                         {"inf,1", "number 1 'inf'"}});
}

// global_context (issue 14): thread by default, inline selectable, anything else named.
TEST(AppConfig, GlobalContextKey) {
  AppConfig c;
  ASSERT_TRUE(parse("laser = socketcan:vcan0\nlocalizer = odom\n", &c).is_ok());
  EXPECT_TRUE(c.global_threaded);
  ASSERT_TRUE(parse("laser = socketcan:vcan0\nlocalizer = odom\nglobal_context = inline\n", &c).is_ok());
  EXPECT_FALSE(c.global_threaded);
  Status s = parse("laser = socketcan:vcan0\nlocalizer = odom\nglobal_context = fast\n", &c);
  EXPECT_NE(std::strstr(s.message(), "line 3: key 'global_context'"), nullptr) << s.message();
}

TEST(AppConfig, FifoIsRefusedWithoutBlocking) {
  char dir[] = "/tmp/mmlfw-config-fifo.XXXXXX";
  ASSERT_NE(mkdtemp(dir), nullptr);
  const std::string fifo = std::string(dir) + "/robot.conf";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  AppConfig c;
  Status s = load_app_config(fifo.c_str(), &c);
  unlink(fifo.c_str());
  rmdir(dir);
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(std::strstr(s.message(), "not a regular file"), nullptr) << s.message();
}

TEST(AppConfig, MissingFileNamesThePath) {
  AppConfig c;
  Status s = load_app_config("/nonexistent/mmlfw.conf", &c);
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(std::strstr(s.message(), "/nonexistent/mmlfw.conf"), nullptr);
}

// Issue 59: laser = can | sick | hokuyo | rplidar with the port, the rate and a protocol option.
TEST(AppConfig, LaserKinds) {
  for (const char* ok : {"can:can0", "socketcan:can0", "sick:/dev/ttyS0@500000", "serial:/dev/ttyS0",
                         "hokuyo:/dev/ttyACM0", "hokuyo:/dev/ttyACM0@115200,intensity", "rplidar:/dev/ttyUSB0@256000",
                         "rplidar:/dev/ttyUSB0,express", "rplidar:/dev/ttyUSB0@1000000,force",
                         "rplidar:/dev/ttyUSB0@256000,express,pwm=660,beams=720"}) {
    AppConfig c;
    const Status s = parse(std::string("localizer = odom\nlaser = ") + ok + "\n", &c);
    ASSERT_TRUE(s.is_ok()) << ok << ": " << s.message();
    EXPECT_STREQ(c.laser, ok);
  }
  const RefusedValue refused[] = {{"velodyne:/dev/ttyUSB0", "is not can:IFACE, sick:, hokuyo: or rplidar:DEVICE"},
                                  {"hokuyo:", "is not can:IFACE"},
                                  {"rplidar:@115200", "no device"},
                                  {"rplidar:/dev/ttyUSB0@256001", "baud '256001' is not one of"},
                                  {"hokuyo:/dev/ttyACM0,express", "option 'express' unknown"},
                                  {"rplidar:/dev/ttyUSB0,intensity", "option 'intensity' unknown"},
                                  {"rplidar:/dev/ttyUSB0,express,pwm=2000", "option 'pwm=2000' unknown"},
                                  {"rplidar:/dev/ttyUSB0,beams=0", "option 'beams=0' unknown"},
                                  {"can:an-interface-name-too-long", "interface name too long"}};
  for (const RefusedValue& r : refused) {
    AppConfig c;
    const Status s = parse(std::string("localizer = odom\nlaser = ") + r.value + "\n", &c);
    ASSERT_FALSE(s.is_ok()) << r.value;
    EXPECT_NE(std::strstr(s.message(), r.must_contain), nullptr) << s.message();
  }
}

// laser_mount: the laser's yaw on the robot and whether it hangs upside down.
TEST(AppConfig, LaserMountKey) {
  AppConfig c;
  ASSERT_TRUE(parse("laser = socketcan:vcan0\nlocalizer = odom\n", &c).is_ok());
  EXPECT_FLOAT_EQ(c.laser_mount_yaw_deg, 0.0f);
  EXPECT_FALSE(c.laser_upside_down);
  ASSERT_TRUE(parse("laser = socketcan:vcan0\nlocalizer = odom\nlaser_mount = 180\n", &c).is_ok());
  EXPECT_FLOAT_EQ(c.laser_mount_yaw_deg, 180.0f);
  EXPECT_FALSE(c.laser_upside_down);
  ASSERT_TRUE(parse("laser = socketcan:vcan0\nlocalizer = odom\nlaser_mount = -90, upside-down\n", &c).is_ok());
  EXPECT_FLOAT_EQ(c.laser_mount_yaw_deg, -90.0f);
  EXPECT_TRUE(c.laser_upside_down);
  expect_refused("laser_mount", {{"200", "yaw '200' is not a number of degrees in -180..180"},
                                 {"90, sideways", "'sideways' is not 'upside-down'"},
                                 {"nan", "yaw 'nan'"}});
}

}  // namespace
}  // namespace fw

namespace fw {
namespace {

// Several maps (issue 60): map = id 0, map.1 .. map.3 = ids 1..3, consecutive; map_reload.
TEST(AppConfig, SeveralMapsByIdAndTheirErrors) {
  AppConfig c;
  Status s = parse("laser = socketcan:vcan0\nmap = a.mmap\nmap.1 = b.mmap\nmap.2 = c.mmap\nmap_reload = true\n", &c);
  ASSERT_TRUE(s.is_ok()) << s.message();
  EXPECT_EQ(map_count(c), 3);
  EXPECT_STREQ(map_path(c, 0), "a.mmap");
  EXPECT_STREQ(map_path(c, 1), "b.mmap");
  EXPECT_STREQ(map_path(c, 2), "c.mmap");
  EXPECT_STREQ(map_path(c, 3), "");
  EXPECT_STREQ(map_path(c, 9), "");
  EXPECT_TRUE(c.map_reload);
  s = parse("laser = socketcan:vcan0\nmap = a.mmap\n", &c);
  ASSERT_TRUE(s.is_ok()) << s.message();
  EXPECT_EQ(map_count(c), 1);  // the one-map config as before
  EXPECT_FALSE(c.map_reload);
  struct Bad {
    const char* text;
    const char* must_contain;
  } bad[] = {
      {"map = a.mmap\nmap.0 = b.mmap\n", "line 3: key 'map.0': not a map key: map 0 is 'map'"},
      {"map = a.mmap\nmap.4 = b.mmap\n", "key 'map.4': not a map key"},
      {"map = a.mmap\nmap.x = b.mmap\n", "key 'map.x': not a map key"},
      {"map = a.mmap\nmap.2 = c.mmap\n", "key 'map.2' is set but 'map.1' is not"},
      {"map.1 = b.mmap\n", "key 'map.1' is set but 'map' is not"},
      {"map = a.mmap\nmap.1 = b.mmap\nmap.1 = c.mmap\n", "key 'map.1' set again (first set on line 3)"},
      {"map = a.mmap\nmap_reload = sometimes\n", "key 'map_reload': 'sometimes' is not true or false"},
  };
  for (const Bad& b : bad) {
    s = parse(std::string("laser = socketcan:vcan0\n") + b.text, &c);
    ASSERT_FALSE(s.is_ok()) << b.text;
    EXPECT_NE(std::strstr(s.message(), b.must_contain), nullptr) << s.message();
  }
  s = parse("laser = socketcan:vcan0\nlocalizer = odom\nmap_reload = true\n", &c);
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(std::strstr(s.message(), "'map_reload' needs a map"), nullptr) << s.message();
}

}  // namespace
}  // namespace fw
