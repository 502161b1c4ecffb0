// Global maps of the real datasets (needs ../shared/data; skipped when absent).
#include "sim/map/global_maps.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>

#include "firmware/base/arena.h"
#include "firmware/map/map_image.h"
#include "sim/io/carmen_log.h"
#include "sim/io/datasets.h"
#include "sim/io/relations.h"
#include "sim/map/map_image_writer.h"

namespace sim {
namespace {

bool have_data(const std::string& rel) { return std::filesystem::exists(data_path(rel)); }

// Builds intel at 5 cm from its corrected log, checks the size of the building, that the corrected
// scans agree with the map (their end points lie on occupied cells), and that the firmware loads
// the compiled image.
TEST(GlobalMapsDataTest, IntelMapIsConsistentWithItsScans) {
  const Dataset* d = find_dataset("intel");
  ASSERT_NE(d, nullptr);
  if (!have_data(d->corrected_log)) GTEST_SKIP() << "data not found: " << data_path(d->corrected_log);
  const auto t0 = std::chrono::steady_clock::now();
  RosMap map;
  OccupancyBuildStats st;
  std::string err;
  ASSERT_TRUE(build_global_map("intel", 0.05, &map, &err, &st)) << err;
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("intel map: %dx%d, built in %.2f s\n", map.width, map.height, secs);
  EXPECT_LT(secs, 10.0);
  EXPECT_EQ(st.scans, 910u);
  // The Intel lab is about 30 x 30 m; with the 1 m margin and stray beams, 35..45 m each way.
  EXPECT_GT(map.width * map.resolution, 35.0);
  EXPECT_LT(map.width * map.resolution, 45.0);
  EXPECT_GT(map.height * map.resolution, 33.0);
  EXPECT_LT(map.height * map.resolution, 45.0);

  std::vector<std::uint8_t> image;
  ASSERT_TRUE(compile_map_image(map, &image, &err)) << err;
  fw::StartupArena arena;
  ASSERT_TRUE(arena.init_mapped(fw::map_image_arena_bytes(image.data(), image.size()), false, "test").is_ok());
  fw::GlobalMap gm;
  const fw::Status s = fw::load_map_image(image.data(), image.size(), arena, &gm, "intel");
  ASSERT_TRUE(s.is_ok()) << s.message();
  EXPECT_GT(gm.num_points, 10000u);

  // Every 10th corrected scan: ≥ 90% of its valid end points within 10 cm of an occupied cell.
  CarmenLog log;
  ASSERT_TRUE(read_carmen_log(data_path(d->corrected_log), CarmenReadOptions{}, &log, &err)) << err;
  std::size_t near = 0, total = 0;
  for (std::size_t k = 0; k < log.scans.size(); k += 10) {
    const CarmenScan& sc = log.scans[k];
    for (std::size_t i = 0; i < sc.ranges.size(); ++i) {
      const float r = sc.ranges[i];
      if (!(r > 0.01f) || r >= sc.max_range - 0.01f || r > 25.0f) continue;
      const double a = sc.pose.theta + sc.angle_min + i * sc.angle_increment;
      const float x = static_cast<float>(sc.pose.x + r * std::cos(a)), y = static_cast<float>(sc.pose.y + r * std::sin(a));
      ++total;
      near += gm.distance_at(x, y, 1e9f) <= 0.1f ? 1 : 0;
    }
  }
  ASSERT_GT(total, 10000u);
  const double frac = static_cast<double>(near) / total;
  std::printf("intel: %.1f%% of %zu scan end points within 10 cm of the map\n", 100.0 * frac, total);
  EXPECT_GT(frac, 0.9);
}

// fr-clinic has no corrected log: its poses come from a pose graph of the benchmark relations.
// The optimized trajectory must reproduce the relations (they are mutually consistent), be far
// better than raw odometry, and its scans must agree with the map built from them.
TEST(GlobalMapsDataTest, FrClinicRelationGraphTrajectory) {
  const Dataset* d = find_dataset("fr-clinic");
  ASSERT_NE(d, nullptr);
  if (!have_data(d->raw_log) || !have_data(d->relations)) GTEST_SKIP() << "data not found: " << data_path(d->raw_log);
#if !defined(NDEBUG) || defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  // ~9000 CG iterations of 3x3 Eigen blocks: 4 s optimized, 400 s in a Debug+ASan build (measured;
  // that run was clean). The optimized builds run it.
  GTEST_SKIP() << "fr-clinic pose-graph data test runs only in optimized, unsanitized builds (400 s under Debug+ASan)";
#endif
  std::vector<std::size_t> idx;
  std::vector<fw::Se2d> robot;
  std::string report, err;
  CarmenLog log;
  ASSERT_TRUE(read_carmen_log(data_path(d->raw_log), CarmenReadOptions{}, &log, &err)) << err;
  ASSERT_TRUE(relation_graph_trajectory("fr-clinic", log, &idx, &robot, &report, &err)) << err;
  std::printf("%s\n", report.c_str());
  ASSERT_EQ(idx.size(), 1316u);
  ASSERT_EQ(robot.size(), 1316u);
  std::vector<Relation> rel;
  ASSERT_TRUE(read_relations(data_path(d->relations), &rel, &err)) << err;
  Trajectory traj, odom;
  for (std::size_t k = 0; k < idx.size(); ++k) {
    traj.push_back({log.scans[idx[k]].ipc_timestamp, robot[k]});
    odom.push_back({log.scans[idx[k]].ipc_timestamp, log.scans[idx[k]].odom});
  }
  const RelationsMetric m = evaluate_relations(rel, traj);
  const RelationsMetric mo = evaluate_relations(rel, odom);
  EXPECT_EQ(m.used, rel.size());
  EXPECT_LT(m.trans_mean, 0.005);
  EXPECT_LT(m.rot_mean_deg, 0.05);
  EXPECT_GT(mo.trans_mean, 20 * m.trans_mean);

  // Map at 0.2 m from these poses (the cached 0.1 m map is built the same way by build_global_map;
  // the coarser grid keeps Debug/ASan runs short; EDT exactness on > 4096-cell rows is a unit test).
  std::vector<PosedScan> scans;
  for (std::size_t k = 0; k < idx.size(); ++k) {
    const CarmenScan& sc = log.scans[idx[k]];
    scans.push_back({robot[k].compose(sc.odom.between(sc.pose)), sc.angle_min, sc.angle_increment, sc.max_range,
                     sc.ranges.data(), sc.ranges.size()});
  }
  OccupancyGrid grid;
  ASSERT_TRUE(build_occupancy_grid(scans, global_map_options("fr-clinic", 0.2), &grid, nullptr, &err)) << err;
  const RosMap map = grid_to_ros_map(grid, "fr-clinic.pgm");
  std::vector<float> dist;
  ASSERT_TRUE(distance_field_m(grid, &dist, &err)) << err;
  // The firmware accepts the compiled image (4404 cells wide: beyond float's exact q² range).
  {
    std::vector<std::uint8_t> image;
    ASSERT_TRUE(compile_map_image(map, &image, &err)) << err;
    fw::StartupArena arena;
    ASSERT_TRUE(arena.init_mapped(fw::map_image_arena_bytes(image.data(), image.size()), false, "test").is_ok());
    fw::GlobalMap gm;
    const fw::Status s = fw::load_map_image(image.data(), image.size(), arena, &gm, "fr-clinic");
    ASSERT_TRUE(s.is_ok()) << s.message();
  }
  std::size_t near = 0, total = 0;
  for (std::size_t k = 0; k < idx.size(); k += 10) {
    const CarmenScan& sc = log.scans[idx[k]];
    const fw::Se2d laser = robot[k].compose(sc.odom.between(sc.pose));
    for (std::size_t i = 0; i < sc.ranges.size(); ++i) {
      const float r = sc.ranges[i];
      if (!(r > 0.01f) || r >= sc.max_range - 0.01f || r > 25.0f) continue;
      const double a = laser.theta + sc.angle_min + i * sc.angle_increment;
      std::int32_t cx, cy;
      if (!grid.geometry.world_to_cell(static_cast<float>(laser.x + r * std::cos(a)),
                                       static_cast<float>(laser.y + r * std::sin(a)), &cx, &cy)) continue;
      ++total;
      near += dist[grid.geometry.index(cx, cy)] <= 0.2f ? 1 : 0;
    }
  }
  ASSERT_GT(total, 5000u);
  const double frac = static_cast<double>(near) / total;
  std::printf("fr-clinic: %.1f%% of %zu scan end points within 20 cm of the map\n", 100.0 * frac, total);
  // Measured 80.8% at these 0.2 m cells, 82.8% at 0.1 m (at 0.1 m: 62% exactly on an occupied cell; 8% beyond 0.5 m: people, beds
  // and glass in a busy hospital over 80 minutes are erased by later beams). intel: 98.7% at 10 cm.
  EXPECT_GT(frac, 0.75);
}

TEST(GlobalMapsDataTest, CacheIsWrittenAndReused) {
  const Dataset* d = find_dataset("aces");
  ASSERT_NE(d, nullptr);
  if (!have_data(d->corrected_log)) GTEST_SKIP() << "data not found: " << data_path(d->corrected_log);
  const std::string dir = (std::filesystem::temp_directory_path() / ("global_maps_test_" + std::to_string(::getpid()))).string();
  RosMap a, b;
  std::string err;
  bool rebuilt = false;
  ASSERT_TRUE(ensure_global_map("aces", 0.1, dir, &a, &err, &rebuilt)) << err;
  EXPECT_TRUE(rebuilt);
  for (const char* ext : {".yaml", ".pgm", ".png", ".mmap", ".build.txt"}) {
    EXPECT_TRUE(std::filesystem::exists(dir + "/aces" + ext)) << ext;
  }
  ASSERT_TRUE(ensure_global_map("aces", 0.1, dir, &b, &err, &rebuilt)) << err;
  EXPECT_FALSE(rebuilt);
  EXPECT_EQ(a.pixels, b.pixels);
  // Another resolution invalidates the cache.
  ASSERT_TRUE(ensure_global_map("aces", 0.2, dir, &b, &err, &rebuilt)) << err;
  EXPECT_TRUE(rebuilt);
  EXPECT_EQ(b.resolution, 0.2);
  EXPECT_FALSE(ensure_global_map("nowhere", 0.1, dir, &b, &err));
  EXPECT_NE(err.find("unknown dataset 'nowhere'"), std::string::npos) << err;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sim
