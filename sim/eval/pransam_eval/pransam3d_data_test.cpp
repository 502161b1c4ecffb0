// Real 3-D clouds (label "data", issue 17): pRANSAM 3-D on the first office1 and car6 draws finds the
// known transform within 0.4 voxel / 2° after refinement and reports nothing wrong; the common
// refinement itself pulls a pose 1.5 voxels / 3° off back to the truth; a known truth scores as
// correct and a 180° turn as wrong; a draw whose scene reaches beyond the model is matched the other way.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>

#include "sim/eval/pransam_eval/cloud_draws.h"
#include "sim/eval/pransam_eval/cloud_outcome.h"
#include "sim/eval/pransam_eval/pransam3d_real.h"
#include "sim/io/datasets.h"

namespace sim::pransam_eval {
namespace {

#define REQUIRE_CLOUDS()                                                                        \
  if (!std::filesystem::exists(cloud_path("README.md")))                                       \
  GTEST_SKIP() << "point clouds not found: " << cloud_path("") << " (set MMLFW_DATA_DIR to ../shared/data)"

TEST(Pransam3dData, OfficeAndCarDrawsAreMatched) {
  REQUIRE_CLOUDS();
  for (const char* cloud : {"office1", "car6"}) {
    DrawOptions o;
    o.draws = 3;
    o.voxel = default_voxel(cloud);
    std::vector<CloudDraw> draws;
    std::string err;
    ASSERT_TRUE(load_draws(cloud, o, &draws, &err)) << err;
    for (const auto& d : draws) {
      EXPECT_GE(d.overlap, 0.55) << cloud;
      EXPECT_LE(d.overlap, 0.85) << cloud;
    }
    MethodRun r;
    ASSERT_TRUE(run_pransam3d(draws, Pransam3dConfig(), 2, &r, &err)) << err;
    EXPECT_EQ(r.wrong(), 0u) << cloud;
    EXPECT_EQ(r.successes(), 3u) << summary_line(cloud, r);
  }
}

// Pransam3dConfig::retry_other_way: office draw #22 (scene ≈ 19k voxels, model ≈ 11k) reaches no
// Ω_thres with the scene as A — Ω counts A's points, and the scene reaches beyond the model — and is
// matched right when the model is matched onto the scene instead.
TEST(Pransam3dData, LargerSceneIsMatchedTheOtherWay) {
  REQUIRE_CLOUDS();
  DrawOptions o;
  o.draws = 23;
  o.voxel = default_voxel("office1");
  std::vector<CloudDraw> draws;
  std::string err;
  ASSERT_TRUE(load_draws("office1", o, &draws, &err)) << err;
  const std::vector<CloudDraw> one(draws.begin() + 22, draws.end());
  ASSERT_GT(one[0].scene.size(), one[0].model.size() * 3 / 2);
  for (const bool retry : {false, true}) {
    Pransam3dConfig c;
    c.retry_other_way = retry;
    MethodRun r;
    ASSERT_TRUE(run_pransam3d(one, c, 2, &r, &err)) << err;
    EXPECT_EQ(r.wrong(), 0u);
    EXPECT_EQ(r.successes(), retry ? 1u : 0u) << summary_line("office1 #22", r);
  }
}

TEST(Pransam3dData, RefinementAndScoring) {
  REQUIRE_CLOUDS();
  DrawOptions o;
  o.draws = 1;
  std::vector<CloudDraw> draws;
  std::string err;
  ASSERT_TRUE(load_draws("office1", o, &draws, &err)) << err;
  const CloudDraw& d = draws[0];
  PlaneModel pm;
  pm.build(&d.model, 3.0f * d.voxel);
  const Eigen::Matrix3f off = Eigen::AngleAxisf(3.0f * static_cast<float>(M_PI) / 180.0f,
                                                Eigen::Vector3f(1, 2, 3).normalized()).toRotationMatrix();
  const CloudOutcome near = score_answer(d, pm, off * d.truth_rotation,
                                         d.truth_translation + Eigen::Vector3f(1.5f * d.voxel, 0, 0), true, 1.0);
  EXPECT_TRUE(near.correct) << near.trans_err << " m " << near.rot_err_deg << "°";
  const CloudOutcome turned = score_answer(d, pm, Eigen::AngleAxisf(static_cast<float>(M_PI), Eigen::Vector3f::UnitY()) *
                                                      d.truth_rotation, d.truth_translation, true, 1.0);
  EXPECT_FALSE(turned.correct);
  MethodRun r;
  r.outcomes = {near, turned};
  EXPECT_EQ(r.successes(), 1u);
  EXPECT_EQ(r.wrong(), 1u);
}

}  // namespace
}  // namespace sim::pransam_eval
