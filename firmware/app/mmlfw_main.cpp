// mmlfw: the firmware binary. Start-up (everything that may fail happens here, once):
// configuration → HAL board (backends from the config) → start-up arena → map image → worker
// threads (pinned, created once) → localizer → LocalizationLoop; then the arena is sealed and the
// loop runs until SIGINT/SIGTERM (or --max-scans / --duration). Steady state allocates nothing.
//   mmlfw --config FILE [--memory-report] [--timing-report] [--max-scans N] [--duration S]
//   mmlfw --check-config FILE
// Threads (firmware/runtime/execution_contexts.h, created here once and pinned): the main thread is
// the `sensor` context (scan in → tracking → pose out, deadline one scan period); mml-track's MML
// step runs on the `global` context thread (config global_context = thread, the default) and the
// worker pool beside it. realtime = true: SCHED_FIFO at the table's priorities + mlockall; if the
// OS refuses either, start-up fails with the reason (a real-time promise that cannot be kept is
// an error, not a warning).
// --timing-report: on exit, a per-stage timing table (perf counters: count, mean, p50, p99, max).
// --memory-report: performs the full start-up, prints the static memory budget by module and exits;
// the exit status is non-zero (with the reason on stderr) when this machine cannot run the config:
// the board (bus, device) cannot be opened, the footprint exceeds the memory the machine or its
// limits allow, or realtime = true and the memory cannot be locked.
// --check-config FILE: the same start-up without the loop (config, board interface, map image CRC
// and version, arena_mib against what the map and localizer need, the footprint against the
// machine's limits); prints "mmlfw: check-config '<FILE>': ok, static memory ..." and exits 0, or one
// line per problem and exits 1. For the integrator and the package's post-install hint.
// Service manager (systemd Type=notify, hal_linux/sd_notify.h, firmware/app/service_notify.h):
// READY=1 after start-up, WATCHDOG=1 from the sensor loop only while it keeps its deadline,
// STATUS= when the localization status or the faults change, STOPPING=1 on the way out.
// --test-stall-after S (tests only): after S seconds the sensor loop stops cycling (no steps, no
// WATCHDOG=1) until a signal, as a hung loop would; the watchdog tests use it.
// On exit a one-line summary "mmlfw summary: {...}" goes to stderr.
#include <signal.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "firmware/app/app_config.h"
#include "firmware/app/map_set.h"
#include "firmware/app/memory_limits.h"
#include "firmware/app/operator_io.h"
#include "firmware/app/service_notify.h"
#include "firmware/app/system.h"
#include "firmware/base/arena.h"
#include "firmware/base/memory_report.h"
#include "firmware/base/worker_pool.h"
#include "firmware/map/global_map.h"
#include "firmware/map/map_image.h"
#include "firmware/map/map_image_file.h"
#include "firmware/runtime/execution_contexts.h"
#include "firmware/runtime/localization_loop.h"
#include "firmware/runtime/rt_thread.h"
#include "hal_linux/board.h"
#include "hal_linux/sd_notify.h"

