#include "sim/cli/sim_runner.h"

#include "firmware/app/localizer_names.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <thread>

#include "firmware/base/arena.h"
#include "firmware/map/map_image.h"
#include "firmware/runtime/localization_loop.h"
#include "firmware/track/global_context.h"
#include "firmware/track/track_options.h"
#include "hal/hal.h"
#include "hal_linux/linux_clock.h"
#include "hal_linux/black_box_file.h"
#include "hal_sim/sim_hal.h"
#include "sim/cli/log_frames.h"
#include "sim/cli/reference_judge.h"
#include "sim/cli/run_picture.h"
#include "sim/common/units.h"
#include "sim/io/datasets.h"
#include "sim/map/global_maps.h"
#include "sim/map/map_image_writer.h"
#include "sim/world/builtin_worlds.h"

namespace sim {

namespace {

// What the run knows of the scan a published estimate belongs to (by scan id).
struct FrameInfo {
  double t = 0;
  bool has_truth = false;
  fw::Se2d truth;
  double truth_bound_m = 0, truth_bound_rad = 0;  // the reference's own error bound (log_frames.h)
  double travelled_m = 0;
  bool kidnapped = false;
  bool in_unknown = false;
};

// A compiled map image starts with the magic "MMLFWMAP" (firmware/map/map_image.h).
bool is_map_image_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;  // errors: left to the YAML reader
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return false;
  char magic[8] = {};
  const bool ok = std::fread(magic, 1, sizeof(magic), f) == sizeof(magic) && std::memcmp(magic, "MMLFWMAP", 8) == 0;
  std::fclose(f);
  return ok;
}

// ---- configuration ----

// --dataset NAME: the raw log, its reference poses and the global map built from the corrected log
// (cached by sim/map/global_maps.h under build/maps).
bool resolve_dataset(SimConfig* cfg, std::string* err) {
  const Dataset* ds = find_dataset(cfg->dataset);
  if (ds == nullptr) {
    std::string names;
    for (const Dataset& d : datasets()) names += (names.empty() ? "" : ", ") + d.name;
    *err = "unknown dataset '" + cfg->dataset + "' (known: " + names + ")";
    return false;
  }
  if (ds->raw_log.empty()) {
    *err = "dataset '" + cfg->dataset + "' has no raw log";
    return false;
  }
  cfg->log_path = data_path(ds->raw_log);
  if (!std::filesystem::exists(cfg->log_path)) {
    *err = "dataset '" + cfg->dataset + "': log '" + cfg->log_path + "' not found (MMLFW_DATA_DIR=" + data_dir() + ")";
    return false;
  }
  if (cfg->reference_path.empty() && !ds->corrected_poses.empty()) cfg->reference_path = data_path(ds->corrected_poses);
  if (cfg->map_yaml.empty()) {
    RosMap m;
    if (!ensure_global_map(cfg->dataset, 0.0, map_cache_dir(), &m, err)) {
      *err = "dataset '" + cfg->dataset + "': global map: " + *err;
      return false;
    }
    cfg->map_yaml = global_map_yaml_path(cfg->dataset);
  }
  return true;
}

// Fail before a long run, not after it.
bool create_output_dir(const std::string& out_dir, std::string* err) {
  if (out_dir.empty()) return true;
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec || !std::filesystem::is_directory(out_dir)) {
    *err = "cannot create output directory '" + out_dir + "'" + (ec ? ": " + ec.message() : "");
    return false;
  }
  return true;
}

// The firmware's default when it is registered, else dead reckoning.
std::string default_localizer() {
  std::string name = "odom";
  for (const LocalizerInfo& l : localizer_names()) {
    if (l.name == fw::kDefaultLocalizer) name = fw::kDefaultLocalizer;
  }
  return name;
}

// Exactly one source: a world (built-in or custom) or a log; a reference only with a log.
bool check_sources(SimConfig* cfg, std::string* err) {
  if (cfg->custom_world != nullptr) {
    if (!cfg->world.empty() || !cfg->log_path.empty()) {
      *err = "a custom world excludes --world and --log";
      return false;
    }
    cfg->world = cfg->custom_world->name.empty() ? "custom" : cfg->custom_world->name;
  } else if (cfg->custom_map_world != nullptr) {
    *err = "a custom map world needs a custom world";
    return false;
  }
  if (cfg->world.empty() == cfg->log_path.empty()) {
    *err = "give exactly one of a world (--world) or a log (--log)";
    return false;
  }
  if (!cfg->reference_path.empty() && cfg->log_path.empty()) {
    *err = "--reference needs --log";
    return false;
  }
  return true;
}

// The configuration as the run uses it: a dataset resolved to its log, reference and map, the
// output folder created, the localizer named, the source checked.
}  // namespace

