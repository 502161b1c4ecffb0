// Operator commands on the bus (protocol.h, README "Commands"): SET_POSE_HINT as a 3-part record,
// SELECT_MAP and DUMP_LOG as single frames, COMMAND_REPLY from the firmware.
#include <cmath>
#include <cstring>

#include "hal_can/codec.h"
#include "record_frames.h"

namespace hal_can {
namespace {

constexpr std::size_t kHintPayload = kPoseHintParts * kPartBytes;  // 21
constexpr double kHintMaxAbsM = 2147483.0;                          // i32 mm

// Field → wire code, or an error naming the field: a hint is never clamped into another one.
fw::Status hint_i32(float v, double per_unit, double max_abs, const char* field, std::int32_t* out) {
  if (!std::isfinite(v) || std::fabs(static_cast<double>(v)) > max_abs) {
    return fw::Status::error(fw::Errc::kInvalidArgument, "encode SET_POSE_HINT: %s = %g is not finite or beyond +-%g",
                             field, static_cast<double>(v), max_abs);
  }
  *out = static_cast<std::int32_t>(std::lround(static_cast<double>(v) * per_unit));
  return fw::Status::ok();
}
fw::Status hint_sigma(float v, double per_unit, const char* field, std::uint16_t* out) {
  // Rounded up (an uncertainty never shrinks), but not past a float's own error (0.3f = 0.30000001).
  const double code = std::ceil(static_cast<double>(v) * per_unit - 1e-4);
  if (!(v > 0.0f) || !(code < 65535.0)) {
    return fw::Status::error(fw::Errc::kInvalidArgument, "encode SET_POSE_HINT: %s = %g is not in (0, %g]", field,
                             static_cast<double>(v), 65534.0 / per_unit);
  }
  *out = static_cast<std::uint16_t>(code);
  return fw::Status::ok();
}

void single_frame(std::uint32_t id, std::uint8_t len, hal::CanFrame* f) {
  *f = hal::CanFrame{};
  f->id = id;
  f->len = len;
}

}  // namespace

fw::Status encode_command(const hal::Command& c, bool fd, hal::CanFrame* out, std::size_t capacity,
                          std::size_t* count) {
  *count = 0;
  if (capacity < 1) return fw::Status::error(fw::Errc::kCapacityExceeded, "encode command: no room for a frame");
  if (c.kind == hal::CommandKind::kDumpLog || (c.kind == hal::CommandKind::kSelectMap && !c.has_hint)) {
    const bool dump = c.kind == hal::CommandKind::kDumpLog;
    // SELECT_MAP is 3 bytes since the reload flag (older firmware reads the first 2 of it).
    single_frame(dump ? kDumpLogId : kSelectMapId, dump ? 1 : 3, &out[0]);
    out[0].data[0] = c.seq;
    out[0].data[1] = dump ? 0 : c.map_id;
    if (!dump && c.reload) out[0].data[2] = kSelectMapFlagReload;
    *count = 1;
    return fw::Status::ok();
  }
  if (c.kind != hal::CommandKind::kSetPoseHint && c.kind != hal::CommandKind::kSelectMap) {
    return fw::Status::error(fw::Errc::kInvalidArgument, "encode command: unknown command kind %u",
                             static_cast<unsigned>(c.kind));
  }
  const hal::PoseHint& h = c.hint;
  std::int32_t x = 0, y = 0, th = 0;
  std::uint16_t sxy = 0, sth = 0;
  FW_RETURN_IF_ERROR(hint_i32(h.x, 1e3, kHintMaxAbsM, "x", &x));
  FW_RETURN_IF_ERROR(hint_i32(h.y, 1e3, kHintMaxAbsM, "y", &y));
  FW_RETURN_IF_ERROR(hint_i32(h.theta, 1e6, 2147.0, "theta", &th));
  FW_RETURN_IF_ERROR(hint_sigma(h.sigma_xy_m, 1e3, "sigma_xy", &sxy));
  FW_RETURN_IF_ERROR(hint_sigma(h.sigma_theta_rad, 1e4, "sigma_theta", &sth));
  std::uint8_t p[kHintPayload] = {};
  p[0] = c.kind == hal::CommandKind::kSelectMap ? c.map_id : h.map_id;
  p[1] = c.kind == hal::CommandKind::kSelectMap ? kHintFlagSelectMap : 0;
  if (c.kind == hal::CommandKind::kSelectMap && c.reload) p[1] |= kHintFlagReload;
  put_u32(p + 2, static_cast<std::uint32_t>(x));
  put_u32(p + 7, static_cast<std::uint32_t>(y));
  put_u16(p + 11, sxy);
  put_u32(p + 14, static_cast<std::uint32_t>(th));
  put_u16(p + 18, sth);
  return emit_record(kPoseHintId, kPoseHintParts, c.seq, p, fd, out, capacity, count, "SET_POSE_HINT");
}

void encode_reply(const hal::CommandReply& r, hal::CanFrame* out) {
  single_frame(kCommandReplyId, 4, out);
  out->data[0] = r.seq;
  out->data[1] = static_cast<std::uint8_t>(r.kind);
  out->data[2] = static_cast<std::uint8_t>(r.result);
  out->data[3] = r.detail;
}

Decoded Decoder::command_malformed() {
  ++stats_.malformed;
  ++stats_.malformed_commands;
  return Decoded::kNothing;
}

Decoded Decoder::feed_command(std::uint32_t id, bool fd_id, const hal::CanFrame& f) {
  if (id >= kPoseHintId && id < kPoseHintId + kPoseHintParts) {
    const bool done = fd_id ? (id == kPoseHintId && feed_fd_record(&hint_rec_, kPoseHintParts, f))
                            : feed_part(&hint_rec_, kPoseHintParts, id - kPoseHintId, f);
    if (!done) return Decoded::kNothing;
    const std::uint8_t* p = hint_rec_.bytes;
    // Reserved flags, or reload without select (a hint alone never reloads a map).
    if ((p[1] & ~(kHintFlagSelectMap | kHintFlagReload)) != 0 || p[1] == kHintFlagReload) return command_malformed();
    command_ = hal::Command{};
    command_.timestamp_ns = f.timestamp_ns;
    command_.seq = hint_rec_.tag;
    command_.kind = (p[1] & kHintFlagSelectMap) ? hal::CommandKind::kSelectMap : hal::CommandKind::kSetPoseHint;
    command_.map_id = p[0];
    command_.reload = (p[1] & kHintFlagReload) != 0;
    command_.has_hint = true;
    hal::PoseHint& h = command_.hint;
    h.map_id = p[0];
    h.x = static_cast<float>(static_cast<std::int32_t>(get_u32(p + 2)) * 1e-3);
    h.y = static_cast<float>(static_cast<std::int32_t>(get_u32(p + 7)) * 1e-3);
    h.sigma_xy_m = static_cast<float>(get_u16(p + 11) * 1e-3);
    h.theta = static_cast<float>(static_cast<std::int32_t>(get_u32(p + 14)) * 1e-6);
    h.sigma_theta_rad = static_cast<float>(get_u16(p + 18) * 1e-4);
    ++stats_.commands_ok;
    return Decoded::kCommand;
  }
  if (fd_id) {  // the single-frame commands and the reply have no FD variant
    ++stats_.unknown_ids;
    return Decoded::kNothing;
  }
  if (id == kSelectMapId || id == kDumpLogId) {
    const bool dump = id == kDumpLogId;
    if (f.len < (dump ? 1 : 2)) return command_malformed();
    command_ = hal::Command{};
    command_.timestamp_ns = f.timestamp_ns;
    command_.kind = dump ? hal::CommandKind::kDumpLog : hal::CommandKind::kSelectMap;
    command_.seq = f.data[0];
    command_.map_id = dump ? 0 : f.data[1];
    if (!dump && f.len >= 3) {
      if ((f.data[2] & ~kSelectMapFlagReload) != 0) return command_malformed();  // reserved flags
      command_.reload = (f.data[2] & kSelectMapFlagReload) != 0;
    }
    ++stats_.commands_ok;
    return Decoded::kCommand;
  }
  if (id == kCommandReplyId) {
    if (f.len < 4 || f.data[1] == 0 || f.data[1] >= hal::kCommandKindCount || f.data[2] >= hal::kCommandResultCount) {
      return command_malformed();
    }
    reply_ = hal::CommandReply{};
    reply_.seq = f.data[0];
    reply_.kind = static_cast<hal::CommandKind>(f.data[1]);
    reply_.result = static_cast<hal::CommandResult>(f.data[2]);
    reply_.detail = f.data[3];
    ++stats_.replies_ok;
    return Decoded::kReply;
  }
  ++stats_.unknown_ids;
  return Decoded::kNothing;
}

}  // namespace hal_can
