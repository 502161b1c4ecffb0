// The global maps of the real datasets (../shared/data), built by ray casting the SLAM-corrected
// logs (sim/map/occupancy_builder.h) and cached as ROS maps + compiled map images:
//   <cache>/<dataset>.yaml, .pgm, .png (picture), .mmap (firmware image), .build.txt (parameters)
// <cache> = $MMLFW_MAP_DIR, else <source dir>/build/maps. Default resolutions: 0.05 m for the
// office buildings (intel, fr079, aces, fr101), 0.10 m for mit-killian (250 x 245 m), fr-clinic (440 x 241 m;
// at 5 cm its image would be 212 MB) and the outdoor fr-campus (max usable range 40 m as mit-killian).
// fr101 and fr-campus have only corrected logs: their maps come from those (as the others').
#pragma once

#include <string>
#include <vector>

#include "firmware/base/se2.h"
#include "sim/io/ros_map.h"
#include "sim/map/occupancy_builder.h"

namespace sim {

// Datasets with a global map: intel, fr079, aces, mit-killian, fr-clinic, fr101, fr-campus.
const std::vector<std::string>& global_map_datasets();
double default_map_resolution(const std::string& dataset);
// Builder options used for a dataset (resolution filled in by the caller).
OccupancyBuildOptions global_map_options(const std::string& dataset, double resolution);
// Human-readable provenance: which log and poses the map comes from, and its caveats.
std::string global_map_source(const std::string& dataset);

// Builds the map from the dataset's corrected log (fr-clinic: raw log, see global_map_source).
// `report` (optional) receives notes on how the poses were obtained (fr-clinic: pose-graph fit).
bool build_global_map(const std::string& dataset, double resolution, RosMap* out, std::string* error,
                      OccupancyBuildStats* stats = nullptr, std::string* report = nullptr);

std::string map_cache_dir();
std::string global_map_yaml_path(const std::string& dataset, const std::string& dir = map_cache_dir());
std::string global_map_image_path(const std::string& dataset, const std::string& dir = map_cache_dir());

// Builds the map and writes <dir>/<dataset>.{yaml,pgm,png,mmap,build.txt} (always rebuilds).
bool write_global_map(const std::string& dataset, double resolution, const std::string& dir, RosMap* out,
                      std::string* error, OccupancyBuildStats* stats = nullptr, std::string* report = nullptr);

// Builds (if the cache is missing or was built with other parameters) and writes <dir>/<dataset>.*
// (yaml, pgm, png, mmap, build.txt); then reads the cached map. resolution ≤ 0: the default.
bool ensure_global_map(const std::string& dataset, double resolution, const std::string& dir, RosMap* out,
                       std::string* error, bool* rebuilt = nullptr);

// fr-clinic has no corrected log. Its benchmark relations chain every relation timestamp to the
// next (and the one after) and add 169 loop closures, so a pose graph over the 1316 relation
// scans (robot poses, initialised by chaining the consecutive relations, optimized with
// pose_graph.h) gives a trajectory consistent with the benchmark's ground truth. Returns the
// scan indices (into the raw log) and optimized robot poses; `report` says how well they fit.
// Note: evaluating an estimate against the same relations on THIS trajectory is circular.
bool relation_graph_trajectory(const std::string& dataset, std::vector<std::size_t>* scan_indices,
                               std::vector<fw::Se2d>* robot_poses, std::string* report, std::string* error);
// Same, with the dataset's raw log already read (avoids reading it again).
struct CarmenLog;
bool relation_graph_trajectory(const std::string& dataset, const CarmenLog& raw_log,
                               std::vector<std::size_t>* scan_indices, std::vector<fw::Se2d>* robot_poses,
                               std::string* report, std::string* error);

// Writes a PNG of a ROS map's image (grey levels as in the PGM).
bool write_map_png(const std::string& path, const RosMap& map, std::string* error);

}  // namespace sim
