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

// Walks the arguments; an option that takes a value consumes the one after it.
struct ArgCursor {
  const std::vector<std::string>& args;
  size_t i = 0;
  std::string* err;

  const std::string& flag() const { return args[i]; }
  // The value after the flag, or false: a following "--x" is taken for a forgotten value, not for
  // the value itself.
  bool value(std::string* v) {
    const std::string& a = flag();
    if (i + 1 >= args.size() || (args[i + 1].rfind("--", 0) == 0 && args[i + 1].size() > 2)) {
      *err = a + " needs a value";
      return false;
    }
    *v = args[++i];
    return true;
  }
  bool u64_value(unsigned long long hi, unsigned long long* n) {
    const std::string& a = flag();
    std::string v;
    return value(&v) && parse_u64(a, v, hi, n, err);
  }
  bool double_value(double lo, double hi, double* d) {
    const std::string& a = flag();
    std::string v;
    return value(&v) && parse_double(a, v, lo, hi, d, err);
  }
};

// What the checks after the loop need beyond the config itself.
struct GivenOptions {
  std::vector<std::string> world_only;  // options of synthetic worlds that were given
  bool start = false, odom_noise = false;
};

// An option group's verdict on the current argument.
enum class Parsed { kNotMine, kOk, kError };

Parsed ok_if(bool ok) { return ok ? Parsed::kOk : Parsed::kError; }

Parsed fail_with(std::string* err, const std::string& msg) {
  *err = msg;
  return Parsed::kError;
}

// --help, --list: what to do instead of a run.
Parsed parse_action_option(const std::string& a, SimArgsAction* action) {
  if (a == "--help" || a == "-h") {
    *action = SimArgsAction::kHelp;
  } else if (a == "--list") {
    *action = SimArgsAction::kList;
  } else {
    return Parsed::kNotMine;
  }
  return Parsed::kOk;
}

// --world, --dataset, --log and what a log replay takes beside it.
Parsed parse_source_option(ArgCursor* cur, SimConfig* cfg, GivenOptions* given) {
  const std::string& a = cur->flag();
  unsigned long long n = 0;
  if (a == "--world") return ok_if(cur->value(&cfg->world));
  if (a == "--dataset") return ok_if(cur->value(&cfg->dataset));
  if (a == "--log") return ok_if(cur->value(&cfg->log_path));
  if (a == "--reference") return ok_if(cur->value(&cfg->reference_path));
  if (a == "--map") return ok_if(cur->value(&cfg->map_yaml));
  if (a == "--start") {
    if (!cur->u64_value(100000000ull, &n)) return Parsed::kError;
    cfg->log_start = static_cast<size_t>(n);
    given->start = true;
    return Parsed::kOk;
  }
  if (a == "--max-log-mib") {
    if (!cur->u64_value(1ull << 20, &n)) return Parsed::kError;
    if (n == 0) return fail_with(cur->err, "--max-log-mib: must be at least 1");
    cfg->max_log_bytes = static_cast<std::uint64_t>(n) << 20;
    return Parsed::kOk;
  }
  return Parsed::kNotMine;
}

