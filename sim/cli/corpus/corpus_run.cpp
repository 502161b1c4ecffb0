#include "sim/cli/corpus/corpus_run.h"

#include <chrono>
#include <cmath>
#include <cstring>

#include "firmware/base/rng.h"
#include "sim/cli/sim_runner.h"
#include "sim/world/odometry_profiles.h"
#include "sim/world/sensor_profiles.h"

namespace sim::corpus {

double processed_scan_period(double rate_hz) {
  if (!(rate_hz > 0)) return 0.2;
  return std::max(1.0, std::round(0.2 * rate_hz)) / rate_hz;
}

namespace {

// An unmapped wing for a via-unknown draw: a 6 × 6 m block around a route node away from the
// start, erased from the map (the world keeps it), so the robot drives into space the map lacks.
void add_unmapped_block(std::uint64_t seed, World* world, World* map) {
  const RouteGraph& g = world->route;
  if (g.nodes.empty()) return;
  fw::RandomStream r(seed, 7);
  const Vec2 c = g.nodes[r.uniform_index(static_cast<std::uint32_t>(g.nodes.size()))];
  Box b{c - Vec2(3, 3), c + Vec2(3, 3)};
  b.min = b.min.cwiseMax(world->bounds.min);
  b.max = b.max.cwiseMin(world->bounds.max);
  world->unknown_areas.push_back(b);
  map->unknown_areas.push_back(b);
}

bool configure(const CorpusDraw& d, const CorpusRunOptions& opt, const World& world, const World& map,
               const MapDrawing& drawing, SimConfig* cfg, std::string* err) {
  const SensorProfile* sensor = find_sensor_profile(d.sensor);
  const OdometryProfile* wheels = find_odometry_profile(d.odometry);
  if (sensor == nullptr || wheels == nullptr) {
    *err = "unknown profile '" + (sensor == nullptr ? d.sensor : d.odometry) + "'";
    return false;
  }
  cfg->custom_world = &world;
  cfg->custom_map_world = &map;
  cfg->map_drawing = drawing.bent ? &drawing : nullptr;
  cfg->localizer = "mml-track";
  if (!wheels->tracker_odom_noise.empty()) cfg->localizer_options["odom_noise"] = wheels->tracker_odom_noise;
  cfg->localizer_options["odom_noise_per_step"] =
      wheels->tracker_odom_noise_per_step.empty() ? "0,0" : wheels->tracker_odom_noise_per_step;
  if (!wheels->tracker_odom_slip.empty()) cfg->localizer_options["odom_slip"] = wheels->tracker_odom_slip;
  for (const auto& [key, value] : opt.localizer_options) cfg->localizer_options[key] = value;
  cfg->seed = d.seed;
  cfg->threads = opt.threads;
  cfg->wall_timing = opt.timing;
  cfg->progress = false;
  cfg->pictures = !opt.picture_dir.empty();
  cfg->out_dir = opt.picture_dir;
  SyntheticRunOptions& so = cfg->synthetic;
  so.laser = sensor->laser;
  so.odometry = wheels->wheels;
  so.scan_period_s = processed_scan_period(sensor->rate_hz);
  so.people = d.people;
  so.kidnap_at_scan = d.kidnap_at_scan;
  so.max_scans = opt.max_scans;
  so.route.length_m = d.route_length_m * opt.route_scale;
  so.route.speed = 0.5 * (d.speed_min + d.speed_max);
  so.route.speed_min = d.speed_min;
  so.route.speed_max = d.speed_max;
  so.route.stop_probability = d.stop_probability;
  so.route.via_unknown = d.via_unknown;
  return true;
}

CorpusStep corpus_step(const StepRecord& r) {
  CorpusStep s;
  s.err_m = static_cast<float>(r.err_m);
  s.err_deg = static_cast<float>(r.err_deg);
  s.pl_xy_m = r.estimate.protection_xy_m;
  s.pl_theta_deg = static_cast<float>(r.estimate.protection_theta_rad * 180.0 / M_PI);
  s.travelled_m = static_cast<float>(r.travelled_m);
  s.step_ms = static_cast<float>(r.step_ms);
  s.status = static_cast<std::uint8_t>(r.estimate.status);
  s.mode = static_cast<std::uint8_t>(r.estimate.mode);
  s.reason = static_cast<std::uint8_t>(r.estimate.reason);
  s.has_pose = r.has_pose && r.has_truth ? 1 : 0;
  s.in_unknown = r.in_unknown ? 1 : 0;
  s.kidnapped = r.kidnapped ? 1 : 0;
  s.wait_cause = wait_cause_index(r.wait_cause);
  return s;
}

}  // namespace

const std::vector<std::string>& wait_cause_names() {
  static const std::vector<std::string> names = {"none",  "odometry-jump",      "unexplained", "innovation",
                                                 "better-rival", "odometry-window", "alias-beyond-alert",
                                                 "hint", "mml-conflict",   "other"};
  return names;
}

std::uint8_t wait_cause_index(const char* name) {
  const std::vector<std::string>& n = wait_cause_names();
  if (name == nullptr) return 0;
  for (std::size_t k = 0; k + 1 < n.size(); ++k) {
    if (n[k] == name) return static_cast<std::uint8_t>(k);
  }
  return static_cast<std::uint8_t>(n.size() - 1);
}

CorpusRun run_draw(const CorpusDraw& d, const CorpusRunOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  CorpusRun run;
  run.draw = d;
  BuildingPlan plan;
  World world, map;
  std::string err;
  SimConfig cfg;
  SimResult result;
  if (!generate_building(d.building, d.seed, &plan, &err) ||
      !apply_map_changes(plan, d.changes, d.seed, &world, &map, &run.changes, &err)) {
    run.error = "building: " + err;
  } else {
    if (d.via_unknown) add_unmapped_block(d.seed, &world, &map);
    const Vec2 size = plan.structure.bounds.max - plan.structure.bounds.min;
    run.width_m = size.x();
    run.height_m = size.y();
    if (!configure(d, opt, world, map, run.changes.drawing, &cfg, &err) || !run_simulation(cfg, &result, &err)) {
      run.error = err;
    } else {
      run.ok = true;
      run.steps.reserve(result.steps.size());
      for (const StepRecord& r : result.steps) run.steps.push_back(corpus_step(r));
    }
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!opt.timing) run.seconds = 0;
  return run;
}

// ---- bytes ----
// Layout: "MMLCRUN1", then fixed-size fields and the step array; the draw itself is not stored (the
// parent knows it by index and copies it back).

namespace {
template <class T>
void put(std::string* b, const T& v) {
  b->append(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <class T>
bool get(const std::string& b, std::size_t* at, T* v) {
  if (*at + sizeof(T) > b.size()) return false;
  std::memcpy(v, b.data() + *at, sizeof(T));
  *at += sizeof(T);
  return true;
}
}  // namespace

std::string serialize_run(const CorpusRun& run) {
  std::string b = "MMLCRUN1";
  put(&b, static_cast<std::uint8_t>(run.ok));
  put(&b, static_cast<std::uint32_t>(run.error.size()));
  b += run.error;
  put(&b, run.changes.clutter_items);
  put(&b, run.changes.doors_flipped);
  put(&b, run.changes.furniture_moved);
  put(&b, static_cast<std::uint8_t>(run.changes.distorted));
  put(&b, run.width_m);
  put(&b, run.height_m);
  put(&b, run.seconds);
  put(&b, static_cast<std::uint64_t>(run.steps.size()));
  b.append(reinterpret_cast<const char*>(run.steps.data()), run.steps.size() * sizeof(CorpusStep));
  return b;
}

bool deserialize_run(const std::string& b, CorpusRun* run, std::string* err) {
  std::size_t at = 8;
  std::uint8_t ok = 0, distorted = 0;
  std::uint32_t elen = 0;
  std::uint64_t n = 0;
  bool good = b.size() >= 8 && b.compare(0, 8, "MMLCRUN1") == 0 && get(b, &at, &ok) && get(b, &at, &elen) &&
              at + elen <= b.size();
  if (good) {
    run->error = b.substr(at, elen);
    at += elen;
    good = get(b, &at, &run->changes.clutter_items) && get(b, &at, &run->changes.doors_flipped) &&
           get(b, &at, &run->changes.furniture_moved) && get(b, &at, &distorted) && get(b, &at, &run->width_m) &&
           get(b, &at, &run->height_m) && get(b, &at, &run->seconds) && get(b, &at, &n) &&
           b.size() - at == n * sizeof(CorpusStep);
  }
  if (!good) {
    *err = "corpus run record truncated or malformed (" + std::to_string(b.size()) + " bytes)";
    return false;
  }
  run->ok = ok != 0;
  run->changes.distorted = distorted != 0;
  run->steps.resize(n);
  std::memcpy(run->steps.data(), b.data() + at, n * sizeof(CorpusStep));
  return true;
}

}  // namespace sim::corpus