namespace {

// All big objects live in static storage (sized at compile time, listed in the memory report).
hal_linux::Board g_board;
fw::StartupArena g_arena;
fw::WorkerPool g_pool;
fw::LocalizationSystem g_system;  // without a map (localizer = odom); its objects live in the arena
fw::MapSet g_maps;  // map, map.1 ..: one slot of the arena each, with its localizer (issue 60)
// The system the loop steps: the active map's (SELECT_MAP switches), or the map-less one.
fw::LocalizationSystem& active_system() { return g_maps.count() > 0 ? g_maps.active() : g_system; }
// Told by the command handler after a switch: the loop steps the new map's localizer.
void on_map_switch(void* loop, fw::Localizer& localizer) { static_cast<fw::LocalizationLoop*>(loop)->set_localizer(localizer); }
fw::LocalizationLoop g_loop;
fw::OperatorIo g_operator;  // commands from the bus, the black box (issue 60)
fw::AppConfig g_config;
hal_linux::SdNotify g_notify;
fw::WatchdogFeed g_watchdog;
volatile sig_atomic_t g_stop = 0;

void on_signal(int) { g_stop = 1; }

int usage(const char* msg) {
  std::fprintf(stderr,
               "mmlfw: %s\nusage: mmlfw --config FILE [--memory-report] [--timing-report] [--max-scans N] [--duration S]\n"
               "       mmlfw --check-config FILE\n       mmlfw --help\n",
               msg);
  return 2;
}

// --help: the text the package ships as the firmware's reference (man page mmlfw(1) says the same).
void print_help() {
  std::printf(
      "mmlfw: onboard global localization (MML, mml-track) for a robot with a 2-D laser and odometry\n"
      "\n"
      "usage: mmlfw --config FILE [--memory-report] [--timing-report] [--max-scans N] [--duration S]\n"
      "       mmlfw --check-config FILE\n"
      "\n"
      "  --config FILE        run: start-up from FILE, then localize until SIGINT/SIGTERM\n"
      "  --check-config FILE  start-up without the loop: the config, the board's bus or device, the map\n"
      "                       image (CRC, version), arena_mib against what the map and localizer need,\n"
      "                       the footprint against the machine's limits; prints 'ok' with the static\n"
      "                       memory, or one line per problem (exit status 1)\n"
      "  --memory-report      start-up, print the static memory budget by module, exit (non-zero when\n"
      "                       this machine cannot run the config)\n"
      "  --timing-report      on exit, per-stage timing of the sensor and global contexts\n"
      "  --max-scans N, --duration S   stop after N scans or S seconds\n"
      "\n"
      "Config (key = value, '#' comments; the packaged example is /etc/mmlfw/mmlfw.conf):\n"
      "  laser = can:IFACE | sick:DEVICE[@BAUD] | hokuyo:DEVICE[@BAUD][,intensity]\n"
      "          | rplidar:DEVICE[@BAUD][,express|,force]   (required; socketcan: and serial: still accepted)\n"
      "  laser_mount = YAW_DEG[, upside-down]   (how the laser sits on the robot; default 0)\n"
      "  odometry = socketcan:IFACE | none    output = socketcan:IFACE | log    can_fd = auto|true|false\n"
      "  localizer = mml-track | mml | handoff | mcl | odom    map = IMAGE.mmap (mml-mapc)\n"
      "  map.1 .. map.3 = IMAGE.mmap (more maps, one per floor: SELECT_MAP switches), map_reload = true|false\n"
      "  workers, cores, realtime, global_context, global_period_scans, arena_mib, step_deadline_ms,\n"
      "  health_period_ms, laser_timeout_ms, seed, mml_preset, log_level, odom_noise, odom_noise_per_step, odom_slip\n"
      "  blackbox = PATH | off, blackbox_frames = N   (the last frames in and out, written on DUMP_LOG, a fault, exit)\n"
      "  blackbox_serial_chunks = N                   (a serial laser's bytes in and out, in the same file)\n"
      "\n"
      "Commands on the bus (DBC: SET_POSE_HINT, SELECT_MAP, DUMP_LOG; answered by COMMAND_REPLY; mml-ctl sends them).\n"
      "\n"
      "Under systemd (mmlfw.service, Type=notify): READY=1 after start-up, WATCHDOG=1 from the sensor\n"
      "loop while it keeps its deadline, STATUS= with the localization status (systemctl status mmlfw).\n"
      "Poses and health go out as CAN frames (DBC: /usr/share/mmlfw/mmlfw.dbc) or to the log.\n"
      "Exit status: 0 ok, 1 bad input or start-up failure (the message names the input), 2 bad arguments.\n");
}

fw::Errc g_fail_code = fw::Errc::kOk;  // of the last start-up stage that failed

int fail(const char* stage, const fw::Status& s) {
  g_fail_code = s.code();
  std::fprintf(stderr, "mmlfw: %s: %s\n", stage, s.message());
  return 1;
}

}  // namespace

namespace {
// log_level = debug: one line per processed scan with the odometry it was paired with and, for MML,
// the interpreter's view (Eq. 5.7, 5.14, 5.16) — what a field engineer needs to replay a bad run.
void trace_step(hal::Hal& hal) {
  const hal::PoseEstimate& e = g_loop.last_estimate();
  const hal::Odometry& od = g_loop.last_odometry();
  fw::LocalizationSystem& sys = active_system();
  const fw::mml::MmlLocalizer* mml = sys.mml();
  if (e.mode == hal::LocalizationMode::kTracking && sys.tracked() != nullptr) {
    const fw::track::TrackStep& t = sys.tracked()->tracker().last();
    hal.log->log(hal::LogLevel::kDebug,
                 "step scan %u t %llu odom %.4f %.4f %.4f status %s pose %.3f %.3f %.3f track %s inliers %u/%u "
                 "unknown %u chi2 %.2f pl %.3f m %.4f rad unsupported %u reason %s",
                 e.scan_id, static_cast<unsigned long long>(e.timestamp_ns), od.x, od.y, od.theta,
                 hal::status_name(e.status), e.x, e.y, e.theta, fw::track::verdict_name(t.verdict), t.alignment.inliers,
                 t.alignment.inliers + t.alignment.contradicting, t.alignment.unknown, t.innovation_chi2,
                 e.protection_xy_m, e.protection_theta_rad, e.unsupported_steps, hal::reason_name(e.reason));
    return;
  }
  // MML's state belongs to the global thread when it runs there: not read from here.
  const bool mml_threaded = sys.tracked() != nullptr && sys.tracked()->global_context().threaded();
  if (mml == nullptr || mml_threaded) {
    hal.log->log(hal::LogLevel::kDebug, "step scan %u t %llu odom %.4f %.4f %.4f status %s pose %.3f %.3f %.3f", e.scan_id,
                 static_cast<unsigned long long>(e.timestamp_ns), od.x, od.y, od.theta, hal::status_name(e.status), e.x, e.y,
                 e.theta);
    return;
  }
  const fw::mml::InterpretResult& r = mml->last();
  hal.log->log(hal::LogLevel::kDebug,
               "step scan %u t %llu odom %.4f %.4f %.4f status %s pose %.3f %.3f %.3f hyps %u/%u clusters %u r %.3f "
               "d2 %.2f smed %.2f c %d%d%d soft %d thres %.3f unique-rejections %u",
               e.scan_id, static_cast<unsigned long long>(e.timestamp_ns), od.x, od.y, od.theta, hal::status_name(e.status),
               e.x, e.y, e.theta, r.hypotheses_valid, r.hypotheses_in, r.cluster_count, r.best_rating, r.d2, r.sigma_med,
               r.c_rating, r.c_mahalanobis, r.c_median, r.soft, r.omega_thres_next, mml->uniqueness_rejections());
}
}  // namespace

