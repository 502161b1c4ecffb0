#include "sim/cli/map_switch_scenario.h"

#include <time.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "firmware/app/map_set.h"
#include "firmware/runtime/command_handler.h"
#include "firmware/runtime/odometry_interpolation.h"
#include "sim/cli/sim_runner.h"
#include "sim/map/map_image_writer.h"
#include "sim/world/builtin_worlds.h"
#include "sim/world/raster.h"
#include "sim/world/synthetic_run.h"

namespace sim {
namespace {

double cpu_now_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// A scan with the odometry interpolated to its time, as the loop pairs them (odometry_interpolation.h).
struct Step {
  hal::LaserScan scan;
  hal::Odometry odom;
  fw::Se2d truth;
  double t = 0;
};

// The frames of a whole run, generated before any localizer runs (so that the counted part of a
// test sees only the firmware).
bool make_steps(const std::string& world_name, std::uint64_t seed, std::size_t scans, std::uint64_t start_ns,
                std::vector<Step>* out, std::string* err) {
  World world;
  if (!make_builtin_world(world_name, &world, err)) return false;
  SyntheticRunOptions so;
  so.seed = seed;
  so.max_scans = scans;
  so.start_time_ns = start_ns;
  SyntheticRun run;
  if (!run.init(world, so, err)) return false;
  SyntheticFrame f;
  hal::Odometry prev{};
  bool have_prev = false;
  while (run.next(&f)) {
    Step s;
    s.scan = f.scan;
    s.truth = f.truth;
    s.t = f.t;
    hal::Odometry before = prev, after = prev;
    bool have_before = have_prev;
    for (const hal::Odometry& o : f.odometry) {
      if (o.timestamp_ns <= f.scan.timestamp_ns) {
        before = o;
        have_before = true;
      }
      after = o;
      prev = o;
      have_prev = true;
    }
    if (!have_before) before = after;
    if (!fw::interpolate_odometry(before, after, f.scan.timestamp_ns, &s.odom).is_ok()) s.odom = after;
    out->push_back(s);
  }
  return !out->empty();
}

bool wrong(const hal::PoseEstimate& e, const fw::Se2d& truth) {
  const double dx = e.x - truth.x, dy = e.y - truth.y;
  double dth = std::remainder(static_cast<double>(e.theta) - truth.theta, 2.0 * M_PI);
  return std::hypot(dx, dy) > kIntegrityLimitM || std::fabs(dth) * 180.0 / M_PI > kIntegrityLimitDeg;
}

// Threaded global search: wait until the active map's global step is done (at most ~2 s), as if
// every global step finished within its window (the next scan then takes its result).
void wait_global_idle(fw::MapSet& maps) {
  fw::track::TrackedLocalizer* t = maps.active().tracked();
  if (t == nullptr || !t->global_context().threaded()) return;
  for (int i = 0; i < 20000 && t->global_context().job_in_flight(); ++i) {
    const timespec ts{0, 100000};
    nanosleep(&ts, nullptr);
  }
}

// `n` scans of `steps` from `from` on the active localizer: localized scans and wrong ones.
void drive_steps(fw::Localizer*& loc, fw::MapSet& maps, const std::vector<Step>& steps, std::size_t from, std::size_t n,
             long* localized, long* wrong_steps) {
  hal::PoseEstimate e;
  for (std::size_t i = from; i < from + n && i < steps.size(); ++i) {
    const Step& s = steps[i];
    const bool ok = loc->step(s.scan, s.odom, &e).is_ok();
    wait_global_idle(maps);
    if (!ok || e.status != hal::LocalizationStatus::kLocalized) continue;
    ++*localized;
    if (wrong(e, s.truth)) ++*wrong_steps;
  }
}

bool flip_byte(const std::string& path, std::size_t at, std::string* err) {
  std::vector<std::uint8_t> bytes;
  if (!read_file_bytes(path, &bytes, err)) return false;
  if (bytes.size() <= at) at = bytes.size() / 2;
  bytes[at] ^= 0x5A;
  return write_file_bytes(path, bytes, err);
}

}  // namespace

bool write_world_map_image(const std::string& world_name, const std::string& path, std::string* err) {
  World world;
  if (!make_builtin_world(world_name, &world, err)) return false;
  OccupancyGrid grid;
  if (!rasterize_world(world, RasterOptions(), &grid, err)) return false;
  MapImageWriter writer;
  if (!writer.set_grid(grid, err)) return false;
  if (!writer.write(path, err)) {
    *err = path + ": " + *err;
    return false;
  }
  return true;
}

bool run_map_switch(const MapSwitchOptions& opt, MapSwitchResult* out, std::string* err) {
  *out = MapSwitchResult();
  const std::string path_a = opt.dir + "/a.mmap", path_b = opt.dir + "/b.mmap";
  if (!write_world_map_image(opt.world_a, path_a, err) || !write_world_map_image(opt.world_b, path_b, err)) return false;
  std::vector<Step> steps_a, steps_b;
  if (!make_steps(opt.world_a, opt.seed, opt.scans_a, 1'000'000'000ull, &steps_a, err)) return false;
  // Floor B's run starts after A's (the same clock; the lift ride takes 10 s).
  const std::uint64_t b_start = steps_a.back().scan.timestamp_ns + 10'000'000'000ull;
  const bool back_to_a = opt.scans_after_reload > 0;
  const std::size_t b_scans = opt.scans_b + (back_to_a ? 0 : opt.scans_after_corrupt);
  if (!make_steps(opt.world_b, opt.seed + 1, b_scans, b_start, &steps_b, err)) return false;
  // The ride back to floor A (another run there, after B's).
  std::vector<Step> steps_a2;
  const std::uint64_t a2_start = steps_b.back().scan.timestamp_ns + 10'000'000'000ull;
  if (back_to_a && !make_steps(opt.world_a, opt.seed + 2, opt.scans_after_reload + opt.scans_after_corrupt, a2_start,
                               &steps_a2, err)) {
    return false;
  }

  // The firmware's side: start-up as mmlfw does it (map_set.h), then only steps and commands.
  auto arena = std::make_unique<fw::StartupArena>();
  auto maps = std::make_unique<fw::MapSet>();
  fw::Status st = arena->init_mapped(std::size_t(512) << 20, false, "map switch");
  fw::MapSetSpec spec;
  spec.count = 2;
  spec.paths[0] = path_a.c_str();
  spec.paths[1] = path_b.c_str();
  spec.reload = opt.reload_slot;
  static const fw::track::GlobalScheduleOptions live = fw::track::live_global_schedule();
  if (opt.threaded_global) spec.system.global_schedule = &live;
  if (st) st = maps->init(spec, *arena, nullptr, nullptr);
  if (st) st = maps->start_global_contexts(opt.threaded_global, false, nullptr, fw::kGlobalContext);
  if (!st) {
    *err = std::string("map set: ") + st.message();
    return false;
  }
  arena->seal();
  out->slot_bytes_a = maps->slot_bytes(0);
  out->slot_bytes_b = maps->slot_bytes(1);
  out->shared_work_bytes = maps->shared_work_bytes();
  fw::Localizer* loc = &maps->active().localizer();
  fw::CommandHandler handler;
  fw::CommandHandlerOptions ho;
  ho.maps = maps.get();
  ho.on_switch = [](void* ctx, fw::Localizer& l) { *static_cast<fw::Localizer**>(ctx) = &l; };
  ho.switch_ctx = &loc;
  handler.init(nullptr, loc, ho);

  hal::PoseEstimate e;
  for (const Step& s : steps_a) {
    const bool ok = loc->step(s.scan, s.odom, &e).is_ok();
    wait_global_idle(*maps);
    if (!ok) continue;
    if (e.status != hal::LocalizationStatus::kLocalized) continue;
    out->localized_on_a = true;
    if (wrong(e, s.truth)) ++out->integrity_failures_a;
  }
  if (opt.before_switch != nullptr) opt.before_switch();
  hal::Command select;
  select.kind = hal::CommandKind::kSelectMap;
  select.seq = 1;
  select.map_id = 1;
  const double c0 = cpu_now_s();
  out->switch_reply = handler.handle(select).result;
  out->select_cpu_s = cpu_now_s() - c0;
  const double t_select = steps_a.back().t;  // the command arrives with the robot on floor B
  const double b_t0 = steps_b.front().t;
  double steps_cpu = 0;
  for (std::size_t i = 0; i < opt.scans_b && i < steps_b.size(); ++i) {
    const Step& s = steps_b[i];
    const double c1 = cpu_now_s();
    const bool ok = loc->step(s.scan, s.odom, &e).is_ok();
    steps_cpu += cpu_now_s() - c1;
    wait_global_idle(*maps);
    if (!ok || e.status != hal::LocalizationStatus::kLocalized) continue;
    ++out->localized_steps_b;
    if (wrong(e, s.truth)) ++out->integrity_failures;
    if (out->scans_to_localized < 0) {
      out->scans_to_localized = static_cast<long>(i + 1);
      // Robot time: from the SELECT_MAP (sent when the lift doors open, at B's first scan) to this scan.
      out->seconds_to_localized = s.t - b_t0;
      out->steps_cpu_s = steps_cpu;
    }
  }
  (void)t_select;
  if (opt.after_b != nullptr) out->allocations = opt.after_b();
  std::size_t next = opt.scans_b;
  const std::vector<Step>* last_run = &steps_b;
  if (back_to_a) {
    // Back on floor A: A's good image read again into the spare and switched to, A searched afresh.
    hal::Command reload = select;
    reload.seq = 3;
    reload.map_id = 0;
    reload.reload = true;
    out->reload_reply = handler.handle(reload).result;
    drive_steps(loc, *maps, steps_a2, 0, opt.scans_after_reload, &out->localized_after_reload, &out->integrity_failures);
    next = opt.scans_after_reload;
    last_run = &steps_a2;
  }
  out->reloads = maps->reloads();
  if (opt.scans_after_corrupt == 0) return true;

  // The image of B replaced on disk by a broken one, then a reload asked for: refused, B stays.
  if (!flip_byte(path_b, 4096, err)) return false;
  fw::Result<fw::Localizer*> direct = maps->select(1, true);
  out->corrupt_message = direct ? "" : direct.status().message();
  hal::Command reload = select;
  reload.seq = 2;
  reload.reload = true;
  out->corrupt_reply = handler.handle(reload).result;
  out->active_after_corrupt = maps->active_id();
  drive_steps(loc, *maps, *last_run, next, opt.scans_after_corrupt, &out->localized_after_corrupt, &out->integrity_failures);
  out->reloads = maps->reloads();
  return true;
}

}  // namespace sim
