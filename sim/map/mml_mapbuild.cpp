// mml-mapbuild: global occupancy maps of the real datasets from their SLAM-corrected logs.
//   mml-mapbuild --dataset intel|fr079|aces|mit-killian|fr-clinic|fr101|fr-campus|all [--resolution R] [--out DIR]
// writes DIR/<dataset>.yaml + .pgm (ROS map_server), .png (picture), .mmap (compiled firmware map
// image), .build.txt (parameters). Default DIR: build/maps; default R: 0.05 m (0.10 m mit-killian, fr-clinic).
//   mml-mapbuild --log FILE.clf[.gz] --name NAME [--resolution R] [--max-range M] [--laser-max-range M] [--out DIR]
// builds from any CARMEN log whose scan poses are known (e.g. a corrected log). --max-range: readings
// used up to M m (default 25 m, as the built-in indoor maps); --laser-max-range: the laser's own
// maximum (readings at or beyond it are "no return", not drawn; default: the log's PARAM
// robot_front_laser_max / robot_rear_laser_max, else its largest reading). How many beams that
// leaves out is printed, with a warning when it is more than 5 %.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "sim/io/carmen_log.h"
#include "sim/map/global_maps.h"
#include "sim/map/map_image_writer.h"
#include "sim/common/cli_main.h"

