// The DBC file documents the wire format: decode encoder output with the DBC's signal
// definitions and compare with the values that were encoded.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "hal_can/codec.h"

#ifndef MMLFW_DBC_FILE
#error MMLFW_DBC_FILE must point to hal/can/mmlfw.dbc
#endif

namespace hal_can {
namespace {

struct Signal {
  int start = 0, bits = 0;
  bool is_signed = false;
  double factor = 1;
};
struct Message {
  std::string name;
  int dlc = 0;
  std::map<std::string, Signal> signals;
};

std::map<std::uint32_t, Message> load_dbc() {
  std::map<std::uint32_t, Message> out;
  std::ifstream in(MMLFW_DBC_FILE);
  EXPECT_TRUE(in.good()) << MMLFW_DBC_FILE;
  std::string line;
  Message* cur = nullptr;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "BO_") {
      std::uint32_t id;
      std::string name;
      int dlc;
      ls >> id >> name >> dlc;
      name.pop_back();  // ':'
      cur = &out[id];
      cur->name = name;
      cur->dlc = dlc;
    } else if (tag == "SG_" && cur) {
      std::string name, colon, layout, scale;
      ls >> name >> colon >> layout >> scale;
      Signal s;
      std::sscanf(layout.c_str(), "%d|%d@1", &s.start, &s.bits);
      s.is_signed = layout.back() == '-';
      std::sscanf(scale.c_str(), "(%lf", &s.factor);
      cur->signals[name] = s;
    }
  }
  return out;
}

double extract(const hal::CanFrame& f, const Signal& s) {
  // A DBC signal is at most 64 bits; std::uint64_t, not __int128, which 32-bit ARM (armhf) lacks.
  std::uint64_t raw = 0;
  for (int b = 0; b < s.bits && b < 64; ++b) {
    const int bit = s.start + b;
    if (f.data[bit / 8] & (1u << (bit % 8))) raw |= std::uint64_t{1} << b;
  }
  long double v = static_cast<long double>(raw);
  if (s.is_signed && (raw >> (s.bits - 1)) & 1) v -= std::ldexp(1.0L, s.bits);
  return static_cast<double>(v) * s.factor;
}

double sig(const std::map<std::uint32_t, Message>& dbc, const hal::CanFrame* frames, std::size_t n, const char* name) {
  for (std::size_t i = 0; i < n; ++i) {
    auto it = dbc.find(frames[i].id);
    if (it == dbc.end()) continue;
    auto s = it->second.signals.find(name);
    if (s != it->second.signals.end()) return extract(frames[i], s->second);
  }
  ADD_FAILURE() << "signal " << name << " not found";
  return NAN;
}