// The product's tracker is told what its α model (odom_noise) misses of the simulated wheels, as a
// deployment configures its robot's odometry: a world's wheels err by σ per scan step whatever the
// motion (Sec. 5.7.1: 4 cm on x and y, 4° — standing, turning on the spot or driving). Per axis that
// σ becomes odom_noise_per_step (track_options.h) where the α model gives less on the robot's
// nominal straight step (route speed × scan period): on the large office's 0.3 m step the default α
// already give 0.2 × 0.3 m = 6 cm ≥ 4 cm (not counted twice), and 0.2 × 0.3 = 3.4° < 4° of rotation
// (handed over). An explicit --opt odom_noise_per_step wins (0,0: the α model alone). Not for logs:
// their wheels are real, --odom-noise only adds to them.
std::string wheel_noise_beyond_alpha(const SimConfig& cfg) {
  if (cfg.localizer != "mml-track" || cfg.localizer_options.count("odom_noise_per_step") > 0) return "";
  if (cfg.world.empty() && cfg.custom_world == nullptr) return "";
  const fw::track::TrackOptions defaults;
  double tt = defaults.odom_trans_per_m, tr = 0, rr = 0, rt = defaults.odom_rot_per_m;
  const auto given = cfg.localizer_options.find("odom_noise");
  if (given != cfg.localizer_options.end() &&
      std::sscanf(given->second.c_str(), "%lf,%lf,%lf,%lf", &tt, &tr, &rr, &rt) != 4) {
    return "";  // malformed: the localizer's factory names it
  }
  const OdometryNoiseOptions& wheels = cfg.synthetic.odometry;
  const double step_m = cfg.synthetic.route.speed * cfg.synthetic.scan_period_s;
  const double rot_rad = wheels.sigma_rot_deg * 3.14159265358979 / 180.0;
  const double m = tt * step_m < wheels.sigma_trans ? wheels.sigma_trans : 0.0;
  const double deg = rt * step_m < rot_rad ? wheels.sigma_rot_deg : 0.0;
  if (!(m > 0.0 || deg > 0.0)) return "";
  char v[64];
  std::snprintf(v, sizeof(v), "%g,%g", std::min(m, 1.0), std::min(deg, 28.0));  // the option's ranges
  return v;
}