namespace {

const char kUsage[] =
    "usage: mml-mapbuild --dataset intel|fr079|aces|mit-killian|fr-clinic|fr101|fr-campus|all [--resolution R] [--out DIR]\n"
    "       mml-mapbuild --log FILE --name NAME [--resolution R] [--max-range M] [--laser-max-range M] [--out DIR]\n"
    "Writes DIR/NAME.yaml + .pgm (ROS map_server), .png, .mmap (the firmware's map image, for mmlfw and\n"
    "mml-sim --map; add pRANSAM's relation table with 'mml-mapc --relation-table DIR/NAME.yaml OUT.mmap').\n"
    "  --dataset NAME        a built-in dataset of ../shared/data (MMLFW_DATA_DIR), or all\n"
    "  --log FILE            a CARMEN log whose scan poses are correct (a corrected log, e.g. GMapping's);\n"
    "                        needs --name\n"
    "  --name NAME           file name of the map built from --log\n"
    "  --resolution R        cell size in m (default 0.05; built-in: 0.10 for mit-killian, fr-clinic, fr-campus)\n"
    "  --max-range M         --log: readings used up to M m, longer ones only clear free space (default 25,\n"
    "                        as the built-in indoor maps; 40 for mit-killian and fr-campus)\n"
    "  --laser-max-range M   --log: the laser's maximum range; readings at or beyond it are 'no return' and\n"
    "                        not drawn (default: the log's PARAM robot_front_laser_max / robot_rear_laser_max,\n"
    "                        else its largest reading)\n"
    "  --out DIR             output directory (default build/maps)\n"
    "  --help                this text\n";

int usage_error(const std::string& msg) {
  std::fprintf(stderr, "mml-mapbuild: %s\n%s", msg.c_str(), kUsage);
  return 2;
}

// A number > 0 (finite), or a message naming the option and the value.
bool parse_positive(const std::string& opt, const char* v, double* out, std::string* err) {
  char* end = nullptr;
  errno = 0;
  const double d = std::strtod(v, &end);
  if (*v == '\0' || *end != '\0' || errno != 0 || !std::isfinite(d) || !(d > 0.0)) {
    *err = opt + ": '" + v + "' is not a number > 0";
    return false;
  }
  *out = d;
  return true;
}

bool write_all(const std::string& dir, const std::string& name, const sim::RosMap& map, std::string* err) {
  // The image first: a map that does not compile leaves no files at all (each file is written
  // through a temporary renamed over it, so none is left half-written either).
  std::vector<std::uint8_t> image;
  return sim::compile_map_image(map, &image, err) && sim::write_ros_map(dir + "/" + name + ".yaml", map, err) &&
         sim::write_map_png(dir + "/" + name + ".png", map, err) &&
         sim::write_file_bytes(dir + "/" + name + ".mmap", image, err);
}

void print_stats(const std::string& name, const sim::RosMap& m, const sim::OccupancyBuildStats& s, double secs) {
  std::printf("%s: %dx%d cells at %.3g m (%.1f x %.1f m), origin (%.2f, %.2f); %zu scans, %zu beams "
              "(%zu hits, %zu no-return, %zu truncated, %zu invalid); cells occupied %zu, free %zu, unknown %zu; %.2f s\n",
              name.c_str(), m.width, m.height, m.resolution, m.width * m.resolution, m.height * m.resolution,
              m.origin[0], m.origin[1], s.scans, s.beams, s.hits, s.no_return, s.truncated, s.invalid, s.occupied,
              s.free, s.unknown, secs);
}

// The command line: a built-in dataset (or all), or a log with known poses and the map's name.
struct MapBuildArgs {
  std::string dataset, log_path, name, out = sim::map_cache_dir();
  double resolution = 0.0, max_range = 0.0, laser_max = 0.0;  // 0: not given
};

// Options given together that do not go together. Set: the exit code of the error reported.
std::optional<int> check_combination(const MapBuildArgs& o) {
  if (!o.dataset.empty() && !o.log_path.empty()) return usage_error("--dataset and --log exclude each other");
  if (o.dataset.empty() && o.log_path.empty()) return usage_error("nothing to build: give --dataset NAME or --log FILE --name NAME");
  if (!o.log_path.empty() && o.name.empty()) {
    return usage_error("--log needs --name NAME (the map's file name: DIR/NAME.yaml, .pgm, .png, .mmap)");
  }
  if (!o.dataset.empty() && !o.name.empty()) return usage_error("--name is for --log (a dataset's map is named after it)");
  if (!o.dataset.empty() && (o.max_range > 0.0 || o.laser_max > 0.0)) {
    return usage_error(std::string(o.max_range > 0.0 ? "--max-range" : "--laser-max-range") +
                       " is for --log (the built-in maps use their own: 25 m, 40 m for mit-killian and fr-campus)");
  }
  return std::nullopt;
}

// Reads the command line into *o. Set: the run ends here with that exit code (--help, or an error
// already reported).
std::optional<int> parse_args(int argc, char** argv, MapBuildArgs* o) {
  std::string err;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    const bool takes_value = a == "--dataset" || a == "--resolution" || a == "--out" || a == "--log" ||
                             a == "--name" || a == "--max-range" || a == "--laser-max-range";
    if (!takes_value) return usage_error("unknown argument '" + a + "'");
    if (i + 1 >= argc) return usage_error(a + " needs a value");
    const char* v = argv[++i];
    if (a == "--dataset") {
      o->dataset = v;
    } else if (a == "--resolution") {
      if (!parse_positive(a, v, &o->resolution, &err)) return usage_error(err);
    } else if (a == "--out") {
      o->out = v;
    } else if (a == "--log") {
      o->log_path = v;
    } else if (a == "--name") {
      o->name = v;
      if (o->name.empty() || o->name.find('/') != std::string::npos) {
        return usage_error("--name: '" + o->name + "' is not a file name (no '/'; the directory is --out)");
      }
    } else if (a == "--max-range") {
      if (!parse_positive(a, v, &o->max_range, &err)) return usage_error(err);
    } else if (a == "--laser-max-range") {
      if (!parse_positive(a, v, &o->laser_max, &err)) return usage_error(err);
    }
  }
  return check_combination(*o);
}

// Where the laser's maximum range comes from, for the messages.
std::string laser_max_source(const sim::CarmenLog& log, double laser_max) {
  std::string max_src = "--laser-max-range";
  if (laser_max <= 0.0) {
    max_src = "the largest reading of the log (no PARAM robot_front_laser_max / robot_rear_laser_max)";
    for (const auto& kv : log.params) {
      if (kv.first == "robot_front_laser_max" || kv.first == "robot_rear_laser_max") max_src = "PARAM " + kv.first;
    }
  }
  return max_src;
}

