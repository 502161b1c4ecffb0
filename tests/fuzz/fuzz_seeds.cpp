// fuzz_seeds OUT_DIR: writes the seed corpus of every fuzz target into OUT_DIR/<target>/, made by
// the project's own writers (CAN encoder, SICK encoder, map image writer + relation table builder,
// ROS map writer, CARMEN / relations / trajectory writers) from the first records of the real logs
// in $MMLFW_DATA_DIR (intel, aces, fr-clinic). Without the data a synthetic room and scan are
// used instead (and the fact is printed). Seeds are small: the fuzzer mutates from real shapes.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "hal_can/codec.h"
#include "hal_serial/rplidar_protocol.h"
#include "hal_serial/scip.h"
#include "hal_serial/sick_telegram.h"
#include "sim/io/carmen_log.h"
#include "sim/io/relations.h"
#include "sim/io/ros_map.h"
#include "sim/map/map_image_writer.h"
#include "sim/map/occupancy_builder.h"
#include "sim/map/relation_table_builder.h"
#include "tests/fuzz/byte_reader.h"
#include "tests/fuzz/can_fuzz_ops.h"
#include "tests/fuzz/serial_lidar_fuzz_ops.h"
#include "tests/fuzz/sick_fuzz_ops.h"

namespace fs = std::filesystem;

namespace {

std::string g_out;
int g_written = 0;

void die(const std::string& msg) {
  std::fprintf(stderr, "fuzz_seeds: %s\n", msg.c_str());
  std::exit(1);
}

void put(const std::string& target, const std::string& name, const std::vector<std::uint8_t>& bytes) {
  const fs::path dir = fs::path(g_out) / target;
  fs::create_directories(dir);
  std::ofstream f(dir / name, std::ios::binary);
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!f) die("cannot write " + (dir / name).string());
  ++g_written;
}
std::vector<std::uint8_t> to_bytes(const std::string& s) { return {s.begin(), s.end()}; }
std::vector<std::uint8_t> with_flag(std::uint8_t flag, const std::vector<std::uint8_t>& b) {
  std::vector<std::uint8_t> v{flag};
  v.insert(v.end(), b.begin(), b.end());
  return v;
}
std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}
std::string first_lines(const std::string& text, int n, const std::string& prefix_filter = "") {
  std::istringstream in(text);
  std::string line, out;
  for (int k = 0; k < n && std::getline(in, line);) {
    if (!prefix_filter.empty() && line.rfind(prefix_filter, 0) != 0 && line.rfind("ODOM", 0) != 0 &&
        line.rfind("PARAM", 0) != 0)
      continue;
    out += line + "\n";
    ++k;
  }
  return out;
}

// The first scans of a real log (or a synthetic room seen from its centre).
struct Source {
  std::vector<sim::CarmenScan> scans;
  std::string intel_text, aces_text, clinic_text, relations_text;
  bool real = false;
};

Source load_source() {
  Source s;
  const char* d = std::getenv("MMLFW_DATA_DIR");
  const std::string dir = d ? d : "";
  std::string err;
  if (!dir.empty() && fs::exists(dir + "/intel/intel.clf.gz")) {
    std::string text;
    if (!sim::read_file_maybe_gz(dir + "/intel/intel.clf.gz", &text, &err)) die(err);
    s.intel_text = first_lines(text, 60);
    if (sim::read_file_maybe_gz(dir + "/aces/aces.clf.gz", &text, &err)) s.aces_text = first_lines(text, 30);
    if (sim::read_file_maybe_gz(dir + "/fr-clinic/fr-clinic_robotlaser.clf.gz", &text, &err))
      s.clinic_text = first_lines(text, 20, "ROBOTLASER1");
    s.relations_text = first_lines(slurp(dir + "/intel/intel.relations"), 40);
    sim::CarmenLog log;
    sim::CarmenReadOptions opt;
    if (!sim::parse_carmen_log("intel head", s.intel_text.data(), s.intel_text.size(), opt, &log, &err)) die(err);
    s.scans = log.scans;
    s.real = !s.scans.empty();
  }
  if (!s.real) {
    std::printf("fuzz_seeds: NOTE: no real logs in '%s'; seeds from a synthetic 8 x 6 m room\n", dir.c_str());
    for (int k = 0; k < 20; ++k) {
      sim::CarmenScan sc;
      sc.type = "FLASER";
      sc.ipc_timestamp = 1000.0 + 0.1 * k;
      sc.pose = fw::Se2d(0.05 * k, 0.0, 0.0);
      sc.odom = sc.pose;
      sc.angle_min = -1.5707963f;
      sc.angle_increment = 3.14159265f / 180.0f;
      sc.max_range = 81.83f;
      for (int i = 0; i < 180; ++i) {
        const double a = sc.angle_min + i * sc.angle_increment;
        const double dx = std::cos(a) > 0 ? (4.0 - sc.pose.x) / std::cos(a) : 1e9;
        const double dy = std::abs(std::sin(a)) > 1e-6 ? 3.0 / std::abs(std::sin(a)) : 1e9;
        sc.ranges.push_back(static_cast<float>(std::min(dx, dy)));
      }
      s.scans.push_back(sc);
    }
    sim::CarmenLog log;
    log.scans = s.scans;
    const std::string tmp = (fs::path(g_out) / "synthetic.clf").string();
    if (!sim::write_carmen_log(tmp, log, {}, &err)) die(err);
    s.intel_text = slurp(tmp);
    fs::remove(tmp);
    s.relations_text = "1000.000000 1000.100000 0.05 0 0 0 0 0\n1000.100000 1000.300000 0.1 0 0 0 0 0.01\n";
  }
  return s;
}

