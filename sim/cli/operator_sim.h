// The operator side of mml-sim (issue 60): a pose hint sent at a scan (SET_POSE_HINT through the
// firmware's command handler; on the CAN wire with --transport can), the black box recorded on the
// firmware's CanNode and written as a candump log (--blackbox FILE), and its replay
// (--replay-blackbox FILE): the rx frames fed back through the same CanNode in lockstep, the POSE
// frames the replay publishes compared byte for byte with the tx frames of the file.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "firmware/base/se2.h"
#include "hal/msg/command.h"
#include "hal/msg/global_record.h"
#include "hal/sensor_io.h"
#include "hal_can/black_box.h"
#include "hal_serial/serial_black_box.h"

namespace sim {

struct HintOptions {
  std::size_t at_scan = 0;   // 1-based scan of the run at which the hint is sent; 0 = none
  bool absolute = false;     // pose = the hinted pose; else the truth moved by `pose` (map frame)
  fw::Se2d pose;             // x, y in m, theta in rad
  double sigma_m = 0.1, sigma_rad = 0.05;
};

struct BlackBoxOptions {
  std::string record_path;   // --blackbox FILE: written after the run (needs --transport can or sick)
  std::string replay_path;   // --replay-blackbox FILE
  std::size_t frames = std::size_t{1} << 21;  // the ring (host: the whole run of a bench world)
  std::size_t serial_chunks = std::size_t{1} << 21;  // a serial laser (--transport sick|hokuyo|rplidar): the serial ring's entries
};

// The hint a run sends at its scan: `truth` moved by the options' offset, or their absolute pose.
hal::Command hint_command(const HintOptions& o, const fw::Se2d& truth, std::uint8_t seq);

// Commands given straight to the loop (--transport none / sick): a host queue.
class DirectCommands final : public hal::CommandSource {
 public:
  void push(const hal::Command& c) { queue_.push_back(c); }
  bool poll(hal::Command* out) override;
 private:
  std::deque<hal::Command> queue_;
};

// The outputs as the product sends them: every estimate encoded as its POSE frames (classic CAN,
// hal/can codec) and recorded in the black box as tx, then handed on.
class BlackBoxTee final : public hal::PoseSink {
 public:
  BlackBoxTee(hal::PoseSink* inner, hal_can::BlackBox* box) : inner_(inner), box_(box) {}
  void publish(const hal::PoseEstimate& e) override;
  void publish_health(const hal::Health& h) override { inner_->publish_health(h); }
  void publish_reply(const hal::CommandReply& r) override;
 private:
  hal::PoseSink* inner_;
  hal_can::BlackBox* box_;
  std::uint8_t tag_ = 0;
};

// Host storage for the rings (the serial one with --transport sick).
struct BlackBoxRecorder {
  std::vector<hal_can::BlackBoxEntry> storage;
  hal_can::BlackBox box;
  std::vector<hal_serial::SerialBlackBoxEntry> serial_storage;
  hal_serial::SerialBlackBox serial;
  std::unique_ptr<BlackBoxTee> tee;
};

// One line of a black box file: the frame (timestamp_ns exact to the µs) and its direction, or
// (serial) the bytes read from / written to the laser port at frame.timestamp_ns.
struct BlackBoxLine {
  hal::CanFrame frame;
  bool tx = false;
  bool serial = false;
  std::vector<std::uint8_t> bytes;
  // A global search's record (sim/devices/global_log_line.h), not a frame: not fed, not compared.
  bool global = false;
  hal::GlobalRecord record;
  std::size_t line_no = 0;  // 1-based line of the file
};
// Reads a black box (candump -L lines with interface rx / tx, the serial lines "(T) rx laser HEX" of
// sim/devices/serial_log_line.h, the global records "(T) global take|drop T R" of
// sim/devices/global_log_line.h); errors name the file and line.
bool read_black_box(const std::string& path, std::vector<BlackBoxLine>* out, std::string* err);
// POSE frames (0x120..0x125, 0x520) in order: of the file's tx lines / of a ring's tx entries.
std::vector<hal::CanFrame> pose_frames(const std::vector<BlackBoxLine>& lines);
std::vector<hal::CanFrame> pose_frames(const hal_can::BlackBox& box);
// Same ids, lengths and bytes, frame by frame; *first_difference = index of the first that differs
// (or the shorter length).
bool same_frames(const std::vector<hal::CanFrame>& a, const std::vector<hal::CanFrame>& b,
                 std::size_t* first_difference);

struct BlackBoxReplay {
  std::size_t rx_frames = 0, recorded_pose_frames = 0, replayed_pose_frames = 0;
  std::size_t global_records = 0;  // global results forced to their recorded scans (issue 60)
  std::string global_mismatch;     // "FILE:LINE: ..." of the first record the replay did not meet
  std::size_t rx_serial_lines = 0;  // serial chunks fed to the laser driver
  std::size_t first_difference = 0;
  bool identical = false;
};

}  // namespace sim