// The run options of the help text but the transport ones.
Parsed parse_run_option(ArgCursor* cur, SimConfig* cfg) {
  const std::string& a = cur->flag();
  std::string v;
  unsigned long long n = 0;
  if (a == "--localizer") return ok_if(cur->value(&cfg->localizer));
  if (a == "--opt") {
    if (!cur->value(&v)) return Parsed::kError;
    const size_t eq = v.find('=');
    if (eq == std::string::npos || eq == 0) return fail_with(cur->err, "--opt: '" + v + "' is not KEY=VALUE");
    cfg->localizer_options[v.substr(0, eq)] = v.substr(eq + 1);
    return Parsed::kOk;
  }
  if (a == "--seed") {
    if (!cur->u64_value(~0ull, &n)) return Parsed::kError;
    cfg->seed = n;
    return Parsed::kOk;
  }
  if (a == "--steps") {
    if (!cur->u64_value(100000000ull, &n)) return Parsed::kError;
    cfg->steps = static_cast<size_t>(n);
    return Parsed::kOk;
  }
  if (a == "--paced") {
    cfg->paced = true;
    return Parsed::kOk;
  }
  if (a == "--speed") return ok_if(cur->double_value(0.01, 1000, &cfg->pace_speed));
  if (a == "--threads") {
    if (!cur->u64_value(64, &n)) return Parsed::kError;
    if (n == 0) return fail_with(cur->err, "--threads: must be at least 1");
    cfg->threads = static_cast<int>(n);
    return Parsed::kOk;
  }
  if (a == "--deadline-ms") return ok_if(cur->double_value(0, 100000, &cfg->deadline_ms));
  if (a == "--out") return ok_if(cur->value(&cfg->out_dir));
  if (a == "--timing") {
    if (!cur->value(&v)) return Parsed::kError;
    if (v != "wall" && v != "none") return fail_with(cur->err, "--timing: '" + v + "' (expected wall or none)");
    cfg->wall_timing = v == "wall";
    return Parsed::kOk;
  }
  if (a == "--quiet") {
    cfg->progress = false;
    return Parsed::kOk;
  }
  if (a == "--no-pictures") {
    cfg->pictures = false;
    return Parsed::kOk;
  }
  return Parsed::kNotMine;
}

// --transport, --sensor-resolution, --byte-fault-rate: the wire between the sensors and the firmware.
Parsed parse_transport_option(ArgCursor* cur, SimConfig* cfg) {
  const std::string& a = cur->flag();
  std::string v;
  if (a == "--transport") {
    if (!cur->value(&v)) return Parsed::kError;
    if (!parse_transport(v, &cfg->transport.transport)) {
      return fail_with(cur->err, "--transport: '" + v + "' (expected none, can, sick, hokuyo or rplidar)");
    }
    return Parsed::kOk;
  }
  if (a == "--sensor-resolution") {
    if (!cur->value(&v)) return Parsed::kError;
    if (v != "exact" && v != "can" && v != "sick") {
      return fail_with(cur->err, "--sensor-resolution: '" + v + "' (expected exact, can or sick)");
    }
    cfg->transport.resolution = v == "can"    ? SensorResolution::kCan
                                : v == "sick" ? SensorResolution::kSick
                                              : SensorResolution::kExact;
    return Parsed::kOk;
  }
  if (a == "--byte-fault-rate") return ok_if(cur->double_value(0, 1, &cfg->transport.byte_fault_rate));
  if (a == "--laser-model") return ok_if(cur->value(&cfg->transport.laser_model));
  return Parsed::kNotMine;
}

// "A,B,C" → three numbers within [lo, hi] each (the flag named in the error).
bool parse_triple(const std::string& flag, const std::string& v, double lo, double hi, double out[3], std::string* err) {
  std::string rest = v;
  for (int i = 0; i < 3; ++i) {
    const size_t comma = rest.find(',');
    if ((i < 2) != (comma != std::string::npos)) {
      *err = flag + ": '" + v + "' is not A,B,C";
      return false;
    }
    if (!parse_double(flag, rest.substr(0, comma), lo, hi, &out[i], err)) return false;
    rest = comma == std::string::npos ? "" : rest.substr(comma + 1);
  }
  return true;
}