namespace {

bool complete_config(const SimConfig& cfg_in, SimConfig* cfg, std::string* err) {
  *cfg = cfg_in;
  if (!cfg->dataset.empty()) {
    if (!cfg->world.empty() || !cfg->log_path.empty()) {
      *err = "--dataset excludes --world and --log";
      return false;
    }
    if (!resolve_dataset(cfg, err)) return false;
  }
  if (!create_output_dir(cfg->out_dir, err)) return false;
  if (cfg->localizer.empty()) cfg->localizer = default_localizer();
  const std::string wheels = wheel_noise_beyond_alpha(*cfg);
  if (!wheels.empty()) cfg->localizer_options["odom_noise_per_step"] = wheels;
  return check_sources(cfg, err);
}

// ---- source and map ----

// What the run replays (a synthetic run or the frames of a log) and the map it localizes on.
struct SimSource {
  std::vector<std::uint8_t> image;  // the compiled map image the firmware loads
  bool image_from_file = false;
  World world;
  SyntheticRun synthetic;
  std::vector<Frame> log_frames;
  OccupancyGrid grid;
  bool have_grid = false;
  std::size_t total = 0;  // frames to replay
};

bool load_world_source(const SimConfig& cfg, SimSource* src, SimSummary* sum, std::string* err) {
  if (cfg.custom_world != nullptr) {
    src->world = *cfg.custom_world;
  } else if (!make_builtin_world(cfg.world, &src->world, err)) {
    return false;
  }
  SyntheticRunOptions so = cfg.synthetic;
  so.seed = cfg.seed;
  if (cfg.steps > 0) so.max_scans = cfg.steps;
  if (!src->synthetic.init(src->world, so, err)) {
    *err = "world '" + cfg.world + "': " + *err;
    return false;
  }
  const World& mapped = cfg.custom_map_world != nullptr ? *cfg.custom_map_world : src->world;
  if (!rasterize_world(mapped, cfg.raster, &src->grid, err)) return false;
  src->have_grid = true;
  src->total = src->synthetic.num_scans();
  sum->source = "world:" + cfg.world;
  return true;
}

// --map: a compiled map image (used as it is) or a ROS map_server YAML.
bool load_map_file(const SimConfig& cfg, SimSource* src, std::string* err) {
  if (!cfg.map_yaml.empty()) {
    if (is_map_image_file(cfg.map_yaml)) {
      // A compiled map image (mml-mapc / mml-mapbuild): used as it is, relation table included.
      if (!read_file_bytes(cfg.map_yaml, &src->image, err)) return false;
      src->image_from_file = true;
    } else {
      RosMap rm;
      if (!read_ros_map(cfg.map_yaml, &rm, err) || !ros_map_to_grid(rm, &src->grid, err)) return false;
    }
    src->have_grid = true;
  }
  return true;
}

bool load_log_source(const SimConfig& cfg, SimSource* src, SimSummary* sum, std::string* err) {
  if (!load_log_frames(cfg, &src->log_frames, &sum->scans_restamped, err)) return false;
  src->total = src->log_frames.size();
  if (!load_map_file(cfg, src, err)) return false;
  sum->source = cfg.dataset.empty() ? "log:" + std::filesystem::path(cfg.log_path).filename().string()
                                    : "dataset:" + cfg.dataset;
  return true;
}

bool load_source(const SimConfig& cfg, SimSource* src, SimSummary* sum, std::string* err) {
  return cfg.world.empty() ? load_log_source(cfg, src, sum, err) : load_world_source(cfg, src, sum, err);
}

// The map as the firmware holds it: the compiled map image loaded by the firmware's own loader into
// a start-up arena.
struct FirmwareMap {
  fw::StartupArena arena;
  fw::GlobalMap global_map;
};

void print_map_image_info(const SimConfig& cfg, const std::vector<std::uint8_t>& image, const fw::GlobalMap& map) {
  std::size_t table_len = 0;
  const bool table = fw::find_section(image.data(), image.size(), fw::MapSectionType::kRelationTable2D,
                                      &table_len) != nullptr;
  std::fprintf(stderr, "mml-sim: map image %s: %ux%u cells at %.3g m; relation table: %s\n", cfg.map_yaml.c_str(),
               map.geometry.width, map.geometry.height, static_cast<double>(map.geometry.resolution),
               table ? "in the image (used as it is)" : "none (the localizer fills its own at start-up)");
}

// The host grid (pictures, map.yaml, the MCL baseline) from a map image's own occupancy.
void grid_from_firmware_map(const fw::GlobalMap& map, OccupancyGrid* grid) {
  grid->geometry = map.geometry;
  grid->cells.assign(grid->geometry.cell_count(), fw::kCellUnknown);
  for (std::uint32_t cy = 0; cy < grid->geometry.height; ++cy) {
    for (std::uint32_t cx = 0; cx < grid->geometry.width; ++cx) {
      grid->cells[grid->geometry.index(cx, cy)] = map.cell(static_cast<std::int32_t>(cx), static_cast<std::int32_t>(cy));
    }
  }
}

// A simulated map is compiled first; a map image from a file is loaded as it is and gives the host
// grid. Nothing to do without a map.
bool load_firmware_map(const SimConfig& cfg, SimSource* src, FirmwareMap* map, std::string* err) {
  if (!src->have_grid) return true;
  if (!src->image_from_file) {
    MapImageWriter writer;
    if (!writer.set_grid(src->grid, err)) return false;
    src->image = writer.bytes();
  }
  const std::vector<std::uint8_t>& image = src->image;
  const std::string what = src->image_from_file ? cfg.map_yaml : std::string("simulated map");
  fw::Status s = map->arena.init_mapped(fw::map_image_arena_bytes(image.data(), image.size()) + (1u << 20), false, "map");
  if (s.is_ok()) s = fw::load_map_image(image.data(), image.size(), map->arena, &map->global_map, what.c_str());
  if (!s.is_ok()) {
    *err = (src->image_from_file ? cfg.map_yaml + ": " : std::string("map: ")) + s.message();
    return false;
  }
  if (src->image_from_file && cfg.progress) print_map_image_info(cfg, image, map->global_map);
  if (src->image_from_file) grid_from_firmware_map(map->global_map, &src->grid);
  return true;
}

// ---- localizer ----

// Through the simulator's registry (sim/cli/localizer_factory.h); the product, mml-track, is built
// there by the firmware's start-up builder.
std::unique_ptr<fw::Localizer> build_localizer(const SimConfig& cfg, SimSource& src, FirmwareMap& map,
                                               LocalizerHooks* hooks, std::string* err) {
  LocalizerContext ctx;
  ctx.global_map = src.have_grid ? &map.global_map : nullptr;
  ctx.map_image = src.have_grid ? &src.image : nullptr;
  ctx.grid = src.have_grid ? &src.grid : nullptr;
  ctx.map_name = cfg.world.empty() ? cfg.map_yaml : cfg.world;
  ctx.seed = cfg.seed;
  ctx.threads = cfg.threads;
  ctx.options = cfg.localizer_options;
  ctx.hooks = hooks;
  if (!cfg.world.empty()) {
    ctx.has_true_start = true;
    ctx.true_start = src.synthetic.trajectory().pose_at(0);
  } else if (!src.log_frames.empty() && src.log_frames.front().has_truth) {
    ctx.has_true_start = true;
    ctx.true_start = src.log_frames.front().truth;
  }
  return make_localizer(cfg.localizer, ctx, err);
}

// ---- HAL (simulation backend) and the firmware loop ----

struct TaskCtx {
  fw::LocalizationLoop* loop;
  fw::Status status;
};

// The hal/sim backend, the sensor transport and the firmware's loop, wired once by wire_firmware;
// it stays where it is (the loop and its task hold pointers into it).
struct FirmwareRig {
  std::unique_ptr<hal_sim::SimHal> sim_hal = std::make_unique<hal_sim::SimHal>();
  hal_linux::LinuxClock wall_clock;
  hal_sim::SteppedClock frozen_clock;  // perf clock when timing is off: every duration is 0
  std::unique_ptr<SensorTransport> transport = std::make_unique<SensorTransport>();
  TransportOptions topt;
  std::unique_ptr<fw::LocalizationLoop> loop = std::make_unique<fw::LocalizationLoop>();
  fw::LocalizationLoopOptions lo;
  TaskCtx task_ctx{nullptr, fw::Status::ok()};
  // Issue 60: operator commands (on the CAN wire with --transport can, else straight to the loop)
  // and the black box on the CanNode with the outputs teed into it.
  DirectCommands direct_commands;
  fw::CommandHandler commands;
  BlackBoxRecorder black_box;
  std::uint8_t command_seq = 0;
};

// Issue 60: commands reach the loop's handler; the black box records the CanNode's traffic and the
// published poses (--blackbox, --replay-blackbox).
bool wire_operator(const SimConfig& cfg, fw::Localizer& localizer, FirmwareRig* rig, std::string* err) {
  hal::Hal& hal = rig->sim_hal->hal;
  const bool can = rig->transport->carries_odometry();  // commands travel with the odometry
  const bool serial = is_serial(rig->topt.transport);
  const bool black_box = !cfg.blackbox.record_path.empty() || !cfg.blackbox.replay_path.empty();
  if (black_box && !can) {
    *err = "--blackbox / --replay-blackbox record the firmware's wires: they need --transport can, sick, hokuyo or rplidar";
    return false;
  }
  hal.commands = can ? &rig->transport->commands() : static_cast<hal::CommandSource*>(&rig->direct_commands);
  rig->commands.init(&hal, &localizer, fw::CommandHandlerOptions());
  rig->loop->set_command_handler(&rig->commands);
  if (black_box) {
    BlackBoxRecorder& r = rig->black_box;
    r.storage.resize(cfg.blackbox.frames);
    r.box.init(r.storage.data(), r.storage.size());
    rig->transport->attach_black_box(&r.box);
    if (serial) {
      r.serial_storage.resize(cfg.blackbox.serial_chunks);
      r.serial.init(r.serial_storage.data(), r.serial_storage.size());
      rig->transport->attach_serial_black_box(&r.serial);
    }
    r.tee = std::make_unique<BlackBoxTee>(hal.pose_sink, &r.box);
    hal.pose_sink = r.tee.get();
  }
  return true;
}

// --transport can|sick|hokuyo|rplidar: the loop reads the firmware's CanNode on the hal/sim loopback
// bus or its SickLaser / HokuyoLaser / RplidarLaser on a hal/sim serial port instead of the rings (sim/devices/sensor_transport.h), on the
// same stepped clock.
bool wire_firmware(const SimConfig& cfg, fw::Localizer& localizer, FirmwareRig* rig, SimSummary* sum,
                   std::string* err) {
  hal::Hal& hal = rig->sim_hal->hal;
  rig->topt = cfg.transport;
  rig->topt.seed = cfg.seed;
  // Issue 60: a black box with a serial laser records the odometry and commands on the CAN wire, as
  // a robot with `odometry = socketcan:IFACE` gets them, so one file holds every input.
  if (!cfg.blackbox.record_path.empty() || !cfg.blackbox.replay_path.empty()) rig->topt.sick_odometry_on_can = true;
  if (!rig->transport->init(rig->topt, &rig->sim_hal->clock, err)) return false;
  if (rig->topt.transport != Transport::kNone) hal.laser = &rig->transport->laser();
  if (rig->transport->carries_odometry()) hal.odometry = &rig->transport->odometry();
  sum->transport = transport_name(rig->topt.transport);
  rig->lo.perf_clock = cfg.wall_timing ? static_cast<const hal::Clock*>(&rig->wall_clock) : &rig->frozen_clock;
  rig->lo.step_deadline_ns = static_cast<std::uint64_t>(cfg.deadline_ms * 1e6);
  const fw::Status s = rig->loop->init(hal, localizer, rig->lo);
  if (!s.is_ok()) {
    *err = s.message();
    return false;
  }
  if (!wire_operator(cfg, localizer, rig, err)) return false;
  rig->task_ctx = {rig->loop.get(), fw::Status::ok()};
  rig->sim_hal->tasks.add_task("localization", [](void* c) {
    auto* tc = static_cast<TaskCtx*>(c);
    tc->status = tc->loop->spin_once();
  }, &rig->task_ctx, 0);
  return true;
}

// ---- run ----

// Feeds the frames through the hal/sim backend to the firmware loop, one task run per scan on the
// stepped clock (or paced at the data's real time), and records every published estimate.
class FrameLoop {
 public:
  FrameLoop(const SimConfig& cfg, SimSource& src, FirmwareRig& rig, const LocalizerHooks& hooks, SimResult* out)
      : cfg_(cfg), src_(src), rig_(rig), hooks_(hooks), out_(out), sum_(out->summary),
        unknown_known_(!cfg.world.empty() && cfg.raster.erase_unknown_areas && !src.world.unknown_areas.empty()) {
    info_.reserve(src.total);
  }

