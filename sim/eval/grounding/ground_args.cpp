#include "sim/eval/grounding/ground_args.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "sim/common/stopwatch.h"
#include "sim/map/global_maps.h"

namespace sim::ground {

const char* const kGroundUsage =
    "usage: mml-ground [options]\n"
    "Measures the odometry error (per metre, per radian) and the scan-to-map residuals on the real logs\n"
    "of ../shared/data against their corrected reference, and the same on simulated runs of every\n"
    "odometry and sensor profile (sim/world), with one estimator; writes ground.json, ground.md and\n"
    "ground.svg and a verdict per profile (the real logs it resembles, or none).\n"
    "  --out DIR        output folder (default build/bench)\n"
    "  --logs A,B,...   real datasets (default: intel,fr079,aces,fr-clinic,mit-killian,fr101,fr-campus)\n"
    "  --no-real        profiles only      --no-sim   real logs only\n"
    "  --seeds N        synthetic runs per odometry profile (default 5, 1..50)\n"
    "  --scans N        scans sampled per log / sensor for the residuals (default 150, 1..100000)\n"
    "  --window M       short window (default 1 m)   --long-window M  (default 5 m)\n"
    "  --world NAME     built-in world of the simulated runs (default large-office)\n"
    "  --quiet          no progress lines\n"
    "  -h, --help       this text\n"
    "Data: MMLFW_DATA_DIR (default <source>/../shared/data); maps cached in MMLFW_MAP_DIR (default build/maps).\n"
    "Without the data the real-log part is skipped with a note and the exit status is 0.\n";

namespace {

bool number(const std::string& flag, const std::string& v, double lo, double hi, double* out, std::string* err) {
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (v.empty() || end == nullptr || *end != '\0' || !(x >= lo && x <= hi)) {
    char range[64];
    std::snprintf(range, sizeof(range), "[%g, %g]", lo, hi);
    *err = flag + " '" + v + "': expected a number in " + range;
    return false;
  }
  *out = x;
  return true;
}

bool known_log(const std::string& name) {
  for (const std::string& d : residual_datasets()) {
    if (d == name) return true;
  }
  return false;
}

bool parse_logs(const std::string& v, GroundOptions* opt, std::string* err) {
  std::size_t start = 0;
  while (start <= v.size()) {
    const std::size_t comma = v.find(',', start);
    const std::string name = v.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (!known_log(name)) {
      *err = "--logs: unknown dataset '" + name + "' (known: intel, fr079, aces, fr-clinic, mit-killian, fr101, fr-campus)";
      return false;
    }
    opt->logs.push_back(name);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return true;
}

}  // namespace

bool parse_ground_args(const std::vector<std::string>& args, GroundArgs* out, std::string* err) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](std::string* v) {
      if (i + 1 >= args.size()) {
        *err = a + ": missing value";
        return false;
      }
      *v = args[++i];
      return true;
    };
    std::string v;
    double x = 0;
    if (a == "-h" || a == "--help") {
      out->help = true;
    } else if (a == "--no-real") {
      out->opt.real = false;
    } else if (a == "--no-sim") {
      out->opt.simulated = false;
    } else if (a == "--quiet") {
      out->opt.progress = false;
    } else if (a == "--out") {
      if (!value(&out->out_dir)) return false;
    } else if (a == "--logs") {
      if (!value(&v) || !parse_logs(v, &out->opt, err)) return false;
    } else if (a == "--world") {
      if (!value(&out->opt.world)) return false;
    } else if (a == "--seeds") {
      if (!value(&v) || !number(a, v, 1, 50, &x, err)) return false;
      out->opt.sim_seeds = static_cast<int>(x);
    } else if (a == "--scans") {
      if (!value(&v) || !number(a, v, 1, 100000, &x, err)) return false;
      out->opt.residual_scans = static_cast<std::size_t>(x);
    } else if (a == "--window") {
      if (!value(&v) || !number(a, v, 0.1, 100, &out->opt.short_window_m, err)) return false;
    } else if (a == "--long-window") {
      if (!value(&v) || !number(a, v, 0.1, 1000, &out->opt.long_window_m, err)) return false;
    } else {
      *err = "unknown argument '" + a + "' (see --help)";
      return false;
    }
  }
  return true;
}

int run_ground(const GroundArgs& a, const char* tool) {
  const auto t0 = std::chrono::steady_clock::now();
  const GroundReport r = run_grounding(a.opt);
  std::error_code ec;
  std::filesystem::create_directories(a.out_dir, ec);
  BenchJson json;
  add_json(r, &json);
  json.add("ground_seconds", seconds_since(t0));
  std::string err;
  const std::string md = markdown(r);
  std::ofstream(a.out_dir + "/ground.md") << md;
  if (!json.write(a.out_dir + "/ground.json") || !write_svg(r, a.out_dir + "/ground.svg", &err)) {
    std::fprintf(stderr, "%s: %s\n", tool, err.empty() ? "cannot write the outputs" : err.c_str());
    return 1;
  }
  if (!r.data_present) {
    std::fprintf(stderr, "%s: SKIP real logs: no data in %s (set MMLFW_DATA_DIR); profiles measured only\n", tool,
                 r.data_dir.c_str());
  }
  std::printf("%s: wrote %s/ground.json, ground.md, ground.svg\n", tool, a.out_dir.c_str());
  return 0;
}

}  // namespace sim::ground