// Issue 60: --hint-at, --hint-offset, --hint-pose, --hint-sigma, --blackbox, --replay-blackbox.
Parsed parse_operator_option(ArgCursor* cur, SimConfig* cfg) {
  const std::string& a = cur->flag();
  std::string v;
  unsigned long long n = 0;
  double t[3] = {0, 0, 0};
  if (a == "--hint-at") {
    if (!cur->u64_value(100000000ull, &n)) return Parsed::kError;
    if (n == 0) return fail_with(cur->err, "--hint-at: the scan index must be at least 1");
    cfg->hint.at_scan = static_cast<size_t>(n);
    return Parsed::kOk;
  }
  if (a == "--hint-offset" || a == "--hint-pose") {
    if (!cur->value(&v) || !parse_triple(a, v, -1e6, 1e6, t, cur->err)) return Parsed::kError;
    cfg->hint.absolute = a == "--hint-pose";
    cfg->hint.pose = fw::Se2d(t[0], t[1], t[2] * 0.017453292519943295);
    return Parsed::kOk;
  }
  if (a == "--hint-sigma") {
    if (!cur->value(&v)) return Parsed::kError;
    const size_t comma = v.find(',');
    if (comma == std::string::npos) return fail_with(cur->err, "--hint-sigma: '" + v + "' is not M,DEG");
    if (!parse_double(a, v.substr(0, comma), 0.001, 65, &cfg->hint.sigma_m, cur->err) ||
        !parse_double(a, v.substr(comma + 1), 0.01, 360, &t[0], cur->err)) {
      return Parsed::kError;
    }
    cfg->hint.sigma_rad = t[0] * 0.017453292519943295;
    return Parsed::kOk;
  }
  if (a == "--blackbox") return ok_if(cur->value(&cfg->blackbox.record_path));
  if (a == "--replay-blackbox") return ok_if(cur->value(&cfg->blackbox.replay_path));
  return Parsed::kNotMine;
}

// Options of synthetic worlds alone: a log brings its own laser, route and map.
Parsed parse_world_only_option(ArgCursor* cur, SimConfig* cfg) {
  const std::string& a = cur->flag();
  unsigned long long n = 0;
  double d = 0;
  if (a == "--people") {
    if (!cur->u64_value(200, &n)) return Parsed::kError;
    cfg->synthetic.people = static_cast<int>(n);
    return Parsed::kOk;
  }
  if (a == "--beams") {
    if (!cur->u64_value(hal::LaserScan::kMaxBeams, &n)) return Parsed::kError;
    if (n < 2) return fail_with(cur->err, "--beams: need at least 2");
    cfg->synthetic.laser.beams = static_cast<int>(n);
    return Parsed::kOk;
  }
  if (a == "--max-range") return ok_if(cur->double_value(0.5, 200, &cfg->synthetic.laser.max_range));
  if (a == "--range-noise") return ok_if(cur->double_value(0, 1, &cfg->synthetic.laser.sigma_range));
  if (a == "--dropout") return ok_if(cur->double_value(0, 1, &cfg->synthetic.laser.dropout_rate));
  if (a == "--scan-period") return ok_if(cur->double_value(0.01, 10, &cfg->synthetic.scan_period_s));
  if (a == "--route-length") return ok_if(cur->double_value(1, 100000, &cfg->synthetic.route.length_m));
  if (a == "--start-node") {
    if (!cur->u64_value(1000000, &n)) return Parsed::kError;
    cfg->synthetic.route.start_node = static_cast<int>(n);
    return Parsed::kOk;
  }
  if (a == "--via-unknown") {
    cfg->synthetic.route.via_unknown = true;
    return Parsed::kOk;
  }
  if (a == "--enter-unknown") {
    cfg->synthetic.route.avoid_unknown = false;
    return Parsed::kOk;
  }
  if (a == "--map-unknown") {
    cfg->raster.erase_unknown_areas = false;
    return Parsed::kOk;
  }
  if (a == "--resolution") {
    if (!cur->double_value(0.01, 1, &d)) return Parsed::kError;
    cfg->raster.resolution = d;
    return Parsed::kOk;
  }
  return Parsed::kNotMine;
}

