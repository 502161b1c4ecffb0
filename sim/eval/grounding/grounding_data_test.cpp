// The grounding measurement on one real log (aces: 440 corrected poses, a quick read), or a skip
// with the reason when ../shared/data is absent.
#include <gtest/gtest.h>

#include <filesystem>

#include "sim/eval/grounding/grounding.h"
#include "sim/io/datasets.h"

namespace sim::ground {
namespace {

TEST(GroundingData, AcesOdometryErrorIsMeasured) {
  const Dataset* d = find_dataset("aces");
  ASSERT_NE(d, nullptr);
  if (!std::filesystem::exists(data_path(d->raw_log)) || !std::filesystem::exists(data_path(d->corrected_poses))) {
    GTEST_SKIP() << "aces data absent in " << data_dir() << " (set MMLFW_DATA_DIR)";
  }
  GroundOptions opt;
  OdometryMeasure m;
  std::string err;
  ASSERT_TRUE(measure_log_odometry("aces", opt, &m, &err)) << err;
  EXPECT_EQ(m.pairs, 440u);
  ASSERT_TRUE(m.measured);
  EXPECT_GT(m.long_w.windows, 50u);
  // A real differential drive: a few per cent per metre, not zero (the reference is not the
  // odometry) and not tens of per cent.
  EXPECT_GT(m.long_w.trans_p50, 0.002);
  EXPECT_LT(m.long_w.trans_p50, 0.2);
  EXPECT_GT(m.long_w.head_deg_per_m_p50, 0.01);
  EXPECT_LT(m.long_w.head_deg_per_m_p50, 10.0);
}

TEST(GroundingData, MissingDataIsASkipNotAFailure) {
  // Whatever the data dir holds, an unknown dataset is an error with a message, never a crash.
  GroundOptions opt;
  OdometryMeasure m;
  std::string err;
  EXPECT_FALSE(measure_log_odometry("no-such-log", opt, &m, &err));
  EXPECT_FALSE(err.empty());
}

}  // namespace
}  // namespace sim::ground
