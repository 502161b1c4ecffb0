#include "sim/map/global_maps.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "sim/io/carmen_log.h"
#include "sim/io/datasets.h"
#include "sim/map/map_image_writer.h"
#include "sim/map/png_writer.h"

#ifndef MMLFW_SOURCE_DIR
#define MMLFW_SOURCE_DIR "."
#endif

namespace sim {
namespace {

bool fail(std::string* error, const std::string& msg) {
  if (error != nullptr) *error = msg;
  return false;
}

bool known(const std::string& ds) {
  for (const std::string& d : global_map_datasets()) {
    if (d == ds) return true;
  }
  return false;
}

std::string build_signature(const std::string& ds, const OccupancyBuildOptions& o) {
  std::ostringstream s;
  s.precision(17);
  s << "mmlfw global map v1 dataset=" << ds << " resolution=" << o.resolution << " max_usable_range="
    << o.max_usable_range << " free_on_no_return=" << o.free_on_no_return << " margin=" << o.margin
    << " l_occ=" << o.l_occ << " l_free=" << o.l_free << " occupied_logodds=" << o.occupied_logodds
    << " beam_stride=" << o.beam_stride << " source=" << global_map_source(ds);
  return s.str();
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

const std::vector<std::string>& global_map_datasets() {
  static const std::vector<std::string> k = {"intel", "fr079", "aces", "mit-killian", "fr-clinic"};
  return k;
}

double default_map_resolution(const std::string& dataset) { return dataset == "mit-killian" ? 0.10 : 0.05; }

OccupancyBuildOptions global_map_options(const std::string& dataset, double resolution) {
  OccupancyBuildOptions o;
  o.resolution = resolution;
  // Indoor office logs: the far returns are few and noisy (and 81.8 m means "no return");
  // MIT Killian Court is a large open courtyard with long corridors.
  o.max_usable_range = dataset == "mit-killian" ? 40.0 : 25.0;
  return o;
}

std::string global_map_source(const std::string& dataset) {
  if (dataset == "fr-clinic") {
    return "fr-clinic/fr-clinic_robotlaser.clf.gz laser poses (raw odometry: no corrected log exists)";
  }
  const Dataset* d = find_dataset(dataset);
  if (d == nullptr || d->corrected_log.empty()) return "";
  return d->corrected_log + " FLASER poses (GMapping-corrected)";
}

bool build_global_map(const std::string& dataset, double resolution, RosMap* out, std::string* error,
                      OccupancyBuildStats* stats) {
  if (!known(dataset)) {
    return fail(error, "unknown dataset '" + dataset + "' (known: intel, fr079, aces, mit-killian, fr-clinic)");
  }
  const Dataset* d = find_dataset(dataset);
  if (d == nullptr) return fail(error, "dataset '" + dataset + "' missing from sim/io/datasets.h");
  const std::string log_path = data_path(dataset == "fr-clinic" ? d->raw_log : d->corrected_log);
  if (!std::filesystem::exists(log_path)) {
    return fail(error, "dataset '" + dataset + "': log '" + log_path + "' not found (MMLFW_DATA_DIR=" + data_dir() + ")");
  }
  CarmenLog log;
  if (!read_carmen_log(log_path, CarmenReadOptions{}, &log, error)) return false;
  std::vector<PosedScan> scans;
  scans.reserve(log.scans.size());
  for (const CarmenScan& s : log.scans) {
    PosedScan p;
    p.pose = s.pose;
    p.angle_min = s.angle_min;
    p.angle_increment = s.angle_increment;
    p.max_range = s.max_range;
    p.ranges = s.ranges.data();
    p.count = s.ranges.size();
    scans.push_back(p);
  }
  OccupancyGrid grid;
  if (!build_occupancy_grid(scans, global_map_options(dataset, resolution), &grid, stats, error)) {
    if (error != nullptr) *error = log_path + ": " + *error;
    return false;
  }
  *out = grid_to_ros_map(grid, dataset + ".pgm");
  return true;
}

std::string map_cache_dir() {
  const char* env = std::getenv("MMLFW_MAP_DIR");
  if (env != nullptr && *env != '\0') return env;
  return std::string(MMLFW_SOURCE_DIR) + "/build/maps";
}

std::string global_map_yaml_path(const std::string& dataset, const std::string& dir) {
  return dir + "/" + dataset + ".yaml";
}
std::string global_map_image_path(const std::string& dataset, const std::string& dir) {
  return dir + "/" + dataset + ".mmap";
}

bool write_map_png(const std::string& path, const RosMap& map, std::string* error) {
  std::vector<std::uint8_t> px(map.pixels.size());
  const int maxval = map.maxval > 0 ? map.maxval : 255;
  for (std::size_t i = 0; i < px.size(); ++i) px[i] = static_cast<std::uint8_t>(map.pixels[i] * 255 / maxval);
  return write_png(path, map.width, map.height, 1, px, error);
}

bool ensure_global_map(const std::string& dataset, double resolution, const std::string& dir, RosMap* out,
                       std::string* error, bool* rebuilt) {
  if (resolution <= 0.0) resolution = default_map_resolution(dataset);
  if (rebuilt != nullptr) *rebuilt = false;
  if (!known(dataset)) {
    return fail(error, "unknown dataset '" + dataset + "' (known: intel, fr079, aces, mit-killian, fr-clinic)");
  }
  const std::string yaml = global_map_yaml_path(dataset, dir);
  const std::string sig_path = dir + "/" + dataset + ".build.txt";
  const std::string sig = build_signature(dataset, global_map_options(dataset, resolution));
  std::error_code ec;
  if (std::filesystem::exists(yaml) && std::filesystem::exists(global_map_image_path(dataset, dir)) &&
      read_text(sig_path) == sig + "\n") {
    if (read_ros_map(yaml, out, error)) return true;
    // Unreadable cache: rebuild below.
  }
  std::filesystem::create_directories(dir, ec);
  if (ec) return fail(error, dir + ": cannot create directory: " + ec.message());
  RosMap map;
  if (!build_global_map(dataset, resolution, &map, error)) return false;
  std::vector<std::uint8_t> image;
  if (!write_ros_map(yaml, map, error) || !write_map_png(dir + "/" + dataset + ".png", map, error) ||
      !compile_map_image(map, &image, error) || !write_file_bytes(global_map_image_path(dataset, dir), image, error)) {
    return false;
  }
  {
    std::ofstream s(sig_path, std::ios::trunc);
    s << sig << "\n";
    if (!s) return fail(error, sig_path + ": write failed");
  }
  if (rebuilt != nullptr) *rebuilt = true;
  return read_ros_map(yaml, out, error);
}

}  // namespace sim