namespace {

// Command line.
struct Args {
  const char* config_path = nullptr;
  bool memory_report = false;
  bool timing_report = false;
  long max_scans = 0;
  double duration_s = 0;
  bool check_config = false;
  double test_stall_after_s = 0;  // tests only: the sensor loop stalls after this many seconds
  // Start-up only, nothing runs: the memory report and the config check.
  bool preflight() const { return memory_report || check_config; }
};

// What start-up learned and later steps need.
struct Startup {
  fw::Status board_status;
  bool board_ok = false;
  bool lock_refused = false;
  std::size_t table_copy = 0;  // image pages kept for relation tables read in place (all maps)
  bool global_thread = false;
  fw::track::GlobalScheduleOptions live;
  fw::ExecutionContext global_ctx;
  fw::track::TrackOptions track;  // the shipped options but the config's odometry noise model
};
Startup g_startup;  // static storage, as every big object (the map image handle, the map view)

// 0 = parsed; otherwise the exit status (usage printed).
int parse_args(int argc, char** argv, Args* a) {
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--config") && i + 1 < argc) {
      a->config_path = argv[++i];
    } else if (!std::strcmp(argv[i], "--check-config") && i + 1 < argc) {
      a->config_path = argv[++i];
      a->check_config = true;
    } else if (!std::strcmp(argv[i], "--help")) {
      print_help();
      return -1;
    } else if (!std::strcmp(argv[i], "--test-stall-after") && i + 1 < argc) {
      a->test_stall_after_s = std::strtod(argv[++i], nullptr);
      if (!(a->test_stall_after_s > 0)) return usage("--test-stall-after needs a positive number of seconds");
    } else if (!std::strcmp(argv[i], "--memory-report")) {
      a->memory_report = true;
    } else if (!std::strcmp(argv[i], "--timing-report")) {
      a->timing_report = true;
    } else if (!std::strcmp(argv[i], "--max-scans") && i + 1 < argc) {
      a->max_scans = std::strtol(argv[++i], nullptr, 10);
      if (a->max_scans <= 0) return usage("--max-scans needs a positive integer");
    } else if (!std::strcmp(argv[i], "--duration") && i + 1 < argc) {
      a->duration_s = std::strtod(argv[++i], nullptr);
      if (!(a->duration_s > 0)) return usage("--duration needs a positive number of seconds");
    } else {
      return usage("unknown or incomplete argument");
    }
  }
  if (!a->config_path) return usage("--config FILE or --check-config FILE is required");
  if (a->check_config && a->memory_report) return usage("--check-config and --memory-report are separate checks");
  return 0;
}

// HAL board from the config's backends. The memory report is a pre-flight check: it still prints
// the budget on a machine without the configured bus or device, but then exits non-zero with the
// reason (the hardware cannot run it). 0 = go on.
int open_board(const Args& a, Startup* su) {
  const fw::AppConfig& c = g_config;
  hal_linux::BoardSpec spec;
  spec.laser = c.laser;
  spec.laser_yaw_rad = c.laser_mount_yaw_deg * 0.017453292f;
  spec.laser_upside_down = c.laser_upside_down;
  spec.odometry = c.odometry[0] ? c.odometry : nullptr;
  spec.output = c.output[0] ? c.output : nullptr;
  spec.can_fd = c.can_fd;
  spec.log_level = static_cast<hal::LogLevel>(c.log_level);
  const fw::Status st = g_board.create(spec);
  su->board_status = st;
  su->board_ok = st.is_ok();
  if (!su->board_ok && !a.preflight()) return fail("board", st);
  if (!su->board_ok && a.memory_report) std::fprintf(stderr, "mmlfw: board: %s (memory report only)\n", st.message());
  if (su->board_ok) g_board.hal().log->log(hal::LogLevel::kInfo, "mmlfw: board %s", g_board.describe());
  return 0;
}

