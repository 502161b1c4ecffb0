// CommandHandler (issue 60): the operator commands of hal/msg/command.h as the runtime carries them
// out, between two steps of the localization loop (the sensor context: no lock, no race with the
// localizer). Each command is checked (a NaN, a σ ≤ 0, an unknown map id are refused with a reply
// code, never a crash) and answered through PoseSink::publish_reply:
//   SET_POSE_HINT  → Localizer::set_pose_hint; `accepted` means it will be verified on the next
//                    scan, the verdict follows in HEALTH.HintStatus and POSE.Reason
//   SELECT_MAP     → with options.maps (several maps, firmware/runtime/map_selector.h): the map
//                    set switches to that map's localizer (reset: the tracker drops `localized`,
//                    the global search runs on the new map), reloading its image first when asked
//                    (a missing or broken file: `map-invalid`, the map in use stays); then its hint
//                    if given. Without: only the active map (options.active_map_id) — selecting it
//                    restarts the localizer, another id is `unknown-map`
//   DUMP_LOG       → options.dump (the app writes the black box); `done` or `failed`
#pragma once

#include <cstdint>

#include "firmware/base/status.h"
#include "firmware/runtime/localizer.h"
#include "firmware/runtime/map_selector.h"
#include "hal/hal.h"

namespace fw {

struct CommandHandlerOptions {
  std::uint8_t active_map_id = 0;
  // DUMP_LOG: writes the black box; null = no black box (the reply is `unsupported`).
  Status (*dump)(void* ctx) = nullptr;
  void* dump_ctx = nullptr;
  // Several maps: SELECT_MAP switches through it (and active_map_id follows it); null = one map.
  MapSelector* maps = nullptr;
  // Told the new localizer after a switch (the loop steps it from then on); null = nobody.
  void (*on_switch)(void* ctx, Localizer& localizer) = nullptr;
  void* switch_ctx = nullptr;
};

struct CommandCounters {
  std::uint32_t received = 0, accepted = 0, refused = 0;
  std::uint32_t by_kind[hal::kCommandKindCount] = {};
};

// A pose hint the runtime may pass on: finite, within ±2000 km, σ in (0, 100] m and (0, 2π] rad.
Status check_pose_hint(const hal::PoseHint& hint);

class CommandHandler {
 public:
  void init(hal::Hal* hal, Localizer* localizer, const CommandHandlerOptions& options);
  // Carries out every pending command (at most kMaxPerPoll) and replies to each.
  void poll();
  // One command (also for callers without a CommandSource: tests, the simulator's direct path).
  hal::CommandReply handle(const hal::Command& command);
  const CommandCounters& counters() const { return counters_; }
  static constexpr int kMaxPerPoll = 8;

 private:
  hal::CommandResult hint(const hal::PoseHint& h);
  hal::CommandResult select_map(const hal::Command& c);
  std::uint8_t active_map() const { return options_.maps != nullptr ? options_.maps->active_id() : options_.active_map_id; }
  hal::Hal* hal_ = nullptr;
  Localizer* localizer_ = nullptr;
  CommandHandlerOptions options_;
  CommandCounters counters_;
};

}  // namespace fw