  // hypotheses.csv: every hypothesis of every step, when the localizer exposes them.
  bool open_hypotheses_csv(std::string* err) {
    if (!hooks_.hypotheses || cfg_.out_dir.empty()) return true;
    const std::string path = cfg_.out_dir + "/hypotheses.csv";
    hyp_csv_ = std::fopen(path.c_str(), "w");
    if (hyp_csv_ == nullptr) {
      *err = "cannot write '" + path + "'";
      return false;
    }
    std::fprintf(hyp_csv_, "step,x,y,theta,weight\n");
    return true;
  }

  void run(std::chrono::steady_clock::time_point wall_start) {
    wall_start_ = wall_start;
    last_progress_ = wall_start - std::chrono::seconds(1);
    for (std::size_t k = 0; k < src_.total; ++k) {
      if (!next_frame(k)) break;
      if (k == 0) t_first_ = frame_.t;
      if (cfg_.paced) wait_for_frame_time();
      note_frame_info();
      if (cfg_.hint.at_scan == k + 1) send_hint();
      feed_sensors();
      if (frame_.scan.timestamp_ns > rig_.sim_hal->clock.now_ns()) rig_.sim_hal->clock.set_ns(frame_.scan.timestamp_ns);
      rig_.sim_hal->tasks.run_once();
      if (!rig_.task_ctx.status.is_ok()) ++sum_.step_errors;
      record_estimates();
      if (cfg_.progress) print_progress(k);
    }
  }

  // Flushes a scan still waiting for odometry and closes hypotheses.csv.
  bool finish(std::string* err) {
    if (rig_.loop->scan_pending()) {
      rig_.sim_hal->clock.advance_ns(rig_.lo.odom_wait_ns + 1);
      rig_.sim_hal->tasks.run_once();
      record_estimates();
    }
    if (hyp_csv_ != nullptr && std::fclose(hyp_csv_) != 0) {
      *err = "error writing '" + cfg_.out_dir + "/hypotheses.csv'";
      return false;
    }
    if (cfg_.progress && tty_) std::fprintf(stderr, "\n");
    return true;
  }

  std::uint64_t ring_drops() const { return ring_drops_; }

 private:
  bool next_frame(std::size_t k) {
    if (cfg_.world.empty()) {
      frame_ = src_.log_frames[k];  // a copy: the summary asks the map about these scans afterwards
      return true;
    }
    if (!src_.synthetic.next(&sframe_)) return false;
    frame_.index = sframe_.index;
    frame_.t = sframe_.t;
    frame_.has_truth = true;
    frame_.truth = sframe_.truth;
    frame_.truth_bound_m = frame_.truth_bound_rad = 0;  // a simulated world's truth is exact
    frame_.travelled_m = sframe_.travelled_m;
    frame_.kidnapped = sframe_.kidnapped;
    frame_.odometry.swap(sframe_.odometry);
    frame_.scan = sframe_.scan;
    return true;
  }

  void wait_for_frame_time() const {
    const auto due = wall_start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                       std::chrono::duration<double>((frame_.t - t_first_) / cfg_.pace_speed));
    std::this_thread::sleep_until(due);
  }

