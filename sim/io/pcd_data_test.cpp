// The real clouds of ../shared/data/pcl3d (MMLFW_DATA_DIR) read with the counts of its README:
// bun0 397 points, bun4 361, car6 10,031, milk 13,704, office1 (gzip, organized 640 x 480) 307,200
// of which 52,744 are NaN (dropped and counted).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include "sim/io/datasets.h"
#include "sim/io/pcd.h"

namespace sim {
namespace {

TEST(PcdData, SharedCloudsMatchTheirReadme) {
  struct stat st;
  if (stat(data_path("pcl3d/README.md").c_str(), &st) != 0) {
    GTEST_SKIP() << "point clouds not found: " << data_path("pcl3d") << " (set MMLFW_DATA_DIR to ../shared/data)";
  }
  struct Expect {
    const char* file;
    std::size_t declared, nan;
    std::uint32_t width, height;
  };
  for (const Expect& e : {Expect{"bun0.pcd", 397, 0, 397, 1}, Expect{"bun4.pcd", 361, 0, 361, 1},
                          Expect{"car6.pcd", 10031, 0, 10031, 1}, Expect{"milk.pcd", 13704, 0, 13704, 1},
                          Expect{"office1.pcd.gz", 307200, 52744, 640, 480}}) {
    PcdCloud c;
    std::string err;
    ASSERT_TRUE(read_pcd(data_path(std::string("pcl3d/") + e.file), &c, &err)) << err;
    EXPECT_EQ(c.declared_points, e.declared) << e.file;
    EXPECT_EQ(c.dropped_nonfinite, e.nan) << e.file;
    EXPECT_EQ(c.points.size(), e.declared - e.nan) << e.file;
    EXPECT_EQ(c.width, e.width) << e.file;
    EXPECT_EQ(c.height, e.height) << e.file;
    Eigen::Vector3f lo = c.points[0], hi = c.points[0];
    for (const auto& p : c.points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    std::printf("%-15s %6zu points (%zu NaN dropped), extent %.3f x %.3f x %.3f\n", e.file, c.points.size(),
                c.dropped_nonfinite, hi.x() - lo.x(), hi.y() - lo.y(), hi.z() - lo.z());
  }
}

}  // namespace
}  // namespace sim