// How the beams stand to the laser's maximum range.
struct BeamCensus {
  std::size_t beams = 0, at_max = 0, beyond = 0;
  // Beyond the maximum but below the largest reading: real measurements (the largest reading
  // itself is often the laser's no-echo code, 81.91 m for a SICK LMS).
  std::size_t beyond_below_largest = 0;
  float max_seen = 0.0f;  // the largest reading
};

BeamCensus count_beams(const sim::CarmenLog& log) {
  BeamCensus c;
  for (const sim::CarmenScan& s : log.scans) {
    for (float r : s.ranges) {
      ++c.beams;
      if (std::isfinite(r)) c.max_seen = std::max(c.max_seen, r);
      if (s.max_range > 0.0f && r >= s.max_range - 0.01f) ++(r > s.max_range + 0.01f ? c.beyond : c.at_max);
    }
  }
  for (const sim::CarmenScan& s : log.scans) {
    for (float r : s.ranges) {
      if (s.max_range > 0.0f && r > s.max_range + 0.01f && r < c.max_seen - 0.01f) ++c.beyond_below_largest;
    }
  }
  return c;
}

// Says how many beams the laser's maximum range leaves out, with a warning when that may lose real
// measurements.
void report_beam_census(const MapBuildArgs& o, double lmax, const std::string& max_src, const BeamCensus& c) {
  const double pct = 100.0 / static_cast<double>(std::max<std::size_t>(c.beams, 1));
  std::printf("%s: laser maximum range %.2f m (from %s): of %zu beams, %zu (%.1f %%) read the maximum (no echo) and "
              "%zu (%.1f %%) beyond it; both are 'no return' and not drawn; largest reading %.2f m\n",
              o.name.c_str(), lmax, max_src.c_str(), c.beams, c.at_max, pct * static_cast<double>(c.at_max), c.beyond,
              pct * static_cast<double>(c.beyond), static_cast<double>(c.max_seen));
  if (c.beyond > 0 && c.beyond_below_largest * 100 <= c.beyond) {
    std::printf("%s: %zu of the %zu beams beyond it read %.2f m, the laser's no-echo value: next to nothing is lost\n",
                o.name.c_str(), c.beyond - c.beyond_below_largest, c.beyond, static_cast<double>(c.max_seen));
  } else if (c.beyond > 0) {
    std::fprintf(stderr,
                 "mml-mapbuild: warning: %s: %zu of %zu beams (%.1f %%) read beyond the laser maximum range %.2f m "
                 "(%s), up to %.2f m, and are left out of the map; if the laser measures that far, give "
                 "--laser-max-range %.2f\n",
                 o.log_path.c_str(), c.beyond, c.beams, pct * static_cast<double>(c.beyond), lmax, max_src.c_str(),
                 static_cast<double>(c.max_seen), std::ceil((static_cast<double>(c.max_seen) + 0.02) * 100.0) / 100.0);
  } else if (pct * static_cast<double>(c.at_max) > 5.0) {
    std::fprintf(stderr,
                 "mml-mapbuild: warning: %s: %zu of %zu beams (%.1f %%) read the laser maximum range %.2f m (%s) and "
                 "are left out of the map as 'no echo'; if that is not the laser's no-echo value, give "
                 "--laser-max-range M\n",
                 o.log_path.c_str(), c.at_max, c.beams, pct * static_cast<double>(c.at_max), lmax, max_src.c_str());
  }
}

