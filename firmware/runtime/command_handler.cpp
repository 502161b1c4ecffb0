#include "firmware/runtime/command_handler.h"

#include <cmath>

namespace fw {

Status check_pose_hint(const hal::PoseHint& h) {
  if (!std::isfinite(h.x) || !std::isfinite(h.y) || !std::isfinite(h.theta)) {
    return Status::error(Errc::kInvalidArgument, "pose hint: x, y or theta not finite (%g, %g, %g)",
                         static_cast<double>(h.x), static_cast<double>(h.y), static_cast<double>(h.theta));
  }
  if (std::fabs(h.x) > 2e6f || std::fabs(h.y) > 2e6f || std::fabs(h.theta) > 2147.0f) {
    return Status::error(Errc::kInvalidArgument, "pose hint: (%g, %g, %g) beyond +-2000 km / +-2147 rad",
                         static_cast<double>(h.x), static_cast<double>(h.y), static_cast<double>(h.theta));
  }
  if (!(h.sigma_xy_m > 0.0f && h.sigma_xy_m <= 100.0f)) {
    return Status::error(Errc::kInvalidArgument, "pose hint: sigma_xy = %g m is not in (0, 100]",
                         static_cast<double>(h.sigma_xy_m));
  }
  if (!(h.sigma_theta_rad > 0.0f && h.sigma_theta_rad <= 6.2832f)) {
    return Status::error(Errc::kInvalidArgument, "pose hint: sigma_theta = %g rad is not in (0, 2 pi]",
                         static_cast<double>(h.sigma_theta_rad));
  }
  return Status::ok();
}

void CommandHandler::init(hal::Hal* hal, Localizer* localizer, const CommandHandlerOptions& options) {
  hal_ = hal;
  localizer_ = localizer;
  options_ = options;
  counters_ = CommandCounters();
}

void CommandHandler::poll() {
  if (hal_ == nullptr || hal_->commands == nullptr) return;
  hal::Command c;
  for (int k = 0; k < kMaxPerPoll && hal_->commands->poll(&c); ++k) {
    const hal::CommandReply r = handle(c);
    if (hal_->pose_sink != nullptr) hal_->pose_sink->publish_reply(r);
  }
}

hal::CommandResult CommandHandler::hint(const hal::PoseHint& h) {
  const Status s = check_pose_hint(h);
  if (!s) {
    if (hal_ != nullptr && hal_->log != nullptr) hal_->log->log(hal::LogLevel::kWarning, "command: %s", s.message());
    return hal::CommandResult::kInvalidArgument;
  }
  if (h.map_id != active_map()) return hal::CommandResult::kUnknownMap;
  const Status t = localizer_->set_pose_hint(h);
  if (!t) {
    if (hal_ != nullptr && hal_->log != nullptr) hal_->log->log(hal::LogLevel::kWarning, "command: %s", t.message());
    return t.code() == Errc::kUnsupported ? hal::CommandResult::kUnsupported : hal::CommandResult::kInvalidArgument;
  }
  return hal::CommandResult::kAccepted;
}

// A switch (or a reload) that fails leaves the active map and its localizer as they were.
hal::CommandResult CommandHandler::select_map(const hal::Command& c) {
  if (localizer_ == nullptr) return hal::CommandResult::kUnsupported;
  if (options_.maps == nullptr) {
    if (c.map_id != options_.active_map_id) return hal::CommandResult::kUnknownMap;
    if (c.reload) return hal::CommandResult::kUnsupported;  // nothing to reload into
    // The same map again: a fresh start on it (nothing `localized` survives a map selection).
    localizer_->reset();
    return c.has_hint ? hint(c.hint) : hal::CommandResult::kDone;
  }
  Result<Localizer*> r = options_.maps->select(c.map_id, c.reload);
  if (!r) {
    if (hal_ != nullptr && hal_->log != nullptr) {
      hal_->log->log(hal::LogLevel::kWarning, "command: SELECT_MAP %u%s: %s", c.map_id, c.reload ? " reload" : "",
                     r.status().message());
    }
    switch (r.status().code()) {
      case Errc::kNotFound: return hal::CommandResult::kUnknownMap;
      case Errc::kCorruptData:
      case Errc::kIoError: return hal::CommandResult::kMapInvalid;
      case Errc::kUnsupported: return hal::CommandResult::kUnsupported;
      default: return hal::CommandResult::kFailed;
    }
  }
  localizer_ = *r;
  if (options_.on_switch != nullptr) options_.on_switch(options_.switch_ctx, *localizer_);
  if (hal_ != nullptr && hal_->log != nullptr) {
    hal_->log->log(hal::LogLevel::kInfo, "command: SELECT_MAP: map %u active%s", c.map_id, c.reload ? " (reloaded)" : "");
  }
  return c.has_hint ? hint(c.hint) : hal::CommandResult::kDone;
}

hal::CommandReply CommandHandler::handle(const hal::Command& c) {
  hal::CommandReply r;
  r.seq = c.seq;
  r.kind = c.kind;
  r.detail = options_.active_map_id;
  ++counters_.received;
  if (static_cast<std::uint8_t>(c.kind) < hal::kCommandKindCount) ++counters_.by_kind[static_cast<int>(c.kind)];
  switch (c.kind) {
    case hal::CommandKind::kSetPoseHint:
      r.result = localizer_ != nullptr ? hint(c.hint) : hal::CommandResult::kUnsupported;
      break;
    case hal::CommandKind::kSelectMap:
      r.result = select_map(c);
      break;
    case hal::CommandKind::kDumpLog:
      r.result = options_.dump == nullptr            ? hal::CommandResult::kUnsupported
                 : options_.dump(options_.dump_ctx).is_ok() ? hal::CommandResult::kDone
                                                            : hal::CommandResult::kFailed;
      break;
    default:
      r.result = hal::CommandResult::kMalformed;
      break;
  }
  r.detail = active_map();  // after the command: the map now in use
  if (r.result == hal::CommandResult::kAccepted || r.result == hal::CommandResult::kDone) {
    ++counters_.accepted;
  } else {
    ++counters_.refused;
  }
  return r;
}

}  // namespace fw