  void note_frame_info() {
    if (info_.size() <= frame_.scan.scan_id) info_.resize(frame_.scan.scan_id + 1);
    bool in_unknown = false;
    if (unknown_known_ && frame_.has_truth) {
      for (const Box& b : src_.world.unknown_areas) in_unknown |= b.contains(Vec2(frame_.truth.x, frame_.truth.y));
    }
    fw::Se2d truth = frame_.truth;
    if (cfg_.map_drawing != nullptr && frame_.has_truth) {
      cfg_.map_drawing->pose(frame_.truth.x, frame_.truth.y, frame_.truth.theta, &truth.x, &truth.y, &truth.theta);
    }
    info_[frame_.scan.scan_id] = {frame_.t,           frame_.has_truth, truth,             frame_.truth_bound_m,
                                  frame_.truth_bound_rad, frame_.travelled_m, frame_.kidnapped, in_unknown};
  }

  // --hint-at: the operator's hint for this scan (from its truth), before the scan's data.
  void send_hint() {
    const hal::Command c = hint_command(cfg_.hint, frame_.truth, rig_.command_seq++);
    sum_.hint_step = static_cast<long>(out_->steps.size());
    std::string why;
    if (rig_.transport->carries_odometry()) {
      if (!rig_.transport->send_command(c, frame_.scan.timestamp_ns, &why)) sum_.hint_reply = "not sent: " + why;
    } else {
      rig_.direct_commands.push(c);
    }
  }

  // With --transport can|sick (or --sensor-resolution can|sick) the simulated sensors report what
  // the wire carries, so the driver path and the direct one see the same values.
  void feed_sensors() {
    SensorTransport& transport = *rig_.transport;
    for (hal::Odometry& o : frame_.odometry) transport.to_sensor_resolution(&o);
    transport.to_sensor_resolution(&frame_.scan);
    for (const hal::Odometry& o : frame_.odometry) {
      if (transport.carries_odometry()) {
        transport.send_odometry(o);
      } else if (!rig_.sim_hal->odometry.push(o)) {
        ++ring_drops_;
      }
    }
    if (rig_.topt.transport != Transport::kNone) {
      transport.send_scan(frame_.scan);
    } else if (!rig_.sim_hal->laser.push(frame_.scan)) {
      ++ring_drops_;
    }
  }

  StepRecord step_record(const hal::PoseEstimate& e) const {
    StepRecord r;
    r.step = static_cast<std::uint32_t>(out_->steps.size());
    r.estimate = e;
    if (e.scan_id < info_.size()) {
      const FrameInfo& fi = info_[e.scan_id];
      r.t = fi.t;
      r.has_truth = fi.has_truth;
      r.truth = fi.truth;
      r.truth_bound_m = fi.truth_bound_m;
      r.truth_bound_deg = fi.truth_bound_rad * kRadToDeg;
      r.travelled_m = fi.travelled_m;
      r.kidnapped = fi.kidnapped;
      r.in_unknown = fi.in_unknown;
    }
    r.has_pose = estimate_has_pose(e);
    if (r.has_truth && r.has_pose) {
      r.err_m = std::hypot(e.x - r.truth.x, e.y - r.truth.y);
      r.err_deg = std::fabs(fw::wrap_angle(static_cast<double>(e.theta) - r.truth.theta)) * kRadToDeg;
    }
    const hal::Odometry& o = rig_.loop->last_odometry();
    r.odom = fw::Se2d(o.x, o.y, o.theta);
    r.step_ms = static_cast<double>(rig_.loop->last_step_ns()) * 1e-6;
    if (hooks_.wait_cause) r.wait_cause = hooks_.wait_cause();
    return r;
  }

  // Status changes worth a line of their own: becoming sure (or faulty, or outside the map) and
  // losing it; searching <-> ambiguous flapping stays in the progress line.
  void report_status_change(const StepRecord& r) const {
    const hal::PoseEstimate& e = r.estimate;
    const auto notable = [](hal::LocalizationStatus st) {
      return st == hal::LocalizationStatus::kLocalized || st == hal::LocalizationStatus::kOutsideMap ||
             st == hal::LocalizationStatus::kFault;
    };
    if (e.status == last_status_ || !cfg_.progress || !(notable(e.status) || notable(last_status_))) return;
    std::fprintf(stderr, "%sstep %u (t=%.1f s, %.1f m): %s -> %s at (%.2f, %.2f, %.1f deg)", tty_ ? "\r\033[K" : "",
                 r.step, r.t, r.travelled_m, hal::status_name(last_status_), hal::status_name(e.status), e.x, e.y,
                 e.theta * kRadToDeg);
    if (!r.has_pose) std::fprintf(stderr, " (no pose)");
    if (r.has_truth) std::fprintf(stderr, "; truth (%.2f, %.2f)", r.truth.x, r.truth.y);
    if (r.has_truth && r.has_pose) std::fprintf(stderr, ", error %.2f m", r.err_m);
    if (e.protection_xy_m > 0) {
      std::fprintf(stderr, ", PL %.2f m / %.1f deg", e.protection_xy_m, e.protection_theta_rad * kRadToDeg);
    }
    std::fprintf(stderr, "\n");
  }

  void record_hypotheses(std::uint32_t step) {
    step_hyps_.clear();
    hooks_.hypotheses(&step_hyps_);
    if (step_hyps_.empty()) return;
    out_->last_hypotheses = step_hyps_;
    out_->last_hypotheses_step = step;
    if (hyp_csv_ == nullptr) return;
    for (const HypothesisPoint& h : step_hyps_) {
      std::fprintf(hyp_csv_, "%u,%.4f,%.4f,%.5f,%.5f\n", step, h.x, h.y, h.theta, h.weight);
    }
  }

  void record_estimates() {
    hal::PoseEstimate e;
    while (rig_.sim_hal->pose_sink.pop(&e)) {
      const StepRecord r = step_record(e);
      report_status_change(r);
      last_status_ = e.status;
      out_->steps.push_back(r);
      if (hooks_.hypotheses) record_hypotheses(r.step);
    }
  }

