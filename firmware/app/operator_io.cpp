#include "firmware/app/operator_io.h"

#include "firmware/base/memory_report.h"
#include "hal_linux/black_box_file.h"

namespace fw {

Status OperatorIo::init_black_box(const AppConfig& c, StartupArena& arena, hal_linux::Board& board) {
  if (!c.blackbox[0]) return Status::ok();
  if (board.can_node() != nullptr && c.blackbox_frames > 0) {
    Result<hal_can::BlackBoxEntry*> r = arena.allocate_array<hal_can::BlackBoxEntry>(c.blackbox_frames, "black box");
    if (!r) return Status::error(r.status().code(), "blackbox_frames = %u: %s", c.blackbox_frames, r.status().message());
    FW_RETURN_IF_ERROR(MemoryReport::instance().add(
        {"hal", "black box (CAN frames in and out)", sizeof(hal_can::BlackBoxEntry) * c.blackbox_frames,
         c.blackbox_frames, nullptr}));
    box_.init(*r, c.blackbox_frames);
    board.attach_black_box(&box_);
  }
  if (board.serial_laser() != nullptr && c.blackbox_serial_chunks > 0) {
    const std::uint32_t n = c.blackbox_serial_chunks;
    Result<hal_serial::SerialBlackBoxEntry*> r =
        arena.allocate_array<hal_serial::SerialBlackBoxEntry>(n, "black box (serial)");
    if (!r) return Status::error(r.status().code(), "blackbox_serial_chunks = %u: %s", n, r.status().message());
    FW_RETURN_IF_ERROR(MemoryReport::instance().add(
        {"hal", "black box (serial laser bytes in and out)", sizeof(hal_serial::SerialBlackBoxEntry) * n, n, nullptr}));
    serial_box_.init(*r, n);
    board.attach_serial_black_box(&serial_box_);
  }
  if (!recording()) {
    hal_->log->log(hal::LogLevel::kWarning, "mmlfw: blackbox '%s': nothing to record (no CAN node, no serial laser, "
                   "or blackbox_frames / blackbox_serial_chunks 0)", c.blackbox);
  }
  return Status::ok();
}

Status OperatorIo::init(const AppConfig& c, StartupArena& arena, hal_linux::Board& board, LocalizationLoop& loop,
                        Localizer& localizer, const OperatorMaps& maps) {
  config_ = &c;
  hal_ = &board.hal();
  FW_RETURN_IF_ERROR(init_black_box(c, arena, board));
  CommandHandlerOptions o;
  o.active_map_id = 0;  // map 0 is active after start-up
  o.maps = maps.selector;
  o.on_switch = maps.on_switch;
  o.switch_ctx = maps.ctx;
  if (recording()) {
    o.dump = &OperatorIo::dump_command;
    o.dump_ctx = this;
  }
  handler_.init(hal_, &localizer, o);
  loop.set_command_handler(&handler_);
  return Status::ok();
}

Status OperatorIo::dump_command(void* self) { return static_cast<OperatorIo*>(self)->dump("DUMP_LOG"); }

Status OperatorIo::dump(const char* why) {
  if (!recording()) return Status::ok();
  std::size_t bytes = 0;
  const Status s = hal_linux::write_black_box_file(&box_, &serial_box_, config_->blackbox, &bytes);
  if (!s) {
    hal_->log->log(hal::LogLevel::kError, "mmlfw: %s: %s", why, s.message());
  } else {
    hal_->log->log(hal::LogLevel::kInfo,
                   "mmlfw: %s: black box '%s' written (%zu frames, %zu serial chunks, %zu bytes, %llu overwritten)", why,
                   config_->blackbox, box_.size(), serial_box_.size(), bytes,
                   static_cast<unsigned long long>(box_.overwritten() + serial_box_.overwritten()));
  }
  return s;
}

void OperatorIo::watch_faults(std::uint32_t fault_bits) {
  const std::uint32_t risen = fault_bits & ~faults_seen_;
  faults_seen_ = fault_bits;
  if (risen != 0) dump("fault");
}

}  // namespace fw
