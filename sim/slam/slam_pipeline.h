// Host side of AntSLAM (issue 12): raw CARMEN log → RBSM scan-matching odometry (the existing
// front end, sim/eval/rbsm) → fw::antslam::AntSlam (fragments, edges, pRANSAM loop closing, ant
// colony or Levenberg–Marquardt) → corrected pose per scan. Also writes the outputs of mml-slam:
// trajectory (sim/io relations format, what `mml-carmen eval` scores), ROS map_server map and an
// SVG picture of fragments, edges and closed loops. Shared by mml-slam, bench_slam and the data test.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "firmware/antslam/antslam.h"
#include "sim/eval/rbsm/rbsm_eval_lib.h"
#include "sim/io/carmen_log.h"
#include "sim/io/relations.h"

namespace sim {

struct SlamConfig {
  MatcherConfig front = default_matcher_config();  // RBSM front end
  // RBSM's poses fused with PL-ICP's laser-to-laser increments (fw::IncrementFusion, front.fusion;
  // an extension, issue 15) and smoothed backwards when front.fusion_smooth (the default) before the
  // back end; false = RBSM alone (the dissertation's front end).
  // On by default: better AntSLAM maps on all five logs of bench_slam (README, AntSLAM section).
  bool fuse_front = true;
  fw::antslam::AntSlamOptions slam = fw::antslam::default_antslam_options();
  int workers = 1;          // >1: pRANSAM and the ants over a fw::WorkerPool (results unchanged)
  std::size_t max_scans = 0;  // 0 = whole log
  // Called now and then with (scans done, scans total, phase) for a progress line.
  std::function<void(std::size_t, std::size_t, const char*)> progress;
};

struct SlamFragmentInfo {
  fw::Se2d pose;
  std::vector<fw::Point2f> points;  // fragment frame
  std::vector<fw::antslam::Border> borders;  // fragment frame (Sec. 3.4; empty with traversal off)
  std::vector<fw::Point2f> hull;             // fragment frame, counter-clockwise
};
struct SlamEdgeInfo {
  std::uint32_t from = 0, to = 0;
  bool closure = false, frozen = false;
};

struct SlamRun {
  std::vector<fw::Se2d> frontend;  // RBSM poses (one per scan)
  std::vector<fw::Se2d> poses;     // AntSLAM corrected (one per scan)
  // With AntSlamOptions::final_refinement: the poses before it (Alg. 3 as published: loops
  // corrected and frozen, nothing after); empty without it (then `poses` are those).
  std::vector<fw::Se2d> alg3_poses;
  std::vector<SlamFragmentInfo> fragments;
  std::vector<SlamEdgeInfo> edges;
  std::vector<fw::antslam::ClosureRecord> closures;
  fw::antslam::AntSlamStats stats;
  double frontend_s = 0, backend_s = 0;  // wall time
  double optimizer_ms = 0, matcher_ms = 0;
};

// Runs the whole pipeline over the first config.max_scans scans of `log`.
bool run_slam(const CarmenLog& log, const SlamConfig& config, SlamRun* out, std::string* error);
// Only the back end over given front-end poses (e.g. to compare ACO and LM on the same front end).
bool run_slam_backend(const CarmenLog& log, const std::vector<fw::Se2d>& frontend, const SlamConfig& config,
                      SlamRun* out, std::string* error);

// The relations a data set is scored with: its relation file, except mit-killian, whose relation
// timestamps cannot be looked up in the reconstructed log (synthetic timestamps,
// ../shared/data/README.md): there each GMapping-corrected pose the data set ships (every ~9th
// scan) is related to the next one.
bool slam_dataset_relations(const CarmenLog& log, const EvalDataset& dataset, std::vector<Relation>* out,
                            std::string* error);

// Outputs.
bool write_slam_map(const CarmenLog& log, const std::vector<fw::Se2d>& poses, double resolution, double max_range,
                    const std::string& yaml_path, std::string* error);
bool write_slam_svg(const SlamRun& run, const std::string& title, const std::string& path, std::string* error);

}  // namespace sim