// The occupancy grid of the log's scans at their poses, written as NAME.{yaml,pgm,png,mmap}: 0, or
// the exit code of the failure reported.
int build_and_write(const MapBuildArgs& o, const sim::CarmenLog& log, std::chrono::steady_clock::time_point t0) {
  std::string err;
  std::vector<sim::PosedScan> scans;
  for (const sim::CarmenScan& s : log.scans) {
    scans.push_back({s.pose, s.angle_min, s.angle_increment, s.max_range, s.ranges.data(), s.ranges.size()});
  }
  // Default options of the built-in maps (sim/map/global_maps.cpp: 25 m indoors).
  sim::OccupancyBuildOptions opt = sim::global_map_options("", o.resolution > 0.0 ? o.resolution : 0.05);
  if (o.max_range > 0.0) opt.max_usable_range = o.max_range;
  std::printf("%s: resolution %.3g m, readings used up to %.1f m%s\n", o.name.c_str(), opt.resolution,
              opt.max_usable_range, o.max_range > 0.0 ? " (--max-range)" : " (default, as the built-in indoor maps)");
  sim::OccupancyGrid grid;
  sim::OccupancyBuildStats stats;
  if (!sim::build_occupancy_grid(scans, opt, &grid, &stats, &err)) {
    std::fprintf(stderr, "mml-mapbuild: %s: %s\n", o.log_path.c_str(), err.c_str());
    return 1;
  }
  const sim::RosMap map = sim::grid_to_ros_map(grid, o.name + ".pgm");
  if (!write_all(o.out, o.name, map, &err)) {
    std::fprintf(stderr, "mml-mapbuild: %s\n", err.c_str());
    return 1;
  }
  print_stats(o.name, map, stats, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  std::printf("  wrote %s/%s.{yaml,pgm,png,mmap}\n", o.out.c_str(), o.name.c_str());
  return 0;
}

// --log: the map of a log whose scan poses are correct.
int build_from_log(const MapBuildArgs& o) {
  const auto t0 = std::chrono::steady_clock::now();
  std::string err;
  sim::CarmenLog log;
  if (!sim::read_carmen_log(o.log_path, sim::CarmenReadOptions{}, &log, &err)) {
    std::fprintf(stderr, "mml-mapbuild: %s\n", err.c_str());
    return 1;
  }
  if (log.scans.empty()) {
    std::fprintf(stderr, "mml-mapbuild: %s: no laser scans in the log\n", o.log_path.c_str());
    return 1;
  }
  // The laser's maximum: readings at or beyond it are "no return" (occupancy_builder.h) and are
  // not drawn. Say where it comes from and how many beams it leaves out.
  const std::string max_src = laser_max_source(log, o.laser_max);
  if (o.laser_max > 0.0) {
    for (sim::CarmenScan& s : log.scans) s.max_range = static_cast<float>(o.laser_max);
  }
  report_beam_census(o, log.scans.front().max_range, max_src, count_beams(log));
  return build_and_write(o, log, t0);
}

// --dataset: the built-in maps; one that fails does not stop the others.
int build_datasets(const MapBuildArgs& o) {
  std::vector<std::string> list;
  if (o.dataset == "all") {
    list = sim::global_map_datasets();
  } else {
    list = {o.dataset};
  }
  int rc = 0;
  for (const std::string& ds : list) {
    const auto t0 = std::chrono::steady_clock::now();
    const double r = o.resolution > 0.0 ? o.resolution : sim::default_map_resolution(ds);
    sim::RosMap map;
    sim::OccupancyBuildStats stats;
    std::string err, report;
    if (!sim::write_global_map(ds, r, o.out, &map, &err, &stats, &report)) {
      std::fprintf(stderr, "mml-mapbuild: %s: %s\n", ds.c_str(), err.c_str());
      rc = 1;
      continue;
    }
    print_stats(ds, map, stats, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    if (!report.empty()) std::printf("  %s\n", report.c_str());
    std::printf("  source: %s\n  wrote %s/%s.{yaml,pgm,png,mmap}\n", sim::global_map_source(ds).c_str(), o.out.c_str(),
                ds.c_str());
  }
  return rc;
}

}  // namespace

static int run_main(int argc, char** argv) {
  MapBuildArgs o;
  if (const std::optional<int> exit_code = parse_args(argc, argv, &o)) return *exit_code;
  std::error_code ec;
  std::filesystem::create_directories(o.out, ec);
  if (ec) {
    std::fprintf(stderr, "mml-mapbuild: %s: %s\n", o.out.c_str(), ec.message().c_str());
    return 1;
  }
  return o.log_path.empty() ? build_datasets(o) : build_from_log(o);
}

int main(int argc, char** argv) {
  return sim::guarded_main("mml-mapbuild", [&] { return run_main(argc, argv); });
}
