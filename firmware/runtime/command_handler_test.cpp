// Issue 60: operator commands checked and answered by the runtime; bad input is a reply code.
#include "firmware/runtime/command_handler.h"

#include <gtest/gtest.h>

#include <cmath>

namespace fw {
namespace {

class HintedLocalizer final : public Localizer {
 public:
  const char* name() const override { return "hinted"; }
  void reset() override { ++resets; }
  Status step(const hal::LaserScan&, const hal::Odometry&, hal::PoseEstimate*) override { return Status::ok(); }
  Status set_pose_hint(const hal::PoseHint& h) override {
    last = h;
    ++hints;
    return Status::ok();
  }
  hal::PoseHint last;
  int hints = 0, resets = 0;
};

class PlainLocalizer final : public Localizer {
 public:
  const char* name() const override { return "plain"; }
  void reset() override {}
  Status step(const hal::LaserScan&, const hal::Odometry&, hal::PoseEstimate*) override { return Status::ok(); }
};

hal::Command hint(float x, float sxy) {
  hal::Command c;
  c.kind = hal::CommandKind::kSetPoseHint;
  c.seq = 7;
  c.has_hint = true;
  c.hint.x = x;
  c.hint.y = 2.0f;
  c.hint.sigma_xy_m = sxy;
  c.hint.sigma_theta_rad = 0.1f;
  return c;
}

TEST(CommandHandlerTest, HintsAreCheckedBeforeTheLocalizerSeesThem) {
  HintedLocalizer loc;
  CommandHandler h;
  h.init(nullptr, &loc, CommandHandlerOptions());
  hal::CommandReply r = h.handle(hint(1.0f, 0.2f));
  EXPECT_EQ(r.result, hal::CommandResult::kAccepted);
  EXPECT_EQ(r.seq, 7);
  EXPECT_EQ(loc.hints, 1);
  EXPECT_EQ(h.handle(hint(NAN, 0.2f)).result, hal::CommandResult::kInvalidArgument);
  EXPECT_EQ(h.handle(hint(INFINITY, 0.2f)).result, hal::CommandResult::kInvalidArgument);
  EXPECT_EQ(h.handle(hint(1.0f, 0.0f)).result, hal::CommandResult::kInvalidArgument);
  EXPECT_EQ(h.handle(hint(1.0f, NAN)).result, hal::CommandResult::kInvalidArgument);
  hal::Command other_map = hint(1.0f, 0.2f);
  other_map.hint.map_id = 3;
  EXPECT_EQ(h.handle(other_map).result, hal::CommandResult::kUnknownMap);
  EXPECT_EQ(loc.hints, 1);
  EXPECT_EQ(h.counters().refused, 5u);
}

TEST(CommandHandlerTest, SelectMapAndDumpLog) {
  HintedLocalizer loc;
  CommandHandlerOptions o;
  o.active_map_id = 1;
  static int dumps = 0;
  static bool dump_ok = true;
  o.dump = [](void*) { ++dumps; return dump_ok ? Status::ok() : Status::error(Errc::kIoError, "disk full"); };
  CommandHandler h;
  h.init(nullptr, &loc, o);
  hal::Command c;
  c.kind = hal::CommandKind::kSelectMap;
  c.map_id = 0;
  EXPECT_EQ(h.handle(c).result, hal::CommandResult::kUnknownMap);
  EXPECT_EQ(loc.resets, 0);
  c.map_id = 1;
  const hal::CommandReply r = h.handle(c);
  EXPECT_EQ(r.result, hal::CommandResult::kDone);
  EXPECT_EQ(r.detail, 1);
  EXPECT_EQ(loc.resets, 1);
  c = hint(3.0f, 0.5f);
  c.kind = hal::CommandKind::kSelectMap;
  c.map_id = c.hint.map_id = 1;
  EXPECT_EQ(h.handle(c).result, hal::CommandResult::kAccepted);
  EXPECT_EQ(loc.hints, 1);
  c = hal::Command();
  c.kind = hal::CommandKind::kDumpLog;
  EXPECT_EQ(h.handle(c).result, hal::CommandResult::kDone);
  dump_ok = false;
  EXPECT_EQ(h.handle(c).result, hal::CommandResult::kFailed);
  EXPECT_EQ(dumps, 2);
  c.kind = static_cast<hal::CommandKind>(42);
  EXPECT_EQ(h.handle(c).result, hal::CommandResult::kMalformed);
}

// Several maps: a fake MapSelector with two localizers (the MapSet itself: sim/cli/map_switch_test).
class TwoMaps final : public MapSelector {
 public:
  Result<Localizer*> select(std::uint8_t id, bool reload) override {
    if (id > 1) return Status::error(Errc::kNotFound, "map %u: no such map", id);
    if (reload && broken) return Status::error(Errc::kCorruptData, "b.mmap: occupancy section CRC mismatch");
    active = id;
    loc[id].reset();
    return &loc[id];
  }
  std::uint8_t active_id() const override { return active; }
  HintedLocalizer loc[2];
  std::uint8_t active = 0;
  bool broken = false;
};

TEST(CommandHandlerTest, SelectMapSwitchesThroughTheSelector) {
  TwoMaps maps;
  Localizer* stepped = &maps.loc[0];
  CommandHandlerOptions o;
  o.maps = &maps;
  o.on_switch = [](void* ctx, Localizer& l) { *static_cast<Localizer**>(ctx) = &l; };
  o.switch_ctx = &stepped;
  CommandHandler h;
  h.init(nullptr, &maps.loc[0], o);
  hal::Command c;
  c.kind = hal::CommandKind::kSelectMap;
  c.map_id = 1;
  hal::CommandReply r = h.handle(c);
  EXPECT_EQ(r.result, hal::CommandResult::kDone);
  EXPECT_EQ(r.detail, 1);
  EXPECT_EQ(stepped, &maps.loc[1]);
  EXPECT_EQ(maps.loc[1].resets, 1);
  // A hint now refers to map 1; one for map 0 is unknown-map.
  hal::Command hc = hint(1.0f, 0.2f);
  hc.hint.map_id = 0;
  EXPECT_EQ(h.handle(hc).result, hal::CommandResult::kUnknownMap);
  hc.hint.map_id = 1;
  EXPECT_EQ(h.handle(hc).result, hal::CommandResult::kAccepted);
  EXPECT_EQ(maps.loc[1].hints, 1);
  EXPECT_EQ(maps.loc[0].hints, 0);
  // Unknown id, broken reload: refused, map 1 stays and is not reset.
  c.map_id = 5;
  r = h.handle(c);
  EXPECT_EQ(r.result, hal::CommandResult::kUnknownMap);
  EXPECT_EQ(r.detail, 1);
  maps.broken = true;
  c.map_id = 0;
  c.reload = true;
  r = h.handle(c);
  EXPECT_EQ(r.result, hal::CommandResult::kMapInvalid);
  EXPECT_EQ(r.detail, 1);
  EXPECT_EQ(stepped, &maps.loc[1]);
  EXPECT_EQ(maps.loc[1].resets, 1);
  // Without a selector a reload cannot be done.
  CommandHandler one;
  one.init(nullptr, &maps.loc[0], CommandHandlerOptions());
  c.map_id = 0;
  EXPECT_EQ(one.handle(c).result, hal::CommandResult::kUnsupported);
}

TEST(CommandHandlerTest, LocalizersWithoutHintsAndNoBlackBoxSaySo) {
  PlainLocalizer loc;
  CommandHandler h;
  h.init(nullptr, &loc, CommandHandlerOptions());
  EXPECT_EQ(h.handle(hint(1.0f, 0.2f)).result, hal::CommandResult::kUnsupported);
  hal::Command c;
  c.kind = hal::CommandKind::kDumpLog;
  EXPECT_EQ(h.handle(c).result, hal::CommandResult::kUnsupported);
}

}  // namespace
}  // namespace fw