// Locked memory (realtime), this thread as the sensor context, the start-up arena. 0 = go on.
int prepare_memory_and_sensor_context(const Args& a, Startup* su) {
  const fw::AppConfig& c = g_config;
  hal::Hal& hal = g_board.hal();
  if (c.realtime && mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    su->lock_refused = true;
    if (!a.preflight()) {
      std::fprintf(stderr, "mmlfw: realtime = true but mlockall was refused (ulimit -l / CAP_IPC_LOCK); set "
                           "realtime = false to run without locked memory\n");
      return 1;
    }
  }
  char warning[160];
  fw::Status st = fw::apply_execution_context_here(fw::kSensorContext, c.realtime && !a.preflight(), warning);
  if (!st) return fail("sensor context", st);
  if (warning[0]) hal.log->log(hal::LogLevel::kWarning, "mmlfw: %s", warning);
  st = g_arena.init_mapped(static_cast<std::size_t>(c.arena_mib) << 20, c.realtime, "arena");
  if (!st) return fail("arena", st);
  return 0;
}

// Worker threads, created once and pinned (the table's worker core first, then round). 0 = go on.
int start_workers(const Args& a) {
  const fw::AppConfig& c = g_config;
  fw::WorkerPoolOptions po;
  po.num_workers = c.workers;
  for (int i = 0; i < c.num_cores && i < fw::WorkerPoolOptions::kMaxWorkers; ++i) po.cores[i] = c.cores[i];
  if (c.num_cores == 0) {
    const long online = sysconf(_SC_NPROCESSORS_ONLN) > 0 ? sysconf(_SC_NPROCESSORS_ONLN) : 1;
    for (int i = 0; i < c.workers && i < fw::WorkerPoolOptions::kMaxWorkers; ++i)
      po.cores[i] = static_cast<int>((fw::kWorkerContext.core + i) % online);
  }
  po.realtime = c.realtime && !a.preflight();
  po.require_realtime = po.realtime;
  po.priority = fw::kWorkerContext.priority;
  const fw::Status st = g_pool.start(po);
  if (!st) return fail("workers", st);
  if (g_pool.warning_count() > 0) {
    g_board.hal().log->log(hal::LogLevel::kWarning, "mmlfw: %d worker warning(s), last: %s", g_pool.warning_count(),
                           g_pool.warning());
  }
  return 0;
}

// Every map of the config with its system (firmware/app/map_set.h), or the map-less system (odom);
// then the global context thread (one, serving the active map) or the inline clock. Prints the
// failure; ok = go on.
fw::Status build_systems(const fw::SystemSpec& sys, Startup* su) {
  const fw::AppConfig& c = g_config;
  hal::Hal& hal = g_board.hal();
  fw::Status st;
  if (fw::map_count(c) == 0) {
    st = g_system.build(sys, fw::GlobalMap{}, nullptr, 0, g_arena, &g_pool);
    if (!st) fail("localizer", st);
  } else {
    fw::MapSetSpec ms;
    ms.count = fw::map_count(c);
    for (int id = 0; id < ms.count; ++id) ms.paths[id] = fw::map_path(c, id);
    ms.reload = c.map_reload;
    ms.system = sys;
    st = g_maps.init(ms, g_arena, &g_pool, hal.log);
    if (!st) fail("map", st);
    for (int id = 0; st && id < g_maps.count(); ++id) {
      if (!g_maps.has_table(id) && std::strcmp(c.localizer, "odom") && std::strcmp(c.localizer, "mcl") && c.mml_preset != 1)
        hal.log->log(hal::LogLevel::kInfo, "mmlfw: map %d image has no relation table; filling it at start-up", id);
    }
  }
  if (!st) return st;
  su->table_copy = g_maps.table_copy_bytes();
  if (g_maps.count() > 0) {
    st = g_maps.start_global_contexts(su->global_thread, c.realtime, hal.clock, su->global_ctx);
  } else if (su->global_thread) {
    st = g_system.start_global_context(c.realtime, hal.clock, su->global_ctx);
  }
  if (!st) fail("global context", st);
  return st;
}

// The one start-up builder (firmware/app/system.h), as mml-sim, mml-eval and the replays use it;
// the global context thread; the image kept only where the relation table is read in place. 0 = go on.
int build_localizer(const Args& a, Startup* su) {
  const fw::AppConfig& c = g_config;
  hal::Hal& hal = g_board.hal();
  fw::SystemSpec sys;
  sys.localizer = c.localizer;
  sys.mml_preset = c.mml_preset;
  sys.seed = c.seed;
  su->track.odom_trans_per_m = c.odom_noise[0];
  su->track.odom_trans_per_rad = c.odom_noise[1];
  su->track.odom_rot_per_rad = c.odom_noise[2];
  su->track.odom_rot_per_m = c.odom_noise[3];
  su->track.odom_trans_per_step_m = c.odom_noise_per_step[0];
  su->track.odom_rot_per_step_rad = c.odom_noise_per_step[1] * 0.017453292f;
  su->track.odom_slip_per_100m = c.odom_slip[0];
  su->track.odom_slip_max_m = c.odom_slip[1];
  sys.track = &su->track;
  su->live = fw::track::live_global_schedule(c.global_period_scans);
  su->global_ctx = fw::track::global_context_for(c.global_period_scans);
  su->global_thread = c.global_threaded && !std::strcmp(c.localizer, "mml-track") && !a.preflight();
  if (su->global_thread) {
    sys.global_schedule = &su->live;
    sys.anytime_global = true;
  }
  fw::Status st = build_systems(sys, su);
  if (!st) return 1;
  fw::LocalizationLoopOptions lo;
  lo.step_deadline_ns = static_cast<std::uint64_t>(c.step_deadline_ms * 1e6);
  lo.laser_timeout_ns = static_cast<std::uint64_t>(c.laser_timeout_ms) * 1000000ull;
  if (su->board_ok) {
    st = g_loop.init(hal, active_system().localizer(), lo);
    if (!st) return fail("loop", st);
    fw::OperatorMaps maps;
    if (g_maps.count() > 0) maps = {&g_maps, &on_map_switch, &g_loop};
    st = g_operator.init(c, g_arena, g_board, g_loop, active_system().localizer(), maps);
    if (!st) return fail("operator commands / black box", st);
    // Issue 60: with global_context = thread the black box records when each global result was taken.
    if (g_maps.count() > 0) {
      g_maps.set_global_record_sink(g_operator.global_record_sink());
    } else {
      g_system.set_global_record_sink(g_operator.global_record_sink());
    }
  }
  return 0;
}