  void print_progress(std::size_t k) {
    const auto now = std::chrono::steady_clock::now();
    if (!(now - last_progress_ > std::chrono::milliseconds(tty_ ? 200 : 5000) || k + 1 == src_.total)) return;
    last_progress_ = now;
    const StepRecord* lr = out_->steps.empty() ? nullptr : &out_->steps.back();
    std::fprintf(stderr, "%s[%s %s] step %zu/%zu  t=%.1f s  %.1f m  status=%s", tty_ ? "\r\033[K" : "",
                 sum_.source.c_str(), cfg_.localizer.c_str(), k + 1, src_.total, frame_.t, frame_.travelled_m,
                 lr ? hal::status_name(lr->estimate.status) : "-");
    if (lr && std::isfinite(lr->err_m)) std::fprintf(stderr, "  err=%.2f m", lr->err_m);
    if (lr) std::fprintf(stderr, "  hyps=%u  %.2f ms/step", lr->estimate.hypothesis_count, lr->step_ms);
    if (!tty_) std::fprintf(stderr, "\n");
  }

  const SimConfig& cfg_;
  SimSource& src_;
  FirmwareRig& rig_;
  const LocalizerHooks& hooks_;
  SimResult* out_;
  SimSummary& sum_;
  // Whether a step's truth lies in the unknown area is known for a world whose unknown area was
  // erased from the map (availability leaves those steps out: there is nothing to localize on).
  const bool unknown_known_;
  std::vector<FrameInfo> info_;
  const bool tty_ = isatty(fileno(stderr)) != 0;
  std::chrono::steady_clock::time_point wall_start_, last_progress_;
  hal::LocalizationStatus last_status_ = hal::LocalizationStatus::kSearching;
  std::uint64_t ring_drops_ = 0;
  std::vector<HypothesisPoint> step_hyps_;
  std::FILE* hyp_csv_ = nullptr;
  Frame frame_;
  SyntheticFrame sframe_;
  double t_first_ = 0;
};

// ---- summary and outputs ----

// What the loop and the transport counted, and the run's wall time.
void collect_loop_counters(const FirmwareRig& rig, std::uint64_t ring_drops, double wall_s, SimSummary* sum) {
  sum->wall_s = wall_s;
  sum->scans_per_s = wall_s > 0 ? static_cast<double>(sum->steps) / wall_s : 0;
  sum->scans_dropped = rig.loop->health().dropped_scans;
  sum->ring_drops = ring_drops + rig.sim_hal->laser.stats().dropped + rig.sim_hal->odometry.stats().dropped;
  sum->odom_rejected = rig.loop->counters().odom_rejected;
  sum->scans_held = rig.loop->counters().scans_held;
  sum->deadline_misses = rig.loop->health().deadline_misses;
  sum->transport_stats = rig.transport->stats();
}

// On stderr: no fix, the loop's perf counters (with wall timing), the firmware's last log lines,
// and the story of the run.
void print_run_report(const SimConfig& cfg, const FirmwareRig& rig, const SimSummary& sum) {
  if (sum.first_localized_step < 0) {
    std::fprintf(stderr, "not localized in %zu steps (%.1f m); localizer '%s'\n", sum.steps, sum.path_length_m,
                 cfg.localizer.c_str());
  }
  if (cfg.wall_timing) {
    const fw::LocalizationLoop& loop = *rig.loop;
    for (const fw::PerfCounter* pc :
         {&loop.perf_poll(), &loop.perf_pair(), &loop.perf_step(), &loop.perf_publish(), &loop.perf_total()}) {
      pc->print(stderr);
    }
  }
  const hal_sim::SimLogSink& logs = rig.sim_hal->log;
  const std::size_t shown = std::min<std::size_t>(logs.size(), 10);
  for (std::size_t i = logs.size() - shown; i < logs.size(); ++i) {
    std::fprintf(stderr, "firmware: %s\n", logs.line(i).text);
  }
  if (logs.total() > shown) {
    std::fprintf(stderr, "firmware: (%llu warnings/errors in total, last %zu shown)\n",
                 static_cast<unsigned long long>(logs.total()), shown);
  }
  std::fputs(summary_story(sum).c_str(), stderr);
}

// --blackbox FILE: the ring as the firmware writes it (hal_linux/black_box_file.h).
bool write_black_box(const SimConfig& cfg, const FirmwareRig& rig, SimSummary* sum, std::string* err) {
  const fw::CommandCounters& cc = rig.commands.counters();
  if (sum->hint_step >= 0 && sum->hint_reply.empty()) {
    sum->hint_reply = cc.accepted > 0 ? "accepted" : cc.refused > 0 ? "refused" : "no reply";
  }
  if (cfg.blackbox.record_path.empty()) return true;
  sum->blackbox_frames = rig.black_box.box.size();
  sum->blackbox_serial_chunks = rig.black_box.serial.size();
  sum->blackbox_serial_bytes = rig.black_box.serial.bytes_recorded();
  const fw::Status s = hal_linux::write_black_box_file(&rig.black_box.box, &rig.black_box.serial,
                                                       cfg.blackbox.record_path.c_str(), &sum->blackbox_bytes);
  if (!s.is_ok()) *err = s.message();
  return s.is_ok();
}

// steps.csv, summary.json, the map (map.yaml/.pgm) and the pictures, into --out.
bool write_outputs(const SimConfig& cfg, const SimSource& src, const SimResult& r, std::string* err) {
  if (cfg.out_dir.empty()) return true;
  if (!write_steps_csv(cfg.out_dir + "/steps.csv", r.steps, err)) return false;
  if (!write_summary_json(cfg.out_dir + "/summary.json", r.summary, err)) return false;
  if (src.have_grid && !write_ros_map(cfg.out_dir + "/map.yaml", grid_to_ros_map(src.grid, "map.pgm"), err)) {
    return false;
  }
  return !cfg.pictures || write_pictures(cfg, r, cfg.world.empty() ? nullptr : &src.synthetic.world(),
                                         src.have_grid ? &src.grid : nullptr, err);
}

}  // namespace