// --odom-noise T,R: the synthetic odometry's noise, or extra noise on a log's odometry.
Parsed parse_odom_noise(ArgCursor* cur, SimConfig* cfg, GivenOptions* given) {
  const std::string& a = cur->flag();
  std::string v;
  if (!cur->value(&v)) return Parsed::kError;
  const size_t comma = v.find(',');
  if (comma == std::string::npos) {
    return fail_with(cur->err, "--odom-noise: '" + v + "' is not T,R (metres,degrees per scan step)");
  }
  if (!parse_double(a, v.substr(0, comma), 0, 10, &cfg->synthetic.odometry.sigma_trans, cur->err) ||
      !parse_double(a, v.substr(comma + 1), 0, 180, &cfg->synthetic.odometry.sigma_rot_deg, cur->err)) {
    return Parsed::kError;
  }
  cfg->log_odom_sigma_m = cfg->synthetic.odometry.sigma_trans;
  cfg->log_odom_sigma_deg = cfg->synthetic.odometry.sigma_rot_deg;
  given->odom_noise = true;
  return Parsed::kOk;
}

// --kidnap-at N: set for both kinds of source; check_source_kind keeps the one that applies.
Parsed parse_kidnap_at(ArgCursor* cur, SimConfig* cfg) {
  unsigned long long n = 0;
  if (!cur->u64_value(100000000ull, &n)) return Parsed::kError;
  if (n == 0) return fail_with(cur->err, "--kidnap-at: the scan index must be at least 1");
  cfg->synthetic.kidnap_at_scan = static_cast<size_t>(n);
  cfg->log_kidnap_at = static_cast<size_t>(n);
  return Parsed::kOk;
}

// The "synthetic world" options of the help text.
Parsed parse_world_option(ArgCursor* cur, SimConfig* cfg, GivenOptions* given) {
  const std::string& a = cur->flag();
  if (a == "--odom-noise") return parse_odom_noise(cur, cfg, given);
  if (a == "--kidnap-at") return parse_kidnap_at(cur, cfg);
  const Parsed p = parse_world_only_option(cur, cfg);
  if (p != Parsed::kNotMine) given->world_only.push_back(a);
  return p;
}

// Hands the current argument to each option group in turn; one that none takes is an error.
bool parse_one_option(ArgCursor* cur, SimConfig* cfg, SimArgsAction* action, GivenOptions* given) {
  Parsed p = parse_action_option(cur->flag(), action);
  if (p == Parsed::kNotMine) p = parse_source_option(cur, cfg, given);
  if (p == Parsed::kNotMine) p = parse_run_option(cur, cfg);
  if (p == Parsed::kNotMine) p = parse_transport_option(cur, cfg);
  if (p == Parsed::kNotMine) p = parse_operator_option(cur, cfg);
  if (p == Parsed::kNotMine) p = parse_world_option(cur, cfg, given);
  if (p == Parsed::kNotMine) *cur->err = "unknown argument '" + cur->flag() + "' (see --help)";
  return p == Parsed::kOk;
}

// Exactly one source, and the log-only options only with a log.
bool check_source_choice(const SimConfig& cfg, std::string* err) {
  const int sources = !cfg.world.empty() + !cfg.log_path.empty() + !cfg.dataset.empty();
  if (sources == 0 && !cfg.blackbox.replay_path.empty()) {  // a robot's black box: its map is enough
    if (cfg.map_yaml.empty() && cfg.localizer != "odom") {
      *err = "--replay-blackbox without --world/--dataset/--log needs the robot's map (--map IMAGE.mmap or MAP.yaml)";
      return false;
    }
    return true;
  }
  if (sources == 0) {
    *err = "no input: give --world NAME, --dataset NAME or --log FILE (see --help)";
    return false;
  }
  if (sources > 1) {
    *err = "--world, --dataset and --log exclude each other";
    return false;
  }
  if (!cfg.reference_path.empty() && cfg.log_path.empty() && cfg.dataset.empty()) {
    *err = "--reference needs --log";
    return false;
  }
  if (!cfg.map_yaml.empty() && cfg.log_path.empty() && cfg.dataset.empty()) {
    *err = "--map is for --log replays (worlds bring their own map)";
    return false;
  }
  return true;
}

