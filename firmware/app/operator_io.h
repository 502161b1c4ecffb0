// mmlfw's operator side (issue 60): the commands of the bus (SET_POSE_HINT, SELECT_MAP, DUMP_LOG;
// firmware/runtime/command_handler.h) and the black box (hal_can/black_box.h, and with a serial
// laser hal_serial/serial_black_box.h) — its rings carved from the start-up arena, attached to the
// board's CAN node and serial laser port, written into one file (hal_linux/black_box_file.h) on
// DUMP_LOG, when a fault bit rises and at exit.
#pragma once

#include <cstdint>

#include "firmware/app/app_config.h"
#include "firmware/base/arena.h"
#include "firmware/runtime/command_handler.h"
#include "firmware/runtime/localization_loop.h"
#include "hal_can/black_box.h"
#include "hal_linux/board.h"
#include "hal_serial/serial_black_box.h"

namespace fw {

// Several maps (map_set.h): SELECT_MAP switches through `selector`; `on_switch(ctx, localizer)` hands
// the new map's localizer to the loop. Empty = one map (SELECT_MAP of map 0 only).
struct OperatorMaps {
  MapSelector* selector = nullptr;
  void (*on_switch)(void* ctx, Localizer& localizer) = nullptr;
  void* ctx = nullptr;
};

class OperatorIo {
 public:
  // Start-up: the black box (config blackbox, blackbox_frames for a CAN node, blackbox_serial_chunks
  // for a serial laser; a board with neither: a warning) and the command handler on the loop.
  // Errors name the part.
  Status init(const AppConfig& config, StartupArena& arena, hal_linux::Board& board, LocalizationLoop& loop,
              Localizer& localizer, const OperatorMaps& maps = {});
  // Writes the black box now (DUMP_LOG, exit); logs the bytes or the error.
  Status dump(const char* why);
  // Every loop cycle: a fault bit that was clear is set → one dump.
  void watch_faults(std::uint32_t fault_bits);
  const hal_can::BlackBox& black_box() const { return box_; }
  // The global search's records (issue 60) go into the CAN ring; null without one.
  hal::GlobalRecordSink* global_record_sink() { return box_.enabled() ? &box_ : nullptr; }
  const hal_serial::SerialBlackBox& serial_black_box() const { return serial_box_; }
  const CommandHandler& commands() const { return handler_; }

 private:
  static Status dump_command(void* self);
  Status init_black_box(const AppConfig& config, StartupArena& arena, hal_linux::Board& board);
  bool recording() const { return box_.enabled() || serial_box_.enabled(); }
  const AppConfig* config_ = nullptr;
  hal::Hal* hal_ = nullptr;
  hal_can::BlackBox box_;
  hal_serial::SerialBlackBox serial_box_;
  CommandHandler handler_;
  std::uint32_t faults_seen_ = 0;
};

}  // namespace fw