bool is_placeholder_pose(const hal::PoseEstimate& e) {
  if (!std::isfinite(e.x) || !std::isfinite(e.y) || !std::isfinite(e.theta)) return true;
  if (e.x != 0.0f || e.y != 0.0f || e.theta != 0.0f) return false;
  for (float c : e.cov) {
    if (c != 0.0f) return false;
  }
  return true;
}

bool estimate_has_pose(const hal::PoseEstimate& e) {
  if (e.status == hal::LocalizationStatus::kSearching || e.status == hal::LocalizationStatus::kFault) return false;
  return !is_placeholder_pose(e);
}

bool run_simulation(const SimConfig& cfg_in, SimResult* out, std::string* err) {
  *out = SimResult();
  const auto load_start = std::chrono::steady_clock::now();
  SimConfig cfg;
  if (!complete_config(cfg_in, &cfg, err)) return false;
  if (cfg.progress && cfg_in.localizer_options.count("odom_noise_per_step") == 0 &&
      cfg.localizer_options.count("odom_noise_per_step") > 0) {
    std::fprintf(stderr, "mml-sim: mml-track is given the simulated wheels' noise its odom_noise model misses: "
                 "odom_noise_per_step=%s (metres, degrees per scan step; --opt odom_noise_per_step=0,0 for the α model alone)\n",
                 cfg.localizer_options.at("odom_noise_per_step").c_str());
  }
  SimSummary& sum = out->summary;
  sum.localizer = cfg.localizer;
  SimSource src;
  if (!load_source(cfg, &src, &sum, err)) return false;
  FirmwareMap map;
  if (!load_firmware_map(cfg, &src, &map, err)) return false;
  LocalizerHooks hooks;
  std::unique_ptr<fw::Localizer> localizer = build_localizer(cfg, src, map, &hooks, err);
  if (!localizer) return false;
  FirmwareRig rig;
  if (!wire_firmware(cfg, *localizer, &rig, &sum, err)) return false;
  // Issue 60: a threaded global search records in the black box when it took each result.
  fw::track::GlobalContext* gc = hooks.global_context ? hooks.global_context() : nullptr;
  if (gc != nullptr && !cfg.blackbox.record_path.empty()) gc->set_record_sink(&rig.black_box.box);

  FrameLoop frames(cfg, src, rig, hooks, out);
  // The run through hal/sim and the localizer is timed on its own (wall_s); loading before it is load_s.
  const auto wall_start = std::chrono::steady_clock::now();
  sum.load_s = std::chrono::duration<double>(wall_start - load_start).count();
  if (!frames.open_hypotheses_csv(err)) return false;
  frames.run(wall_start);
  if (!frames.finish(err)) return false;
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

  sum.steps = out->steps.size();
  // A log's reference is judged by the map where a step is beyond a limit against it (reference_judge.h).
  if (!src.log_frames.empty() && src.have_grid) {
    check_steps_against_map(map.global_map, src.log_frames, &out->steps);
    mark_unmapped_steps(map.global_map, src.log_frames, &out->steps);
  }
  collect_loop_counters(rig, frames.ring_drops(), wall_s, &sum);
  summarize_steps(out->steps, &sum);
  if (cfg.progress) print_run_report(cfg, rig, sum);
  if (!write_black_box(cfg, rig, &sum, err)) return false;
  return write_outputs(cfg, src, *out, err);
}

}  // namespace sim