// Options that mean different things for a world and a log: refuse the ones of the other kind and
// switch off what the other kind would have used.
bool check_source_kind(const GivenOptions& given, SimConfig* cfg, std::string* err) {
  const bool log_source = cfg->world.empty();
  if (log_source) {
    if (!given.world_only.empty()) {
      *err = given.world_only.front() + " is an option of synthetic worlds (--world); a log (--log, --dataset) brings " +
             "its own laser, route and map";
      return false;
    }
    cfg->log_odom_noise = given.odom_noise;
    cfg->synthetic.kidnap_at_scan = 0;
  } else {
    if (given.start) {
      *err = "--start is for --log / --dataset replays (a world's route: --start-node)";
      return false;
    }
    cfg->log_kidnap_at = 0;
  }
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
  --transport none|can|sick|hokuyo|rplidar  how scans and odometry reach the firmware: straight
                          into the hal/sim rings (none, default); through our CAN encoder, the hal/sim
                          loopback bus and the firmware's CanNode decoder (can); scans as SICK LMS2xx
                          telegrams on the hal/sim serial port through the firmware's SickLaser driver
                          (sick); as a Hokuyo UTM-30LX's SCIP 2.0 answers through HokuyoLaser (hokuyo)
                          or an RPLIDAR A1's SCAN samples through RplidarLaser (rplidar), after the
                          driver's start-up handshake answered by the simulated device (the firmware
                          sees that unit's geometry: 1081 beams over 270° / 360 beams over 360°)
  --sensor-resolution exact|can|sick  what the simulated sensors report: what a wire carries (can:
                          the default with --transport none, so none and can give the same steps.csv
                          with --timing none; sick: always with --transport sick) or exact floats
  --laser-model NAME      the unit --transport hokuyo|rplidar plays: utm-30lx (default), urg-04lx,
                          ust-10lx; a1 (default), a2, a3, s1. A replay's start-up handshake is
                          answered by it: give the recorded unit's (with --transport)
  --byte-fault-rate P     with a transport but none: drop or bit-flip each frame / telegram / answer with
                          probability P (seeded by --seed); the firmware's decoder drops and counts
                          what it cannot use (summary.json, summary line)
  --hint-at N             at scan N the operator sends a pose hint (SET_POSE_HINT; on the CAN wire with
                          --transport can): the truth moved by --hint-offset DX,DY,DEG (default 0,0,0)
                          or the pose --hint-pose X,Y,DEG, with --hint-sigma M,DEG (default 0.1,3)
  --blackbox FILE         with --transport can|sick|hokuyo|rplidar: the firmware's black box (frames
                          in and out, candump format, hal/can/README.md; a serial laser's bytes as
                          "rx laser HEX" lines, hal/serial/README.md) written to FILE after the run
  --replay-blackbox FILE  feed FILE's received frames (and serial bytes, through the laser's driver:
                          SICK, Hokuyo or RPLIDAR as the bytes tell, or as --transport says) back
                          through the firmware in lockstep and compare the POSE frames with FILE's;
                          exit 0 when identical bit for bit, 1 otherwise. A Hokuyo's / RPLIDAR's
                          start-up handshake, never in a black box, is answered by the simulated
                          UTM-30LX / A1 at the first serial line's time. Give the recording's
                          --world/--dataset and options, or for a robot's black box its --map and
                          localizer options (--opt) alone
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
  ArgCursor cur{args, 0, err};
  GivenOptions given;
  for (; cur.i < args.size(); ++cur.i) {
    if (!parse_one_option(&cur, cfg, action, &given)) return false;
  }
  if (*action != SimArgsAction::kRun) return true;
  return check_source_choice(*cfg, err) && check_source_kind(given, cfg, err);
}

}  // namespace sim
