// mml-mapbuild: global occupancy maps of the real datasets from their SLAM-corrected logs.
//   mml-mapbuild --dataset intel|fr079|aces|mit-killian|fr-clinic|all [--resolution R] [--out DIR]
// writes DIR/<dataset>.yaml + .pgm (ROS map_server), .png (picture), .mmap (compiled firmware map
// image), .build.txt (parameters). Default DIR: build/maps; default R: 0.05 m (0.10 m mit-killian, fr-clinic).
//   mml-mapbuild --log FILE.clf[.gz] --name NAME [--resolution R] [--max-range M] [--out DIR]
// builds from any CARMEN log whose scan poses are known (e.g. a corrected log).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "sim/io/carmen_log.h"
#include "sim/map/global_maps.h"
#include "sim/map/map_image_writer.h"
#include "sim/common/cli_main.h"

namespace {

int usage() {
  std::fprintf(stderr,
               "usage: mml-mapbuild --dataset intel|fr079|aces|mit-killian|fr-clinic|all [--resolution R] [--out DIR]\n"
               "       mml-mapbuild --log FILE --name NAME [--resolution R] [--max-range M] [--out DIR]\n");
  return 2;
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

}  // namespace

static int run_main(int argc, char** argv) {
  std::string dataset, log_path, name, out = sim::map_cache_dir();
  double resolution = 0.0, max_range = 0.0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* { return i + 1 < argc ? argv[++i] : nullptr; };
    const char* v = nullptr;
    if (a == "--dataset" && (v = next())) {
      dataset = v;
    } else if (a == "--resolution" && (v = next())) {
      resolution = std::atof(v);
      if (!(resolution > 0.0)) {
        std::fprintf(stderr, "mml-mapbuild: --resolution must be > 0 (got '%s')\n", v);
        return 2;
      }
    } else if (a == "--out" && (v = next())) {
      out = v;
    } else if (a == "--log" && (v = next())) {
      log_path = v;
    } else if (a == "--name" && (v = next())) {
      name = v;
    } else if (a == "--max-range" && (v = next())) {
      max_range = std::atof(v);
    } else {
      return usage();
    }
  }
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) {
    std::fprintf(stderr, "mml-mapbuild: %s: %s\n", out.c_str(), ec.message().c_str());
    return 1;
  }
  std::string err;
  if (!log_path.empty()) {
    if (name.empty()) return usage();
    const auto t0 = std::chrono::steady_clock::now();
    sim::CarmenLog log;
    if (!sim::read_carmen_log(log_path, sim::CarmenReadOptions{}, &log, &err)) {
      std::fprintf(stderr, "mml-mapbuild: %s\n", err.c_str());
      return 1;
    }
    std::vector<sim::PosedScan> scans;
    for (const sim::CarmenScan& s : log.scans) {
      scans.push_back({s.pose, s.angle_min, s.angle_increment, s.max_range, s.ranges.data(), s.ranges.size()});
    }
    sim::OccupancyBuildOptions o;
    o.resolution = resolution > 0.0 ? resolution : 0.05;
    if (max_range > 0.0) o.max_usable_range = max_range;
    sim::OccupancyGrid grid;
    sim::OccupancyBuildStats stats;
    if (!sim::build_occupancy_grid(scans, o, &grid, &stats, &err)) {
      std::fprintf(stderr, "mml-mapbuild: %s: %s\n", log_path.c_str(), err.c_str());
      return 1;
    }
    const sim::RosMap map = sim::grid_to_ros_map(grid, name + ".pgm");
    if (!write_all(out, name, map, &err)) {
      std::fprintf(stderr, "mml-mapbuild: %s\n", err.c_str());
      return 1;
    }
    print_stats(name, map, stats, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    return 0;
  }
  if (dataset.empty()) return usage();
  std::vector<std::string> list;
  if (dataset == "all") {
    list = sim::global_map_datasets();
  } else {
    list = {dataset};
  }
  int rc = 0;
  for (const std::string& ds : list) {
    const auto t0 = std::chrono::steady_clock::now();
    const double r = resolution > 0.0 ? resolution : sim::default_map_resolution(ds);
    sim::RosMap map;
    sim::OccupancyBuildStats stats;
    std::string report;
    if (!sim::write_global_map(ds, r, out, &map, &err, &stats, &report)) {
      std::fprintf(stderr, "mml-mapbuild: %s: %s\n", ds.c_str(), err.c_str());
      rc = 1;
      continue;
    }
    print_stats(ds, map, stats, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    if (!report.empty()) std::printf("  %s\n", report.c_str());
    std::printf("  source: %s\n  wrote %s/%s.{yaml,pgm,png,mmap}\n", sim::global_map_source(ds).c_str(), out.c_str(),
                ds.c_str());
  }
  return rc;
}

int main(int argc, char** argv) {
  return sim::guarded_main("mml-mapbuild", [&] { return run_main(argc, argv); });
}
