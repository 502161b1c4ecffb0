// Operator commands (issue 60): what the robot or a fleet manager asks of the firmware on the bus
// (hal/can/README.md "Commands"), and the firmware's reply. A command is validated by the runtime
// (firmware/runtime/command_handler.h); a bad one is refused with a reply code, never a crash.
#pragma once

#include <cstdint>

namespace hal {

enum class CommandKind : std::uint8_t {
  kNone = 0,
  kSetPoseHint = 1,  // "the robot is here": x, y, θ, its uncertainty, the map it refers to
  kSelectMap = 2,    // make map `map_id` the active one (the tracker drops `localized`)
  kDumpLog = 3,      // write the black box (the last minutes of inputs and outputs) now
};
constexpr std::uint8_t kCommandKindCount = 4;
inline const char* command_name(CommandKind k) {
  switch (k) {
    case CommandKind::kNone: return "none";
    case CommandKind::kSetPoseHint: return "SET_POSE_HINT";
    case CommandKind::kSelectMap: return "SELECT_MAP";
    case CommandKind::kDumpLog: return "DUMP_LOG";
  }
  return "unknown";
}

// Reply codes (COMMAND_REPLY.Result).
enum class CommandResult : std::uint8_t {
  kAccepted = 0,         // taken; its outcome follows (a hint: HEALTH.HintStatus and POSE.Reason)
  kDone = 1,             // carried out (DUMP_LOG: the file is written; SELECT_MAP: switched)
  kInvalidArgument = 2,  // a field is out of range (σ ≤ 0 or unknown, a position beyond ±2000 km)
  kUnknownMap = 3,       // the map id names no loaded map
  kUnsupported = 4,      // this localizer or configuration cannot do it (e.g. a hint to `mcl`)
  kFailed = 5,           // tried and failed (DUMP_LOG: the file could not be written)
  kMalformed = 6,        // the command's frames did not make a valid command
  kMapInvalid = 7,       // SELECT_MAP reload: the image on disk is missing or broken; the map in use stays
};
constexpr std::uint8_t kCommandResultCount = 8;
inline const char* command_result_name(CommandResult r) {
  switch (r) {
    case CommandResult::kAccepted: return "accepted";
    case CommandResult::kDone: return "done";
    case CommandResult::kInvalidArgument: return "invalid-argument";
    case CommandResult::kUnknownMap: return "unknown-map";
    case CommandResult::kUnsupported: return "unsupported";
    case CommandResult::kFailed: return "failed";
    case CommandResult::kMalformed: return "malformed";
    case CommandResult::kMapInvalid: return "map-invalid";
  }
  return "unknown";
}

// Where a pose hint stands (HEALTH.HintStatus): the last hint's verification, until the next one.
enum class HintStatus : std::uint8_t {
  kNone = 0,          // no hint since start-up (or since the map was switched)
  kPending = 1,       // received; checked on the next scan
  kTracking = 2,      // the scans fit the hint: tracked, awaiting the tracker's recovery scans
  kAwaitingMml = 3,   // the scans fit the hint; `localized` once MML isolates the same pose
  kConfirmed = 4,     // the hinted track became `localized`
  kRefused = 5,       // the scans contradict the hint (no consistent pose within its uncertainty)
  kLost = 6,          // the hinted track was confirmed by the scan, then given up before `localized`
};
constexpr std::uint8_t kHintStatusCount = 7;
inline const char* hint_status_name(HintStatus s) {
  switch (s) {
    case HintStatus::kNone: return "none";
    case HintStatus::kPending: return "pending";
    case HintStatus::kTracking: return "tracking";
    case HintStatus::kAwaitingMml: return "awaiting-mml";
    case HintStatus::kConfirmed: return "confirmed";
    case HintStatus::kRefused: return "refused";
    case HintStatus::kLost: return "lost";
  }
  return "unknown";
}

struct PoseHint {
  float x = 0.0f, y = 0.0f, theta = 0.0f;  // map frame
  float sigma_xy_m = 0.0f;       // 1-σ uncertainty of x and y
  float sigma_theta_rad = 0.0f;  // 1-σ uncertainty of θ
  std::uint8_t map_id = 0;
};

struct Command {
  std::uint64_t timestamp_ns = 0;  // receive time
  CommandKind kind = CommandKind::kNone;
  std::uint8_t seq = 0;            // echoed in the reply
  std::uint8_t map_id = 0;         // kSelectMap
  bool reload = false;             // kSelectMap: read the map's image from disk again first (checked)
  bool has_hint = false;           // kSetPoseHint (always), kSelectMap (optional)
  PoseHint hint;
};

struct CommandReply {
  std::uint8_t seq = 0;
  CommandKind kind = CommandKind::kNone;
  CommandResult result = CommandResult::kAccepted;
  std::uint8_t detail = 0;  // the active map id after the command
};

}  // namespace hal