void can_seeds(const Source& src) {
  for (int fd = 0; fd < 2; ++fd) {
    fuzz::ByteWriter raw, ops;
    for (std::size_t k = 0; k < src.scans.size() && k < 2; ++k) {
      const hal::LaserScan scan = sim::to_laser_scan(src.scans[k], 1'000'000'000ull + k * 100'000'000ull);
      std::vector<hal::CanFrame> frames(hal_can::kMaxScanFrames);
      std::size_t n = 0;
      hal_can::EncodeOptions eo;
      eo.fd = fd;
      const fw::Status st = hal_can::encode_scan(scan, eo, frames.data(), frames.size(), &n);
      if (!st) die(std::string("encode_scan: ") + st.message());
      // As raw frames ...
      for (std::size_t i = 0; i < n; ++i) {
        const hal::CanFrame& f = frames[i];
        raw.u8(fuzz::kCanRawFrame);
        raw.u16(static_cast<std::uint16_t>(f.id));
        raw.u8(static_cast<std::uint8_t>((f.fd ? 1 : 0) | (f.brs ? 4 : 0)));
        raw.u8(f.len);
        raw.bytes(f.data, f.len);
        raw.u16(100);
      }
      // ... and as a synthetic-scan operation (start payload and range codes from the encoder).
      ops.u8(fuzz::kCanScan);
      ops.u8(static_cast<std::uint8_t>(fd));
      ops.u8(0);
      if (fd) {
        ops.bytes(frames[0].data + 1, 28);
      } else {
        for (int p = 0; p < 4; ++p) ops.bytes(frames[p].data + 1, 7);
      }
      for (std::size_t i = fd ? 1 : 4; i + 1 < n; ++i) {
        const std::size_t per = fd ? hal_can::kFdRangesPerSegment : hal_can::kClassicRangesPerSegment;
        const std::size_t b0 = (i - (fd ? 1 : 4)) * per;
        const std::size_t nb = scan.beam_count - b0 < per ? scan.beam_count - b0 : per;
        ops.bytes(frames[i].data + 2, 2 * nb);
      }
      ops.u8(fuzz::kCanOdometry);
      for (float v : {1.5f, -2.25f, 0.3f, 0.4f, 0.05f}) ops.f32(v);
      ops.u8(static_cast<std::uint8_t>(k));
      ops.u8(static_cast<std::uint8_t>(fd));
      ops.u8(fuzz::kCanHealth);
      ops.u32(12345);
      ops.u16(2);
      ops.u32(1);
      ops.u8(static_cast<std::uint8_t>(k));
      ops.u8(static_cast<std::uint8_t>(fd));
      ops.u8(fuzz::kCanTimeout);
      ops.u32(600);
    }
    // Issue 60: the operator's commands and the reply, as raw frames.
    hal::Command cmds[3];
    cmds[0].kind = hal::CommandKind::kSetPoseHint;
    cmds[0].has_hint = true;
    cmds[0].hint.x = 3.5f;
    cmds[0].hint.y = -1.25f;
    cmds[0].hint.theta = 0.5f;
    cmds[0].hint.sigma_xy_m = 0.2f;
    cmds[0].hint.sigma_theta_rad = 0.1f;
    cmds[1].kind = hal::CommandKind::kSelectMap;
    cmds[1].map_id = 1;
    cmds[2].kind = hal::CommandKind::kDumpLog;
    std::vector<hal::CanFrame> cf(hal_can::kMaxParts + 1);
    std::size_t cn = 0;
    for (const hal::Command& c : cmds) {
      const fw::Status st = hal_can::encode_command(c, fd, cf.data(), hal_can::kMaxParts, &cn);
      if (!st) die(std::string("encode_command: ") + st.message());
      hal::CommandReply rep;
      rep.kind = c.kind;
      hal_can::encode_reply(rep, &cf[cn++]);
      for (std::size_t i = 0; i < cn; ++i) {
        const hal::CanFrame& f = cf[i];
        raw.u8(fuzz::kCanRawFrame);
        raw.u16(static_cast<std::uint16_t>(f.id));
        raw.u8(static_cast<std::uint8_t>((f.fd ? 1 : 0) | (f.brs ? 4 : 0)));
        raw.u8(f.len);
        raw.bytes(f.data, f.len);
        raw.u16(100);
      }
    }
    put("can_decoder", fd ? "raw_fd" : "raw_classic", raw.data());
    put("can_decoder", fd ? "ops_fd" : "ops_classic", ops.data());
  }
}

void sick_seeds(const Source& src) {
  fuzz::ByteWriter w;
  const std::uint8_t ack[] = {hal_serial::kRespModeChange, 0x00, 0x10};
  std::uint8_t buf[hal_serial::kMaxTelegramBytes];
  const std::size_t na = hal_serial::encode_sick_telegram(hal_serial::kDeviceAddressBit, ack, sizeof ack, buf, sizeof buf);
  w.u8(fuzz::kSickRaw);
  w.blob(std::vector<std::uint8_t>(buf, buf + na));
  for (std::size_t k = 0; k < src.scans.size() && k < 2; ++k) {
    hal_serial::MeasuredValues v;
    v.count = static_cast<std::uint16_t>(std::min<std::size_t>(src.scans[k].ranges.size(), hal_serial::kMaxMeasuredValues));
    for (std::uint16_t i = 0; i < v.count; ++i) {
      v.values[i] = static_cast<std::uint16_t>(std::min(8191.0f, std::round(src.scans[k].ranges[i] * 100.0f)));
    }
    const std::size_t n = hal_serial::encode_measured_values(v, buf, sizeof buf);
    if (n == 0) die("encode_measured_values refused a real scan");
    w.u8(fuzz::kSickRaw);
    w.blob(std::vector<std::uint8_t>(buf, buf + n));
    w.u8(fuzz::kSickPoll);
    w.u8(63);
  }
  put("sick_telegram", "telegrams", w.data());
  fuzz::ByteWriter m;
  m.u8(fuzz::kSickMeasured);
  m.u8(hal_serial::kDeviceAddressBit);
  m.u16(181 | 0x4000);
  for (int i = 0; i < 181; ++i) m.u16(static_cast<std::uint16_t>(1000 + 10 * i));
  m.u8(0x10);
  m.u8(fuzz::kSickPoll);
  m.u8(255);
  m.u8(fuzz::kSickReconnect);
  put("sick_telegram", "measured_mm", m.data());
}

// Hokuyo (issue 59): a whole UTM-30LX handshake, then two scans made from the real ones (nearest
// beam per 0.25° step), a silence long enough for the driver to ask again.
void scip_seeds(const Source& src) {
  fuzz::ByteWriter w;
  w.u8(0);  // MD, no intensity
  auto status = [&w](const char* echo, const char* st) {
    w.u8(fuzz::kScipStatus);
    w.blob(to_bytes(echo));
    w.u8(static_cast<std::uint8_t>(st[0]));
    w.u8(static_cast<std::uint8_t>(st[1]));
  };
  auto info = [&w](const char* echo, const char* lines) {
    w.u8(fuzz::kScipInfo);
    w.blob(to_bytes(echo));
    w.blob(to_bytes(lines));
  };
  status("SCIP2.0", "0E");
  status("QT", "00");
  info("VV", "VEND:Hokuyo Automatic Co.,Ltd.\nPROD:SOKUIKI Sensor TOP-URG UTM-30LX\nFIRM:1.1\nPROT:SCIP 2.0");
  info("PP", "MODL:UTM-30LX\nDMIN:23\nDMAX:60000\nARES:1440\nAMIN:0\nAMAX:1080\nAFRT:540\nSCAN:2400");
  info("II", "MODL:UTM-30LX\nLASR:OFF\nSTAT:Stable 000 no error.");
  status("BM", "00");
  status("MD0000108001000", "00");
  w.u8(fuzz::kScipPoll);
  w.u8(255);
  for (std::size_t k = 0; k < src.scans.size() && k < 2; ++k) {
    const sim::CarmenScan& sc = src.scans[k];
    w.u8(fuzz::kScipScan);
    w.u8(0);
    w.u16(0);
    w.u16(1080);
    w.u8(1);
    w.u32(static_cast<std::uint32_t>(0xFFFFF0 + 25 * k));  // the 24-bit clock wraps between the two
    w.u16(1081);
    for (int i = 0; i < 1081; ++i) {
      const double a = (i - 540) * 2 * M_PI / 1440;
      const long b = std::lround((a - sc.angle_min) / sc.angle_increment);
      const double r = (b >= 0 && b < static_cast<long>(sc.ranges.size())) ? sc.ranges[b] : 0.0;
      w.u32(static_cast<std::uint32_t>(std::lround(r * 1000.0)));
    }
    w.u8(fuzz::kScipPoll);
    w.u8(255);
  }
  w.u8(fuzz::kScipAdvance);
  w.u16(1100);
  w.u8(fuzz::kScipPoll);
  w.u8(3);
  put("scip", "utm30lx_handshake_scans", w.data());
}

// RPLIDAR (issue 59): health, info, the SCAN descriptor and two turns of samples from a real scan;
// and the same in express mode with capsules.
void rplidar_seeds(const Source& src) {
  const sim::CarmenScan* sc = src.scans.empty() ? nullptr : &src.scans[0];
  auto range_q2 = [sc](double cw_deg) -> std::uint16_t {
    if (!sc) return 4000;
    const double a = -cw_deg * M_PI / 180.0;
    const long b = std::lround((a - sc->angle_min) / sc->angle_increment);
    if (b < 0 || b >= static_cast<long>(sc->ranges.size())) return 0;
    return static_cast<std::uint16_t>(std::min(65535.0, std::round(sc->ranges[b] * 4000.0)));
  };
  for (const int express : {0, 1}) {
    fuzz::ByteWriter w;
    w.u8(express ? 2 : 0);
    w.u16(360);
    w.u8(49);  // min samples 50
    w.u8(fuzz::kRpHealth);
    w.u8(0);
    w.u16(0);
    w.u8(fuzz::kRpInfo);
    const std::uint8_t info[20] = {0x18, 29, 1, 7};
    w.bytes(info, 20);
    w.u8(fuzz::kRpDescriptor);
    w.u32(express ? (84u | (1u << 30)) : (5u | (1u << 30)));
    w.u8(express ? hal_serial::kRplidarAnsCapsule : hal_serial::kRplidarAnsSample);
    w.u8(fuzz::kRpPoll);
    w.u8(255);
    if (!express) {
      for (int turn = 0; turn < 3; ++turn) {
        w.u8(fuzz::kRpSamples);
        w.u8(120);
        for (int k = 0; k < 120; ++k) {
          const double deg = 0.4 + k * 3.0;
          w.u8(static_cast<std::uint8_t>((k == 0 ? 1 : 0) | (40 << 1)));
          w.u16(static_cast<std::uint16_t>(deg * 64));
          w.u16(range_q2(deg));
        }
        w.u8(fuzz::kRpPoll);
        w.u8(255);
      }
    } else {
      for (int c = 0; c < 12; ++c) {
        const double start = std::fmod(c * 45.0 + 0.3, 360.0);
        w.u8(fuzz::kRpCapsule);
        w.u8(c == 0 ? 1 : 0);
        w.u16(static_cast<std::uint16_t>(start * 64));
        for (int k = 0; k < 32; ++k) w.u16(static_cast<std::uint16_t>(range_q2(start + k * 45.0 / 32) / 4));
        for (int k = 0; k < 32; ++k) w.u8(0);
        w.u8(fuzz::kRpPoll);
        w.u8(255);
      }
    }
    w.u8(fuzz::kRpAdvance);
    w.u16(2100);
    w.u8(fuzz::kRpPoll);
    w.u8(1);
    put("rplidar", express ? "a1_express_capsules" : "a1_scan_turns", w.data());
  }
}

// A small occupancy map from the first scans (their odometry poses), 0.2 m cells.
sim::OccupancyGrid seed_grid(const Source& src) {
  std::vector<sim::PosedScan> posed;
  for (const sim::CarmenScan& s : src.scans) {
    sim::PosedScan p;
    p.pose = s.pose;
    p.angle_min = s.angle_min;
    p.angle_increment = s.angle_increment;
    p.max_range = s.max_range;
    p.ranges = s.ranges.data();
    p.count = s.ranges.size();
    posed.push_back(p);
  }
  sim::OccupancyBuildOptions o;
  o.resolution = 0.2;
  o.max_usable_range = 6.0;
  o.margin = 0.4;
  sim::OccupancyGrid grid;
  std::string err;
  if (!sim::build_occupancy_grid(posed, o, &grid, nullptr, &err)) die("occupancy: " + err);
  return grid;
}

void map_seeds(const Source& src) {
  const sim::OccupancyGrid grid = seed_grid(src);
  std::string err;
  sim::MapImageWriter w;
  if (!w.set_grid(grid, &err)) die("map image: " + err);
  put("map_image", "plain", with_flag(0, w.bytes()));
  sim::RelationTableBuildReport rep;
  if (!sim::add_relation_table(&w, sim::RelationTableBuild{}, "seed map", &rep, &err)) die("relation table: " + err);
  put("map_image", "with_table", with_flag(0, w.bytes()));
  put("map_image", "with_table_fixcrc", with_flag(1, w.bytes()));

  // The same map as ROS map_server files (P5 as written by the tools, and a P2 variant).
  const fs::path tmp = fs::path(g_out) / "tmp-ros";
  fs::create_directories(tmp);
  for (int ascii = 0; ascii < 2; ++ascii) {
    sim::RosMap m = sim::grid_to_ros_map(grid, "m.pgm");
    m.pgm_ascii = ascii;
    if (!sim::write_ros_map((tmp / "map.yaml").string(), m, &err)) die("ros map: " + err);
    const std::string yaml = slurp((tmp / "map.yaml").string());
    const std::string pgm = slurp((tmp / "m.pgm").string());
    fuzz::ByteWriter r;
    r.blob(to_bytes(yaml));
    r.bytes(pgm.data(), pgm.size());
    put("ros_map", ascii ? "map_p2" : "map_p5", r.data());
    put("pgm", ascii ? "p2" : "p5", to_bytes(pgm));
  }
  fs::remove_all(tmp);
}

void text_seeds(const Source& src) {
  put("app_config", "socketcan", to_bytes("# robot\nlaser = socketcan:can0\nmap = /opt/robot/map.mmap\n"
                                          "localizer = mml-track\nworkers = 2\ncores = 0,1\nlaser_timeout_ms = 500\n"));
  put("app_config", "serial", to_bytes("laser = serial:/dev/ttyUSB0@500000\nodometry = none\noutput = log\n"
                                       "localizer = mml\nmml_preset = 4\nmap = m.mmap\nrealtime = false\n"
                                       "arena_mib = 64\nstep_deadline_ms = 13.333\nhealth_period_ms = 200\n"
                                       "seed = 7\nlog_level = debug\ncan_fd = auto\n"));
  put("carmen_log", "intel_head", with_flag(0, to_bytes(src.intel_text)));
  if (!src.aces_text.empty()) put("carmen_log", "aces_head", with_flag(1, to_bytes(src.aces_text)));
  if (!src.clinic_text.empty()) put("carmen_log", "clinic_robotlaser", with_flag(0, to_bytes(src.clinic_text)));
  // A gzip log as the tools write it, read through a file (flag 2).
  sim::CarmenLog log;
  log.scans.assign(src.scans.begin(), src.scans.begin() + std::min<std::size_t>(3, src.scans.size()));
  std::string err;
  const std::string gz = (fs::path(g_out) / "seed.clf.gz").string();
  sim::CarmenWriteOptions wo;
  wo.gzip = true;
  if (!sim::write_carmen_log(gz, log, wo, &err)) die(err);
  put("carmen_log", "gzip", with_flag(2, to_bytes(slurp(gz))));
  fs::remove(gz);

  sim::Trajectory traj;
  for (const sim::CarmenScan& s : src.scans) traj.push_back({s.ipc_timestamp, s.pose});
  const std::string tp = (fs::path(g_out) / "traj.txt").string();
  if (!sim::write_trajectory(tp, traj, &err)) die(err);
  fuzz::ByteWriter r;
  r.blob(to_bytes(src.relations_text));
  const std::string t = slurp(tp);
  r.bytes(t.data(), t.size());
  fs::remove(tp);
  put("relations", "intel_head", r.data());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) die("usage: fuzz_seeds OUT_DIR");
  g_out = argv[1];
  fs::create_directories(g_out);
  const Source src = load_source();
  can_seeds(src);
  sick_seeds(src);
  scip_seeds(src);
  rplidar_seeds(src);
  map_seeds(src);
  text_seeds(src);
  std::printf("fuzz_seeds: %d seed files in %s (%s)\n", g_written, g_out.c_str(),
              src.real ? "from the real logs" : "synthetic");
  return 0;
}
