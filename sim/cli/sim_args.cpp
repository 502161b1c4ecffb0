#include "sim/cli/sim_args.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "sim/world/builtin_worlds.h"

namespace sim {

namespace {

bool parse_double(const std::string& flag, const std::string& v, double lo, double hi, double* out, std::string* err) {
  errno = 0;
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (v.empty() || end != v.c_str() + v.size() || errno != 0 || !std::isfinite(d)) {
    *err = flag + ": '" + v + "' is not a number";
    return false;
  }
  if (d < lo || d > hi) {
    *err = flag + ": " + v + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    return false;
  }
  *out = d;
  return true;
}

bool parse_u64(const std::string& flag, const std::string& v, unsigned long long hi, unsigned long long* out,
               std::string* err) {
  errno = 0;
  char* end = nullptr;
  if (v.empty() || v[0] == '-' || v[0] == '+') {
    *err = flag + ": '" + v + "' is not a non-negative integer";
    return false;
  }
  const unsigned long long n = std::strtoull(v.c_str(), &end, 10);
  if (end != v.c_str() + v.size() || errno != 0) {
    *err = flag + ": '" + v + "' is not a non-negative integer";
    return false;
  }
  if (n > hi) {
    *err = flag + ": " + v + " is larger than " + std::to_string(hi);
    return false;
  }
  *out = n;
  return true;
}

}  // namespace

std::string sim_usage() {
  return R"(usage: mml-sim (--world NAME | --dataset NAME | --log FILE.clf[.gz] [--reference POSES.txt]
                [--map MAP.yaml|MAP.mmap] [--start N]) [options]

Feeds a synthetic world or a CARMEN log through the hal/sim backend into the firmware's localization
loop and writes DIR/steps.csv, DIR/summary.json, DIR/run.svg, DIR/run.png and DIR/map.yaml/.pgm.

source:
  --world NAME            built-in world: small-office, large-office, corridor
  --dataset NAME          a dataset of ../shared/data (intel, fr079, aces, mit-killian, fr-clinic): its raw
                          log, reference poses and global map (built once, cached in build/maps)
  --log FILE              CARMEN log (plain or gzip) to replay
  --reference FILE        ground truth for the log's scans: "flaser_index ipc logger x y theta" rows
                          (*.corrected-poses.txt, or written by 'mml-carmen reference RAW CORRECTED OUT')
  --map FILE              the localizer's global map for the log: a ROS map_server YAML, or a compiled
                          map image (.mmap from mml-mapc / mml-mapbuild; its relation table is used)
  --start N               replay the log from its scan N (0-based; default 0)
  --max-log-mib N         refuse a log larger than N MiB, plain or inflated (default 512; stops gzip bombs)
run:
  --localizer NAME        localizer (default mml-track, the firmware's; --list shows all)
  --opt KEY=VALUE         localizer option (repeatable), e.g. --opt anchor=truth for odom
  --seed N                random seed (route, people, noise; default 1)
  --steps N               stop after N scans (default: the whole route / log)
  --paced                 pace at the data's real time (default: lockstep, as fast as possible)
  --speed F               pacing speed factor with --paced (default 1)
  --threads N             worker threads offered to the localizer (default 2, as mml-eval; results
                          depend on the seed only, not on N)
  --deadline-ms MS        count localizer steps longer than MS as deadline misses (default off)
  --out DIR               output directory (default build/run)
  --timing wall|none      measure step times with the wall clock (default) or not (byte-identical CSV)
  --transport none|can|sick  how scans and odometry reach the firmware: straight into the hal/sim
                          rings (none, default); through our CAN encoder, the hal/sim loopback bus and
                          the firmware's CanNode decoder (can); scans as SICK LMS2xx telegrams on the
                          hal/sim serial port through the firmware's SickLaser driver (sick)
  --sensor-resolution exact|can|sick  what the simulated sensors report: exact floats (default with
                          --transport none) or what that wire carries (always with can / sick); with
                          --timing none, `none --sensor-resolution X` and `X` give the same steps.csv
  --byte-fault-rate P     with --transport can|sick: drop or bit-flip each frame / telegram with
                          probability P (seeded by --seed); the firmware's decoder drops and counts
                          what it cannot use (summary.json, summary line)
  --quiet                 no progress line
  --no-pictures           skip run.svg / run.png
synthetic world:
  --people N              moving people (default: per world)
  --beams N               laser beams over 180 deg (181 or 361 for an LMS 200; default 361)
  --max-range M           laser maximum range in m (8 or 80 for an LMS 200; default 8)
  --range-noise SIGMA     laser range noise in m (default 0.005)
  --dropout P             probability of a max-range dropout per beam (default 0.01)
  --odom-noise T,R        odometry noise per scan step: T m, R deg (default 0.04,4); with a log: extra
                          noise on the log's odometry (default none)
  --scan-period S         seconds between scans (default 0.4)
  --route-length M        metres to drive (default: per world)
  --start-node N          route-graph node to start at (default: drawn from the seed)
  --enter-unknown         the route may enter the unknown area
  --via-unknown           drive into the unknown area first (the localizer should say outside-map there)
  --kidnap-at N           at scan N carry the robot to another place (odometry does not see it); with a
                          log: the replay jumps to a scan >= 5 m away (drawn from the seed)
  --map-unknown           keep the unknown area in the map (default: erased)
  --resolution M          map resolution in m (default: per world; large-office 0.06)
other:
  --list                  list worlds and localizers
  --help                  this text
)";
}