// The pre-flight problems found after a complete start-up (board, memory, locking), one line each
// on stderr; returns how many, plus `already` (problems printed before). `memory` = nullptr when
// start-up stopped before the budget.
int print_check_problems(const Args& a, const Startup& su, const fw::Status* memory, int already) {
  const char* what = a.check_config ? "check-config: problem" : "memory report: cannot run";
  int problems = already;
  if (!su.board_ok) {
    std::fprintf(stderr, "mmlfw: %s: board: %s\n", what, su.board_status.message());
    ++problems;
  }
  if (memory != nullptr && !memory->is_ok()) {
    std::fprintf(stderr, "mmlfw: %s: memory: %s\n", what, memory->message());
    ++problems;
  }
  if (su.lock_refused) {
    std::fprintf(stderr, "mmlfw: %s: realtime = true but mlockall was refused (ulimit -l / CAP_IPC_LOCK; the "
                         "mmlfw.service unit sets LimitMEMLOCK=infinity)\n", what);
    ++problems;
  }
  if (a.check_config && problems > 0) std::fprintf(stderr, "mmlfw: check-config '%s': %d problem(s)\n", a.config_path, problems);
  return problems;
}

// A start-up stage failed (its message already printed): --check-config also names the problems
// found before it (the board), so one run lists everything it could see.
int stage_failed(const Args& a, const Startup& su, int rc) {
  if (!a.check_config) return rc;
  if (g_fail_code == fw::Errc::kCapacityExceeded) {
    std::fprintf(stderr, "mmlfw: check-config: problem: arena_mib = %u is too small for this map and localizer\n",
                 g_config.arena_mib);
  }
  print_check_problems(a, su, nullptr, 1);
  return 1;
}

