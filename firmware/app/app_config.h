// mmlfw configuration: a "key = value" text file ('#' comments), validated once at start-up.
// Every error names the file, the line and the key; a key set twice, a NUL byte and an overlong
// value are errors too (nothing is silently dropped or overridden). Keys (defaults in brackets):
//   laser            (required) can:IFACE (= socketcan:IFACE) | sick:DEVICE[@BAUD] (= serial:) |
//                    hokuyo:DEVICE[@BAUD][,intensity] |
//                    rplidar:DEVICE[@BAUD][,express|,force][,pwm=1..1023][,beams=1..1081]
//                    BAUD: 9600 19200 38400 57600 115200 230400 256000 460800 500000 921600 1000000
//                    [sick 38400, hokuyo and rplidar 115200]; IFACE ≤ 15 characters. Hokuyo and
//                    RPLIDAR must answer their start-up handshake (hal/linux/board.h)
//   laser_mount      YAW_DEG[, upside-down]: the laser's zero direction turned YAW degrees (CCW,
//                    -180..180) from the robot's front, and mounted upside down (mirrored); every
//                    scan is turned into the robot's orientation. The laser is taken to sit on the
//                    robot's centre: a lever arm is not modelled (the pose is the laser's) [0]
//   odometry         socketcan:IFACE | none              [laser's interface when socketcan, else none]
//   output           socketcan:IFACE | log               [laser's interface when socketcan, else log]
//   can_fd           auto | true | false                 [auto: FD when the interface MTU is 72]
//   localizer        mml-track | mml | handoff | mcl | odom   [mml-track] (firmware/app/system.h)
//   mml_preset       1..4 MML configuration C1..C4 (firmware/mml/mml_presets.h)  [3]
//   map              path of the compiled map image (mml-mapc / mml-mapbuild)   (required for mml);
//                    map id 0 (SELECT_MAP, SET_POSE_HINT's map id)
//   map.1 .. map.3   more map images, ids 1..3 (one per floor or site; consecutive ids, `map` first):
//                    all are loaded at start-up into the arena, SELECT_MAP switches (firmware/app/map_set.h)
//   map_reload       true | false  keep one spare map slot (as large as the largest map, +25 %) so
//                    that SELECT_MAP with the reload flag can read a map's image from disk again,
//                    check it and build it beside the one in use [false]
//   workers          1..16 worker threads, created once  [2]
//   cores            comma list of CPU ids for worker i  [0,1,...]; pinned to (core mod online CPUs)
//   realtime         true | false  SCHED_FIFO + mlockall for every thread of the execution-context
//                    table (firmware/runtime/execution_contexts.h); refused → start-up fails [false]
//   global_context   thread | inline  mml-track: MML on its own pinned thread at lower priority,
//                    fed every scan it is idle for, result taken 1 scan later (thread), or inside the sensor
//                    step on every scan (inline: the deterministic reference schedule)  [thread]
//   global_period_scans 1..8 thread: MML gets every n-th scan, its result is taken n scans later
//                    (deadline n scan periods) [the table's, firmware/runtime/execution_contexts.h]
//   arena_mib        1..4096 start-up arena (map + localizer storage) [256]
//   step_deadline_ms 0.1..1000 Localizer::step longer than this is a deadline miss [13.333 = 75 Hz]
//   health_period_ms 10..10000 heartbeat period when no scans arrive [200]
//   laser_timeout_ms 10..60000 no scan for this long: fault `laser-timeout` in HEALTH and a pose
//                    with status `fault`, cleared by the next scan [500 = a few scan periods]
//   seed             random seed of the localizer    [1]
//   log_level        debug | info | warning | error  [info]
//   blackbox         PATH | off: the black box (hal/can/include/hal_can/black_box.h) is written to
//                    PATH (a candump log, replaced atomically) on DUMP_LOG, on a fault and at exit;
//                    a serial laser's bytes go into the same file as "(T) rx laser HEX" lines
//                    (hal/serial/README.md "Black box") [off]
//   blackbox_frames  0..4194304 frames the black box keeps (80 bytes each, in the start-up arena when
//                    blackbox is set; ~1000 frames/s on a classic bus, 180 beams at 10 Hz) [65536: 5 MiB]
//   blackbox_serial_chunks 0..4194304 serial chunks of up to 64 bytes it keeps with a serial laser
//                    (80 bytes each; a SICK LMS at 500 kBd, 361 values at 75 Hz, makes ~860/s) [65536: 5 MiB]
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"

