// Voxel downsampling: one centroid per occupied voxel on a grid anchored at the origin, independent
// of the input order; bad sizes and non-finite points are errors naming the cloud.
#include "sim/io/voxel_downsample.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace sim {
namespace {

TEST(VoxelDownsample, CentroidPerVoxelAndOrderIndependent) {
  std::vector<Eigen::Vector3f> in = {{0.01f, 0.01f, 0.01f}, {0.03f, 0.03f, 0.03f}, {0.11f, 0.0f, 0.0f},
                                     {-0.01f, 0.0f, 0.0f}, {0.19f, 0.0f, 0.0f}};
  std::vector<Eigen::Vector3f> out;
  std::string err;
  ASSERT_TRUE(voxel_downsample(in, 0.1f, &out, &err)) << err;
  ASSERT_EQ(out.size(), 3u);  // voxels x ∈ [-0.1,0), [0,0.1), [0.1,0.2)
  EXPECT_NEAR(out[0].x(), -0.01f, 1e-6f);
  EXPECT_NEAR(out[1].x(), 0.02f, 1e-6f);
  EXPECT_NEAR(out[1].z(), 0.02f, 1e-6f);
  EXPECT_NEAR(out[2].x(), 0.15f, 1e-6f);
  std::mt19937 g(3);
  std::vector<Eigen::Vector3f> shuffled = in, out2;
  std::shuffle(shuffled.begin(), shuffled.end(), g);
  ASSERT_TRUE(voxel_downsample(shuffled, 0.1f, &out2, &err));
  ASSERT_EQ(out2.size(), out.size());
  for (std::size_t i = 0; i < out.size(); ++i) EXPECT_TRUE(out[i].isApprox(out2[i], 1e-6f));
}

TEST(VoxelDownsample, DenseCloudShrinksToOnePointPerVoxel) {
  std::mt19937 g(1);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Eigen::Vector3f> in;
  for (int i = 0; i < 20000; ++i) {  // one draw per declarator (argument order is unspecified)
    const float z = u(g), y = u(g), x = u(g);
    in.emplace_back(x, y, z);
  }
  std::vector<Eigen::Vector3f> out;
  std::string err;
  ASSERT_TRUE(voxel_downsample(in, 0.25f, &out, &err)) << err;
  EXPECT_EQ(out.size(), 64u);  // 4 x 4 x 4 voxels, all occupied
}

TEST(VoxelDownsample, BadInput) {
  std::vector<Eigen::Vector3f> out;
  std::string err;
  EXPECT_FALSE(voxel_downsample({{0, 0, 0}}, 0.0f, &out, &err, "office"));
  EXPECT_NE(err.find("office: voxel size"), std::string::npos) << err;
  EXPECT_FALSE(voxel_downsample({{0, 0, 0}, {NAN, 0, 0}}, 0.1f, &out, &err, "bunny"));
  EXPECT_NE(err.find("bunny: point 1 is not finite"), std::string::npos) << err;
  EXPECT_FALSE(voxel_downsample({{0, 0, 0}, {1e6f, 0, 0}}, 0.1f, &out, &err));
  EXPECT_NE(err.find("2^20 voxels"), std::string::npos) << err;
  EXPECT_TRUE(voxel_downsample({}, 0.1f, &out, &err));
  EXPECT_TRUE(out.empty());
}

}  // namespace
}  // namespace sim