// The static memory budget; with --memory-report printed with the pre-flight verdict (the exit
// status, ≥ 0), otherwise -1 (go on; a budget beyond the machine's limits is a warning).
int memory_budget(const Args& a, const Startup& su) {
  const fw::AppConfig& c = g_config;
  fw::MemoryReport& mr = fw::MemoryReport::instance();
  mr.add({"hal", "board (sockets, CAN node rings, SICK/Hokuyo/RPLIDAR drivers)", sizeof(g_board), 0, nullptr});
  mr.add({"runtime", "localization loop (odometry ring, pending scan, perf)", sizeof(g_loop), 0, nullptr});
  mr.add({"runtime", "worker pool", sizeof(g_pool), static_cast<std::size_t>(c.workers), nullptr});
  if (su.table_copy > 0) mr.add({"map", "relation tables (image copies, all maps)", su.table_copy, 0, nullptr});
  g_arena.seal();
  // The map/pransam/mml regions are carved from the arena (listed for the breakdown), so the
  // footprint is the arena plus the static objects plus the relation table kept from the image.
  // (The localizer objects are in the arena: system.h.)
  const std::size_t statics = sizeof(g_board) + sizeof(g_loop) + sizeof(g_pool) + sizeof(g_system) + sizeof(g_maps);
  const std::size_t table_copy = su.table_copy;
  const std::uint64_t footprint = static_cast<std::uint64_t>(g_arena.capacity()) + statics + table_copy;
  const fw::Status memory_status =
      fw::check_memory_fits(footprint, fw::read_memory_limits(), "arena_mib + static objects + table");
  // The arena must hold its peak (the map loader's distance check is start-up scratch), not just
  // what stays allocated.
  // With maps, each slot holds its own peak (map_set.h) and the arena's peak is the slots' carving
  // (a slot takes the rest of the arena while it is built): what stays allocated is the need.
  const std::size_t arena_need = g_maps.count() > 0 ? g_arena.used()
                                 : g_arena.peak_used() > g_arena.used() ? g_arena.peak_used() : g_arena.used();
  if (!a.preflight()) {
    if (!memory_status) g_board.hal().log->log(hal::LogLevel::kWarning, "mmlfw: memory: %s", memory_status.message());
    return -1;
  }
  g_system.stop_global_context();
  g_maps.stop_global_contexts();
  g_pool.stop();
  if (a.check_config) {
    const int problems = print_check_problems(a, su, &memory_status, 0);
    if (problems == 0) {
      std::printf("mmlfw: check-config '%s': ok, static memory %.1f MiB (arena_mib %u reserved, %.1f MiB of it used at "
                  "the peak; static objects %.1f MiB; relation table copy %.1f MiB); localizer %s",
                  a.config_path, footprint / 1048576.0, c.arena_mib, arena_need / 1048576.0, statics / 1048576.0,
                  table_copy / 1048576.0, active_system().localizer().name());
      for (int id = 0; id < g_maps.count(); ++id) {
        const fw::GlobalMap& m = g_maps.map(id);
        std::printf(", map%s%.0d '%s' %ux%u cells at %.3f m (slot %.1f MiB)", id ? "." : "", id, g_maps.path(id),
                    m.geometry.width, m.geometry.height, static_cast<double>(m.geometry.resolution),
                    g_maps.slot_bytes(id) / 1048576.0);
      }
      if (g_maps.spare_bytes() > 0) std::printf(", reload spare %.1f MiB", g_maps.spare_bytes() / 1048576.0);
      if (g_maps.shared_work_bytes() > 0) {
        std::printf(", MML working memory shared by the maps %.1f MiB", g_maps.shared_work_bytes() / 1048576.0);
      }
      std::printf(", board %s\n", g_board.describe());
    }
    return problems == 0 ? 0 : 1;
  }
  std::printf("mmlfw memory report (config '%s', localizer %s, arena used %zu of %zu bytes)\n", a.config_path,
              active_system().localizer().name(), g_arena.used(), g_arena.capacity());
  mr.print(stdout);
  std::printf("footprint: arena reserved %.3f MiB (used %.3f MiB) + static objects %.3f MiB + relation table "
              "(image copy) %.3f MiB = %.3f MiB (%.3f MiB with the arena trimmed to its peak use)\n",
              g_arena.capacity() / 1048576.0, g_arena.used() / 1048576.0, statics / 1048576.0,
              table_copy / 1048576.0, footprint / 1048576.0, (arena_need + statics + table_copy) / 1048576.0);
  // Pre-flight verdict: a configuration this machine cannot run is an error, with the reason.
  return print_check_problems(a, su, &memory_status, 0) == 0 ? 0 : 1;
}

// Service manager: READY=1 and the first STATUS= once start-up is done; the watchdog feed starts.
hal::PoseEstimate g_status_sent{};
std::uint32_t g_faults_sent = 0;
std::uint64_t g_status_sent_ns = 0;
void send_status() {
  char text[192];
  fw::format_service_status(text, sizeof(text), g_loop.last_estimate(), g_loop.health());
  const fw::Status st = g_notify.send(text);
  if (!st) g_board.hal().log->log(hal::LogLevel::kWarning, "mmlfw: %s", st.message());
  g_status_sent = g_loop.last_estimate();
  g_faults_sent = g_loop.health().fault_bits;
}
void notify_ready(std::uint64_t now_ns) {
  if (!g_notify.enabled()) return;
  const fw::Status st = g_notify.send("READY=1");
  if (!st) g_board.hal().log->log(hal::LogLevel::kWarning, "mmlfw: %s", st.message());
  send_status();
  g_status_sent_ns = now_ns;
  const hal::Health& h = g_loop.health();
  g_watchdog.start(g_notify.watchdog_period_ns(), now_ns, h.scans_processed, h.deadline_misses);
  g_board.hal().log->log(hal::LogLevel::kInfo, "mmlfw: service manager notified on '%s' (watchdog %s, check every %.0f ms)",
                         g_notify.socket_name(), g_notify.watchdog_period_ns() ? "on" : "off",
                         g_watchdog.check_interval_ns() * 1e-6);
}
// One sensor-loop cycle: WATCHDOG=1 while the loop keeps its deadline (firmware/app/service_notify.h),
// STATUS= when the status, its reason or the faults changed (at most every 250 ms; refreshed every
// 5 s for the counters). A failed send is logged once per kind and counted (the manager
// restarting is no reason for the firmware to stop).
void notify_cycle(std::uint64_t now_ns) {
  if (!g_notify.enabled()) return;
  const hal::Health& h = g_loop.health();
  if (g_watchdog.cycle(now_ns, h.scans_processed, h.deadline_misses)) {
    const fw::Status st = g_notify.send("WATCHDOG=1");
    if (!st && g_notify.failed() == 1) g_board.hal().log->log(hal::LogLevel::kWarning, "mmlfw: %s", st.message());
  }
  if (fw::service_status_due(g_status_sent, g_faults_sent, g_loop.last_estimate(), h.fault_bits, now_ns,
                             g_status_sent_ns)) {
    send_status();
    g_status_sent_ns = now_ns;
  }
}
// --test-stall-after: the sensor loop hangs (no steps, no feed) until a signal ends the process.
void stall_for_test() {
  g_board.hal().log->log(hal::LogLevel::kWarning, "mmlfw: --test-stall-after: the sensor loop stalls now");
  while (!g_stop) usleep(10000);
}