namespace fw {

// Longest SocketCAN interface name (IFNAMSIZ - 1).
constexpr std::size_t kMaxCanInterfaceName = 15;

struct AppConfig {
  static constexpr int kMaxCores = 16;
  static constexpr int kMaxMaps = 4;  // map + map.1 .. map.3
  static constexpr long kMaxBlackBoxFrames = 4194304;
  char laser[128] = {0};
  float laser_mount_yaw_deg = 0.0f;  // laser_mount: yaw of the laser on the robot (degrees, CCW)
  bool laser_upside_down = false;
  char odometry[128] = {0};  // empty = default
  char output[128] = {0};
  int can_fd = -1;           // -1 auto, 0 classic, 1 FD required
  char localizer[16] = "mml-track";
  int mml_preset = 3;
  char map[256] = {0};
  char more_maps[kMaxMaps - 1][256] = {};  // map.1 .. map.3; empty = not set
  bool map_reload = false;
  int workers = 2;
  int cores[kMaxCores] = {0};
  int num_cores = 0;         // 0 = default (worker i → core i)
  bool realtime = false;
  bool global_threaded = true;
  std::uint32_t global_period_scans = 0;  // 0 = the execution-context table's
  std::uint32_t arena_mib = 256;
  double step_deadline_ms = 1000.0 / 75.0;
  std::uint32_t health_period_ms = 200;
  std::uint32_t laser_timeout_ms = 500;
  std::uint64_t seed = 1;
  int log_level = 1;         // hal::LogLevel
  // The tracker's odometry noise model (TrackOptions::odom_trans_per_m, _trans_per_rad, _rot_per_rad,
  // _rot_per_m; AMCL's α, same defaults): σ_trans = TT·|Δs| + TR·|Δθ|, σ_rot = RR·|Δθ| + RT·|Δs|
  // per scan interval. Set it from your robot: a model tighter than the wheels makes right tracks
  // fail the innovation and odometry-consistency tests (availability).
  float odom_noise[4] = {0.2f, 0.2f, 0.2f, 0.2f};
  // Per-step odometry noise (TrackOptions::odom_trans_per_step_m / _rot_per_step_rad): σ in metres
  // (on x and y) and degrees per scan interval that does not follow the motion, added in quadrature
  // to the model above. 0, 0 (default) for wheels whose error follows the motion.
  float odom_noise_per_step[2] = {0.0f, 0.0f};
  // Declared wheel slips: per 100 m driven, and the largest in metres (TrackOptions::odom_slip_per_100m).
  float odom_slip[2] = {0.0f, 1.0f};
  char blackbox[256] = {0};             // empty = no black box file
  std::uint32_t blackbox_frames = 65536;
  std::uint32_t blackbox_serial_chunks = 65536;
};

// Map ids: 0 is `map`, i ≥ 1 is `map.i`. map_count: how many are set (ids are consecutive).
int map_count(const AppConfig& c);
const char* map_path(const AppConfig& c, int id);  // "" when not set

// Parses `text` (len bytes); `path` is used in messages (abbreviated to its last 96 characters).
Status parse_app_config(const char* path, const char* text, std::size_t len, AppConfig* out);
// Reads the file (at most 16 KiB) with read(2) into a static buffer and parses it.
Status load_app_config(const char* path, AppConfig* out);

}  // namespace fw