std::string sim_list() {
  std::string s = "worlds:\n";
  for (const auto& w : builtin_world_names()) s += "  " + w + "\n";
  s += "localizers:\n";
  for (const auto& l : localizer_names()) s += "  " + l.name + "  " + l.description + "\n";
  return s;
}

bool parse_sim_args(const std::vector<std::string>& args, SimConfig* cfg, SimArgsAction* action, std::string* err) {
  *action = SimArgsAction::kRun;
  cfg->out_dir = "build/run";
  cfg->threads = 2;  // as mml-eval (SimConfig's own default stays 1 for the library's tests)
  std::vector<std::string> world_only;  // options of synthetic worlds that were given
  bool start_given = false, odom_noise_given = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](std::string* v) {
      if (i + 1 >= args.size() || (args[i + 1].rfind("--", 0) == 0 && args[i + 1].size() > 2)) {
        *err = a + " needs a value";
        return false;
      }
      *v = args[++i];
      return true;
    };
    std::string v;
    double d = 0;
    unsigned long long n = 0;
    if (a == "--help" || a == "-h") {
      *action = SimArgsAction::kHelp;
    } else if (a == "--list") {
      *action = SimArgsAction::kList;
    } else if (a == "--world") {
      if (!value(&cfg->world)) return false;
    } else if (a == "--dataset") {
      if (!value(&cfg->dataset)) return false;
    } else if (a == "--log") {
      if (!value(&cfg->log_path)) return false;
    } else if (a == "--reference") {
      if (!value(&cfg->reference_path)) return false;
    } else if (a == "--map") {
      if (!value(&cfg->map_yaml)) return false;
    } else if (a == "--start") {
      if (!value(&v) || !parse_u64(a, v, 100000000ull, &n, err)) return false;
      cfg->log_start = static_cast<size_t>(n);
      start_given = true;
    } else if (a == "--max-log-mib") {
      if (!value(&v) || !parse_u64(a, v, 1ull << 20, &n, err)) return false;
      if (n == 0) {
        *err = "--max-log-mib: must be at least 1";
        return false;
      }
      cfg->max_log_bytes = static_cast<std::uint64_t>(n) << 20;
    } else if (a == "--localizer") {
      if (!value(&cfg->localizer)) return false;
    } else if (a == "--opt") {
      if (!value(&v)) return false;
      const size_t eq = v.find('=');
      if (eq == std::string::npos || eq == 0) {
        *err = "--opt: '" + v + "' is not KEY=VALUE";
        return false;
      }
      cfg->localizer_options[v.substr(0, eq)] = v.substr(eq + 1);
    } else if (a == "--seed") {
      if (!value(&v) || !parse_u64(a, v, ~0ull, &n, err)) return false;
      cfg->seed = n;
    } else if (a == "--steps") {
      if (!value(&v) || !parse_u64(a, v, 100000000ull, &n, err)) return false;
      cfg->steps = static_cast<size_t>(n);
    } else if (a == "--paced") {
      cfg->paced = true;
    } else if (a == "--speed") {
      if (!value(&v) || !parse_double(a, v, 0.01, 1000, &cfg->pace_speed, err)) return false;
    } else if (a == "--threads") {
      if (!value(&v) || !parse_u64(a, v, 64, &n, err)) return false;
      if (n == 0) {
        *err = "--threads: must be at least 1";
        return false;
      }
      cfg->threads = static_cast<int>(n);
    } else if (a == "--deadline-ms") {
      if (!value(&v) || !parse_double(a, v, 0, 100000, &cfg->deadline_ms, err)) return false;
    } else if (a == "--out") {
      if (!value(&cfg->out_dir)) return false;
    } else if (a == "--timing") {
      if (!value(&v)) return false;
      if (v != "wall" && v != "none") {
        *err = "--timing: '" + v + "' (expected wall or none)";
        return false;
      }
      cfg->wall_timing = v == "wall";
    } else if (a == "--transport") {
      if (!value(&v)) return false;
      if (!parse_transport(v, &cfg->transport.transport)) {
        *err = "--transport: '" + v + "' (expected none, can or sick)";
        return false;
      }
    } else if (a == "--sensor-resolution") {
      if (!value(&v)) return false;
      if (v != "exact" && v != "can" && v != "sick") {
        *err = "--sensor-resolution: '" + v + "' (expected exact, can or sick)";
        return false;
      }
      cfg->transport.resolution = v == "can"    ? SensorResolution::kCan
                                  : v == "sick" ? SensorResolution::kSick
                                                : SensorResolution::kExact;
    } else if (a == "--byte-fault-rate") {
      if (!value(&v) || !parse_double(a, v, 0, 1, &cfg->transport.byte_fault_rate, err)) return false;
    } else if (a == "--quiet") {
      cfg->progress = false;
    } else if (a == "--no-pictures") {
      cfg->pictures = false;
    } else if (a == "--people") {
      world_only.push_back(a);
      if (!value(&v) || !parse_u64(a, v, 200, &n, err)) return false;
      cfg->synthetic.people = static_cast<int>(n);
    } else if (a == "--beams") {
      world_only.push_back(a);
      if (!value(&v) || !parse_u64(a, v, hal::LaserScan::kMaxBeams, &n, err)) return false;
      if (n < 2) {
        *err = "--beams: need at least 2";
        return false;
      }
      cfg->synthetic.laser.beams = static_cast<int>(n);
    } else if (a == "--max-range") {
      world_only.push_back(a);
      if (!value(&v) || !parse_double(a, v, 0.5, 200, &cfg->synthetic.laser.max_range, err)) return false;
    } else if (a == "--range-noise") {
      world_only.push_back(a);
      if (!value(&v) || !parse_double(a, v, 0, 1, &cfg->synthetic.laser.sigma_range, err)) return false;
    } else if (a == "--dropout") {
      world_only.push_back(a);
      if (!value(&v) || !parse_double(a, v, 0, 1, &cfg->synthetic.laser.dropout_rate, err)) return false;
    } else if (a == "--odom-noise") {
      if (!value(&v)) return false;
      const size_t comma = v.find(',');
      if (comma == std::string::npos) {
        *err = "--odom-noise: '" + v + "' is not T,R (metres,degrees per scan step)";
        return false;
      }
      if (!parse_double(a, v.substr(0, comma), 0, 10, &cfg->synthetic.odometry.sigma_trans, err) ||
          !parse_double(a, v.substr(comma + 1), 0, 180, &cfg->synthetic.odometry.sigma_rot_deg, err)) {
        return false;
      }
      cfg->log_odom_sigma_m = cfg->synthetic.odometry.sigma_trans;
      cfg->log_odom_sigma_deg = cfg->synthetic.odometry.sigma_rot_deg;
      odom_noise_given = true;
    } else if (a == "--scan-period") {
      world_only.push_back(a);
      if (!value(&v) || !parse_double(a, v, 0.01, 10, &cfg->synthetic.scan_period_s, err)) return false;
    } else if (a == "--route-length") {
      world_only.push_back(a);
      if (!value(&v) || !parse_double(a, v, 1, 100000, &cfg->synthetic.route.length_m, err)) return false;
    } else if (a == "--start-node") {
      world_only.push_back(a);
      if (!value(&v) || !parse_u64(a, v, 1000000, &n, err)) return false;
      cfg->synthetic.route.start_node = static_cast<int>(n);
    } else if (a == "--via-unknown") {
      world_only.push_back(a);
      cfg->synthetic.route.via_unknown = true;
    } else if (a == "--kidnap-at") {
      if (!value(&v) || !parse_u64(a, v, 100000000ull, &n, err)) return false;
      if (n == 0) {
        *err = "--kidnap-at: the scan index must be at least 1";
        return false;
      }
      cfg->synthetic.kidnap_at_scan = static_cast<size_t>(n);
      cfg->log_kidnap_at = static_cast<size_t>(n);
    } else if (a == "--enter-unknown") {
      world_only.push_back(a);
      cfg->synthetic.route.avoid_unknown = false;
    } else if (a == "--map-unknown") {
      world_only.push_back(a);
      cfg->raster.erase_unknown_areas = false;
    } else if (a == "--resolution") {
      world_only.push_back(a);
      if (!value(&v) || !parse_double(a, v, 0.01, 1, &d, err)) return false;
      cfg->raster.resolution = d;
    } else {
      *err = "unknown argument '" + a + "' (see --help)";
      return false;
    }
  }
  if (*action != SimArgsAction::kRun) return true;
  const int sources = !cfg->world.empty() + !cfg->log_path.empty() + !cfg->dataset.empty();
  if (sources == 0) {
    *err = "no input: give --world NAME, --dataset NAME or --log FILE (see --help)";
    return false;
  }
  if (sources > 1) {
    *err = "--world, --dataset and --log exclude each other";
    return false;
  }
  if (!cfg->reference_path.empty() && cfg->log_path.empty() && cfg->dataset.empty()) {
    *err = "--reference needs --log";
    return false;
  }
  if (!cfg->map_yaml.empty() && cfg->log_path.empty() && cfg->dataset.empty()) {
    *err = "--map is for --log replays (worlds bring their own map)";
    return false;
  }
  const bool log_source = cfg->world.empty();
  if (log_source) {
    if (!world_only.empty()) {
      *err = world_only.front() + " is an option of synthetic worlds (--world); a log (--log, --dataset) brings " +
             "its own laser, route and map";
      return false;
    }
    cfg->log_odom_noise = odom_noise_given;
    cfg->synthetic.kidnap_at_scan = 0;
  } else {
    if (start_given) {
      *err = "--start is for --log / --dataset replays (a world's route: --start-node)";
      return false;
    }
    cfg->log_kidnap_at = 0;
  }
  return true;
}

}  // namespace sim