namespace sim {

namespace {

// Issue 60: the file's global records (a robot with global_context = thread) and their lines.
struct GlobalRecords {
  std::vector<hal::GlobalRecord> records;
  std::vector<std::size_t> lines;
};

// Which laser a file's serial lines come from, when --transport does not say: SCIP 2.0 is text
// (LF-terminated ASCII lines), a SICK LMS2xx measured-value telegram starts 02 80 LEN LEN B0, an
// RPLIDAR sends binary samples with neither.
Transport serial_laser_of(const std::vector<BlackBoxLine>& lines) {
  std::string bytes;
  for (const BlackBoxLine& l : lines) {
    if (l.serial && !l.tx) bytes.append(l.bytes.begin(), l.bytes.end());
    if (bytes.size() > 16384) break;
  }
  const bool text = std::all_of(bytes.begin(), bytes.end(), [](char c) { return c == '\n' || (c >= 0x20 && c < 0x7F); });
  if (text) return Transport::kHokuyo;
  for (std::size_t i = 0; i + 4 < bytes.size(); ++i) {
    if (bytes[i] == 0x02 && static_cast<std::uint8_t>(bytes[i + 1]) == 0x80 && static_cast<std::uint8_t>(bytes[i + 4]) == 0xB0) {
      return Transport::kSick;
    }
  }
  return Transport::kRplidar;
}

GlobalRecords global_records(const std::vector<BlackBoxLine>& lines) {
  GlobalRecords g;
  for (const BlackBoxLine& l : lines) {
    if (!l.global) continue;
    g.records.push_back(l.record);
    g.lines.push_back(l.line_no);
  }
  return g;
}

// The global context replays the records instead of running on its thread: each job inline, its
// result held until the scan the robot took it at. Records need a threaded mml-track (its schedule).
bool replay_global_records(const std::string& path, const GlobalRecords& g, fw::track::GlobalContext* gc,
                           std::string* err) {
  if (g.records.empty() && (gc == nullptr || !gc->threaded())) return true;
  const std::string where = g.records.empty() ? path : path + ":" + std::to_string(g.lines.front());
  if (gc == nullptr || !gc->threaded()) {
    *err = where + ": a global record (a robot with global_context = thread): replay with --localizer mml-track "
           "--opt global=thread (and the robot's global_period)";
    return false;
  }
  gc->stop_thread();
  const fw::Status s = gc->replay(g.records.data(), g.records.size());
  if (!s.is_ok()) *err = where + ": " + s.message();
  return s.is_ok();
}

// The first record the replay did not meet, as "FILE:LINE: ...", or empty.
std::string global_mismatch(const std::string& path, const GlobalRecords& g, const fw::track::GlobalContext* gc) {
  if (gc == nullptr || !gc->replaying()) return "";
  if (!gc->replay_status().is_ok()) {
    return path + ":" + std::to_string(g.lines[gc->replay_failed_record()]) + ": " + gc->replay_status().message();
  }
  if (gc->replay_records_used() < g.records.size()) {
    return path + ":" + std::to_string(g.lines[gc->replay_records_used()]) +
           ": global record never met (the replay offered no job at the scan it names)";
  }
  return "";
}

}  // namespace

bool replay_black_box(const SimConfig& cfg_in, SimResult* out, BlackBoxReplay* replay, std::string* err) {
  *out = SimResult();
  *replay = BlackBoxReplay();
  std::vector<BlackBoxLine> lines;
  if (!read_black_box(cfg_in.blackbox.replay_path, &lines, err)) return false;
  const GlobalRecords global = global_records(lines);  // outlives the localizer's replay of them
  SimConfig cfg;
  // A robot's black box: its map (--map) and the localizer's options alone, no source to run.
  const bool robot = cfg_in.world.empty() && cfg_in.log_path.empty() && cfg_in.dataset.empty() &&
                     cfg_in.custom_world == nullptr;
  if (robot) {
    cfg = cfg_in;
    if (!create_output_dir(cfg.out_dir, err)) return false;
    if (cfg.localizer.empty()) cfg.localizer = default_localizer();
  } else if (!complete_config(cfg_in, &cfg, err)) {
    return false;
  }
  // CAN frames alone: the CAN laser; serial lines too: the serial laser's driver on the serial port
  // (--transport names it, else the bytes tell: serial_laser_of), the odometry and commands on the
  // CAN wire (issue 60).
  const bool serial = std::any_of(lines.begin(), lines.end(), [](const BlackBoxLine& l) { return l.serial; });
  cfg.transport.transport = !serial                                 ? Transport::kCan
                            : is_serial(cfg_in.transport.transport) ? cfg_in.transport.transport
                                                                    : serial_laser_of(lines);
  cfg.transport.byte_fault_rate = 0;
  SimSummary& sum = out->summary;
  sum.localizer = cfg.localizer;
  SimSource src;
  if (robot ? !load_map_file(cfg, &src, err) : !load_source(cfg, &src, &sum, err)) return false;
  FirmwareMap map;
  if (!load_firmware_map(cfg, &src, &map, err)) return false;
  LocalizerHooks hooks;
  std::unique_ptr<fw::Localizer> localizer = build_localizer(cfg, src, map, &hooks, err);
  if (!localizer) return false;
  FirmwareRig rig;
  if (!wire_firmware(cfg, *localizer, &rig, &sum, err)) return false;
  fw::track::GlobalContext* gc = hooks.global_context ? hooks.global_context() : nullptr;
  if (!replay_global_records(cfg_in.blackbox.replay_path, global, gc, err)) return false;
  replay->global_records = global.records.size();
  // Lockstep: each received frame at its receive time, one loop cycle after it (the firmware's
  // loop runs as soon as input is pending). Sent frames are what is compared, not fed.
  for (const BlackBoxLine& l : lines) {
    if (l.tx || l.global) continue;
    ++(l.serial ? replay->rx_serial_lines : replay->rx_frames);
    if (l.frame.timestamp_ns > rig.sim_hal->clock.now_ns()) rig.sim_hal->clock.set_ns(l.frame.timestamp_ns);
    // Hokuyo / RPLIDAR: the start-up handshake (not in the file) against the simulated device, at
    // the time of the first serial line, as the recording ran it at its first scan.
    if (l.serial && !rig.transport->start_serial_laser(l.frame.timestamp_ns, true, err)) {
      *err = cfg_in.blackbox.replay_path + ":" + std::to_string(l.line_no) + ": " + *err;
      return false;
    }
    const bool fed = l.serial ? rig.transport->inject_serial(l.bytes.data(), l.bytes.size())
                              : rig.transport->inject_frame(l.frame);
    if (!fed) {
      *err = l.serial ? "--replay-blackbox: the serial port refused bytes" : "--replay-blackbox: the loopback bus refused a frame";
      return false;
    }
    rig.sim_hal->tasks.run_once();
    if (!rig.task_ctx.status.is_ok()) ++sum.step_errors;
    hal::PoseEstimate e;
    while (rig.sim_hal->pose_sink.pop(&e)) {
      StepRecord r;
      r.step = static_cast<std::uint32_t>(out->steps.size());
      r.estimate = e;
      r.has_pose = estimate_has_pose(e);
      out->steps.push_back(r);
    }
  }
  sum.steps = out->steps.size();
  const std::vector<hal::CanFrame> recorded = pose_frames(lines);
  const std::vector<hal::CanFrame> replayed = pose_frames(rig.black_box.box);
  replay->recorded_pose_frames = recorded.size();
  replay->replayed_pose_frames = replayed.size();
  replay->identical = !recorded.empty() && same_frames(recorded, replayed, &replay->first_difference);
  replay->global_mismatch = global_mismatch(cfg_in.blackbox.replay_path, global, gc);
  if (!replay->global_mismatch.empty()) replay->identical = false;
  if (!cfg.out_dir.empty() && !write_steps_csv(cfg.out_dir + "/steps.csv", out->steps, err)) return false;
  return true;
}

}  // namespace sim