// The steady state: scans in, poses out, heartbeats, until a signal, --max-scans or --duration.
// Returns the number of steps that failed.
std::uint64_t run_loop(const Args& a) {
  const fw::AppConfig& c = g_config;
  hal::Hal& hal = g_board.hal();
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  signal(SIGPIPE, SIG_IGN);

  hal.log->log(hal::LogLevel::kInfo, "mmlfw: running (localizer %s, %d workers, %d map(s))", active_system().localizer().name(), c.workers,
               g_maps.count());
  const std::uint64_t t_start = hal.clock->now_ns();
  const std::uint64_t health_period = static_cast<std::uint64_t>(c.health_period_ms) * 1000000ull;
  std::uint64_t last_health = t_start;
  std::uint64_t scans = 0, step_errors = 0;
  notify_ready(t_start);
  while (!g_stop) {
    if (a.test_stall_after_s > 0 && static_cast<double>(hal.clock->now_ns() - t_start) * 1e-9 >= a.test_stall_after_s) {
      stall_for_test();
      break;
    }
    g_board.wait_for_input(5);
    for (int k = 0; k < 16 && !g_stop; ++k) {
      const fw::Status st = g_loop.spin_once();
      if (!st) ++step_errors;
      if (!g_loop.stepped()) break;
      ++scans;
      last_health = hal.clock->now_ns();  // the loop published health with the pose
      if (c.log_level == static_cast<int>(hal::LogLevel::kDebug)) trace_step(hal);
      if (a.max_scans > 0 && static_cast<long>(scans) >= a.max_scans) g_stop = 1;
    }
    const std::uint64_t now = hal.clock->now_ns();
    if (now - last_health >= health_period) {
      g_board.publish_heartbeat(g_loop.health());
      last_health = now;
    }
    if (a.duration_s > 0 && static_cast<double>(now - t_start) * 1e-9 >= a.duration_s) g_stop = 1;
    notify_cycle(now);
    g_operator.watch_faults(g_loop.health().fault_bits);
  }
  return step_errors;
}

// --timing-report: per-stage perf counters of both execution contexts.
void print_timing_report(const Startup& su) {
  const fw::AppConfig& c = g_config;
  std::fprintf(stderr, "mmlfw timing report (ms; context: sensor = main thread, global = MML thread%s)\n",
               su.global_thread ? "" : " (inline: inside loop.step)");
  std::fprintf(stderr, "  %-8s %-14s %10s %9s %9s %9s %9s %9s\n", "context", "stage", "count", "mean", "p50", "p99",
               "max", "deadline");
  auto row = [](const char* ctx, const char* stage, const fw::PerfStats& p, double deadline_ms) {
    std::fprintf(stderr, "  %-8s %-14s %10llu %9.3f %9.3f %9.3f %9.3f %9.3f\n", ctx, stage,
                 static_cast<unsigned long long>(p.count), p.mean_ms, p.p50_ms, p.p99_ms, p.max_ms, deadline_ms);
  };
  const double sensor_ms = c.step_deadline_ms;
  row("sensor", g_loop.perf_poll().name(), g_loop.perf_poll().stats(), 0);
  row("sensor", g_loop.perf_pair().name(), g_loop.perf_pair().stats(), 0);
  row("sensor", g_loop.perf_step().name(), g_loop.perf_step().stats(), sensor_ms);
  row("sensor", g_loop.perf_publish().name(), g_loop.perf_publish().stats(), 0);
  row("sensor", g_loop.perf_total().name(), g_loop.perf_total().stats(), 0);
  if (const fw::track::TrackedLocalizer* t = active_system().tracked()) {
    const fw::track::GlobalContext& gc = t->global_context();
    row(su.global_thread ? "global" : "sensor", "global.step", gc.step_stats(),
        su.global_thread ? su.global_ctx.deadline_ns * 1e-6 : 0);
    if (const fw::mml::MmlLocalizer* m = active_system().mml(); m != nullptr && su.global_thread) {
      // The global step's stages (timed in deadline mode; read after the global thread stopped).
      row("global", m->front_end_perf().name(), m->front_end_perf().stats(), 0);
      row("global", m->match_perf().name(), m->match_perf().stats(), 0);
      row("global", m->after_match_perf().name(), m->after_match_perf().stats(), 0);
    }
    std::fprintf(stderr, "  global: jobs %llu, overruns %llu, skipped offers %llu (every %u scans, result after %u)\n",
                 static_cast<unsigned long long>(gc.jobs()), static_cast<unsigned long long>(gc.overruns()),
                 static_cast<unsigned long long>(gc.skipped_offers()), gc.schedule().every_n_scans,
                 gc.schedule().result_delay_scans);
    if (su.global_thread) {
      std::fprintf(stderr, "  global: last window %.3f ms (median scan interval %.3f ms, at least %.3f ms)\n",
                   gc.last_window_ns() * 1e-6, gc.median_scan_interval_ns() * 1e-6, su.global_ctx.deadline_ns * 1e-6);
    }
  }
}