TEST(Dbc, DescribesEveryFrameTheEncoderProduces) {
  const auto dbc = load_dbc();
  ASSERT_GE(dbc.size(), 26u);
  for (bool fd : {false, true}) {
    hal::CanFrame f[kMaxParts];
    std::size_t n = 0;
    hal::PoseEstimate p;
    p.scan_id = 4242;
    p.x = -12.5f;
    p.y = 33.25f;
    p.theta = -2.5f;
    p.status = hal::LocalizationStatus::kOutsideMap;
    p.mode = hal::LocalizationMode::kTracking;
    p.cov[0] = 0.04f;
    p.hypothesis_count = 17;
    p.timestamp_ns = 123456789000ull;
    p.protection_xy_m = 0.75f;
    p.protection_theta_rad = 0.0523f;
    p.unsupported_steps = 1234;
    p.reason = hal::StatusReason::kTrackAwaitingMml;
    ASSERT_TRUE(encode_pose(p, 5, fd, f, kMaxParts, &n).is_ok());
    EXPECT_EQ(n, fd ? 1u : kPoseParts);
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_TRUE(dbc.count(f[i].id)) << std::hex << f[i].id;
      EXPECT_LE(f[i].len, dbc.at(f[i].id).dlc);
      // Every signal the DBC puts in this frame lies inside the bytes the encoder sends.
      for (const auto& [name, s] : dbc.at(f[i].id).signals) {
        EXPECT_LE(s.bits, 64) << dbc.at(f[i].id).name << "." << name;
        EXPECT_LE(s.start + s.bits, 8 * f[i].len) << dbc.at(f[i].id).name << "." << name;
      }
    }
    EXPECT_EQ(sig(dbc, f, n, "ScanId"), 4242);
    EXPECT_NEAR(sig(dbc, f, n, "X"), -12.5, 1e-9);
    EXPECT_NEAR(sig(dbc, f, n, "Y"), 33.25, 1e-9);
    EXPECT_NEAR(sig(dbc, f, n, "Theta"), -2.5, 1e-6);
    EXPECT_EQ(sig(dbc, f, n, "Status"), 3);
    EXPECT_EQ(sig(dbc, f, n, "Mode"), 1);
    EXPECT_NEAR(sig(dbc, f, n, "SigmaX"), 0.2, 1e-3);
    EXPECT_EQ(sig(dbc, f, n, "HypothesisCount"), 17);
    EXPECT_EQ(sig(dbc, f, n, "TimeUs"), 123456789);
    EXPECT_EQ(sig(dbc, f, n, "PoseLayout"), kPoseLayout);
    EXPECT_NEAR(sig(dbc, f, n, "ProtectionXY"), 0.75, 1e-9);
    EXPECT_NEAR(sig(dbc, f, n, "ProtectionTheta"), 0.0523, 1e-9);
    EXPECT_EQ(sig(dbc, f, n, "UnsupportedSteps"), 1234);
    EXPECT_EQ(sig(dbc, f, n, "Reason"), 9);
    // The DBC factors are the codec's: a saturated bound reads as the DBC's maximum.
    p.protection_xy_m = 1e6f;
    p.protection_theta_rad = 100.0f;
    ASSERT_TRUE(encode_pose(p, 6, fd, f, kMaxParts, &n).is_ok());
    EXPECT_NEAR(sig(dbc, f, n, "ProtectionXY"), 65535 / kProtectionXyPerMetre, 1e-9);
    EXPECT_NEAR(sig(dbc, f, n, "ProtectionTheta"), 65535 / kProtectionThetaPerRad, 1e-9);

    hal::Odometry o;
    o.x = 1.5f;
    o.y = -2.25f;
    o.theta = 0.5f;
    o.v = -0.3f;
    o.timestamp_ns = 5'000'000'000ull;
    ASSERT_TRUE(encode_odometry(o, 1, fd, f, kMaxParts, &n).is_ok());
    EXPECT_NEAR(sig(dbc, f, n, "X"), 1.5, 1e-9);
    EXPECT_NEAR(sig(dbc, f, n, "Y"), -2.25, 1e-9);
    EXPECT_NEAR(sig(dbc, f, n, "Theta"), 0.5, 1e-6);
    EXPECT_NEAR(sig(dbc, f, n, "V"), -0.3, 1e-9);
    EXPECT_EQ(sig(dbc, f, n, "TimeUs"), 5'000'000);

    HealthRecord h;
    h.bus_off = 3;
    h.crc_errors = 9;
    h.scans_processed = 100000;
    h.fault_bits = 0x40;
    h.hint_status = static_cast<std::uint8_t>(hal::HintStatus::kRefused);
    ASSERT_TRUE(encode_health(h, 1, fd, f, kMaxParts, &n).is_ok());
    EXPECT_EQ(sig(dbc, f, n, "HintStatus"), 5);
    EXPECT_EQ(sig(dbc, f, n, "BusOff"), 3);
    EXPECT_EQ(sig(dbc, f, n, "CrcErrors"), 9);
    EXPECT_EQ(sig(dbc, f, n, "ScansProcessed"), 100000);
    EXPECT_EQ(sig(dbc, f, n, "FaultBits"), 0x40);

    // Operator commands (issue 60) and the reply.
    hal::Command c;
    c.kind = hal::CommandKind::kSetPoseHint;
    c.seq = 9;
    c.hint.x = -3.25f;
    c.hint.y = 12.5f;
    c.hint.theta = 1.25f;
    c.hint.sigma_xy_m = 0.3f;
    c.hint.sigma_theta_rad = 0.1f;
    c.hint.map_id = 2;
    ASSERT_TRUE(encode_command(c, fd, f, kMaxParts, &n).is_ok());
    EXPECT_EQ(n, fd ? 1u : kPoseHintParts);
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_TRUE(dbc.count(f[i].id)) << std::hex << f[i].id;
      EXPECT_EQ(f[i].len, dbc.at(f[i].id).dlc);
    }
    EXPECT_EQ(sig(dbc, f, n, "Tag"), 9);
    EXPECT_EQ(sig(dbc, f, n, "MapId"), 2);
    EXPECT_EQ(sig(dbc, f, n, "Flags"), 0);
    EXPECT_NEAR(sig(dbc, f, n, "X"), -3.25, 1e-9);
    EXPECT_NEAR(sig(dbc, f, n, "Y"), 12.5, 1e-9);
    EXPECT_NEAR(sig(dbc, f, n, "Theta"), 1.25, 1e-6);
    EXPECT_NEAR(sig(dbc, f, n, "SigmaXY"), 0.3, 1e-9);
    EXPECT_NEAR(sig(dbc, f, n, "SigmaTheta"), 0.1, 1e-9);
    c = hal::Command{};
    c.kind = hal::CommandKind::kSelectMap;
    c.seq = 4;
    c.map_id = 7;
    ASSERT_TRUE(encode_command(c, fd, f, kMaxParts, &n).is_ok());
    ASSERT_EQ(n, 1u);
    EXPECT_EQ(dbc.at(f[0].id).name, "SELECT_MAP");
    EXPECT_EQ(f[0].len, dbc.at(f[0].id).dlc);
    EXPECT_EQ(sig(dbc, f, n, "Seq"), 4);
    EXPECT_EQ(sig(dbc, f, n, "MapId"), 7);
    EXPECT_EQ(sig(dbc, f, n, "Reload"), 0);
    c.reload = true;
    ASSERT_TRUE(encode_command(c, fd, f, kMaxParts, &n).is_ok());
    EXPECT_EQ(sig(dbc, f, n, "Reload"), 1);
    EXPECT_EQ(sig(dbc, f, n, "MapId"), 7);
    c.has_hint = true;  // a hint with select and reload: Flags 3
    c.hint.sigma_xy_m = 0.3f;
    c.hint.sigma_theta_rad = 0.1f;
    ASSERT_TRUE(encode_command(c, fd, f, kMaxParts, &n).is_ok());
    EXPECT_EQ(sig(dbc, f, n, "Flags"), 3);
    c.has_hint = false;
    c.reload = false;
    c.kind = hal::CommandKind::kDumpLog;
    ASSERT_TRUE(encode_command(c, fd, f, kMaxParts, &n).is_ok());
    EXPECT_EQ(dbc.at(f[0].id).name, "DUMP_LOG");
    EXPECT_EQ(f[0].len, dbc.at(f[0].id).dlc);
    hal::CommandReply rep;
    rep.seq = 4;
    rep.kind = hal::CommandKind::kSelectMap;
    rep.result = hal::CommandResult::kUnknownMap;
    rep.detail = 1;
    encode_reply(rep, &f[0]);
    EXPECT_EQ(dbc.at(f[0].id).name, "COMMAND_REPLY");
    EXPECT_EQ(f[0].len, dbc.at(f[0].id).dlc);
    EXPECT_EQ(sig(dbc, f, 1, "Command"), 2);
    EXPECT_EQ(sig(dbc, f, 1, "Result"), 3);
    EXPECT_EQ(sig(dbc, f, 1, "Detail"), 1);
    rep.result = hal::CommandResult::kMapInvalid;
    encode_reply(rep, &f[0]);
    EXPECT_EQ(sig(dbc, f, 1, "Result"), 7);

    hal::LaserScan s;
    s.scan_id = 77;
    s.beam_count = 40;
    s.angle_min = -1.5f;
    s.angle_increment = 0.0075f;
    s.range_max = 30.0f;
    s.timestamp_ns = 2'000'000'000ull;
    for (int i = 0; i < 40; ++i) s.ranges[i] = 1.0f + 0.5f * static_cast<float>(i);
    hal::CanFrame sf[kMaxScanFrames];
    EncodeOptions eo;
    eo.fd = fd;
    ASSERT_TRUE(encode_scan(s, eo, sf, kMaxScanFrames, &n).is_ok());
    for (std::size_t i = 0; i < n; ++i) ASSERT_TRUE(dbc.count(sf[i].id)) << std::hex << sf[i].id;
    EXPECT_EQ(sig(dbc, sf, n, "BeamCount"), 40);
    EXPECT_NEAR(sig(dbc, sf, n, "AngleMin"), -1.5, 1e-6);
    EXPECT_NEAR(sig(dbc, sf, n, "AngleIncrement"), 0.0075, 1e-7);
    const double unit = sig(dbc, sf, n, "RangeUnit");
    // First data segment: Range0 = beam 0, Range2 = beam 2.
    EXPECT_NEAR(sig(dbc, sf, n, "Range2") * unit, 2.0, 1e-6);
    EXPECT_EQ(sig(dbc, sf, n, "SegmentIndex"), 0);
    EXPECT_EQ(sig(dbc, sf, n, "ScanTag"), 77 & 0xF);
    EXPECT_EQ(sig(dbc, sf, n, "SegmentCount"), fd ? 2 : 14);
  }
}

}  // namespace
}  // namespace hal_can