// The one-line exit summary on stderr.
void print_summary(std::uint64_t step_errors) {
  const fw::PerfStats step = g_loop.perf_step().stats();
  const fw::PerfStats total = g_loop.perf_total().stats();
  const hal::Health& h = g_loop.health();
  const hal_can::CanNode* node = g_board.can_node();
  const hal::CanBusStats* bus = g_board.can_bus() ? &g_board.can_bus()->stats() : nullptr;
  // SICK, Hokuyo or RPLIDAR: the same counters (hal_serial::SerialLaser).
  const hal_serial::SerialLaserCounters sl =
      g_board.serial_laser() ? g_board.serial_laser()->counters() : hal_serial::SerialLaserCounters{};
  std::fprintf(stderr,
               "mmlfw summary: {\"scans_processed\": %u, \"step_errors\": %llu, \"step_p50_ms\": %.3f, "
               "\"step_p99_ms\": %.3f, \"step_max_ms\": %.3f, \"cycle_p99_ms\": %.3f, \"deadline_misses\": %u, "
               "\"dropped_scans\": %u, \"timeouts\": %u, \"can_scans_ok\": %u, \"can_scans_dropped\": %u, \"can_scans_overwritten\": %u, "
               "\"can_crc_errors\": %u, \"can_lost_segments\": %u, \"can_duplicate_segments\": %u, "
               "\"can_odometry\": %u, \"can_rx_frames\": %llu, \"can_rx_dropped\": %llu, \"can_error_frames\": %llu, "
               "\"can_bus_off\": %llu, \"can_tx_failed\": %llu, \"serial_scans\": %u, \"serial_crc_errors\": %u, "
               "\"invalid_scans\": %u, \"can_invalid_scans\": %u, \"serial_bad_measurements\": %u, "
               "\"serial_reconnects\": %u, \"serial_dropped\": %u, \"serial_device_restarts\": %u, "
               "\"laser_timeouts\": %llu, \"fault_bits\": %u, "
               "\"last_status\": \"%s\"}\n",
               h.scans_processed, static_cast<unsigned long long>(step_errors), step.p50_ms, step.p99_ms, step.max_ms,
               total.p99_ms, h.deadline_misses, h.dropped_scans, h.timeouts,
               node ? node->decoder_stats().scans_ok : 0, node ? node->decoder_stats().scans_dropped : 0,
               node ? node->scans_overflowed() : 0,
               node ? node->decoder_stats().crc_errors : 0, node ? node->decoder_stats().lost_segments : 0,
               node ? node->decoder_stats().duplicate_segments : 0, node ? node->decoder_stats().odometry_ok : 0,
               bus ? static_cast<unsigned long long>(bus->rx_frames) : 0ull,
               bus ? static_cast<unsigned long long>(bus->rx_dropped) : 0ull,
               bus ? static_cast<unsigned long long>(bus->error_frames) : 0ull,
               bus ? static_cast<unsigned long long>(bus->bus_off) : 0ull,
               bus ? static_cast<unsigned long long>(bus->tx_failed) : 0ull,
               sl.scans, sl.checksum_errors, h.invalid_scans, node ? node->decoder_stats().invalid_scans : 0,
               sl.bad_measurements, g_board.serial_reconnects(), sl.dropped, sl.device_restarts,
               static_cast<unsigned long long>(g_loop.counters().laser_timeouts),
               h.fault_bits, hal::status_name(g_loop.last_estimate().status));
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  if (const int rc = parse_args(argc, argv, &a)) return rc < 0 ? 0 : rc;
  const fw::Status st = fw::load_app_config(a.config_path, &g_config);
  if (!st) {
    std::fprintf(stderr, "mmlfw: %s\n", st.message());
    if (a.check_config) std::fprintf(stderr, "mmlfw: check-config '%s': 1 problem(s)\n", a.config_path);
    return a.check_config ? 1 : 2;
  }
  // The service manager's socket (systemd Type=notify): a malformed NOTIFY_SOCKET / WATCHDOG_USEC
  // fails start-up, as a watchdog that could never be fed would restart the firmware forever.
  if (!a.preflight()) {
    const fw::Status ns = g_notify.open_from_env();
    if (!ns) return fail("service notification", ns);
  }
  Startup& su = g_startup;
  if (const int rc = open_board(a, &su)) return rc;
  if (const int rc = prepare_memory_and_sensor_context(a, &su)) return stage_failed(a, su, rc);
  if (const int rc = start_workers(a)) return stage_failed(a, su, rc);
  if (const int rc = build_localizer(a, &su)) return stage_failed(a, su, rc);
  if (const int rc = memory_budget(a, su); rc >= 0) return rc;
  const std::uint64_t step_errors = run_loop(a);
  g_notify.send("STOPPING=1");
  g_operator.dump("exit");
  g_system.stop_global_context();  // before the pool it drives
  g_maps.stop_global_contexts();
  if (a.timing_report) print_timing_report(su);
  print_summary(step_errors);
  g_pool.stop();
  return 0;
}
