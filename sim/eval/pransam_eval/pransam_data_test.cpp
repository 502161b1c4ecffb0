// Real-data check of pRANSAM (label "data"): scans of the intel corrected log matched against the
// intel global map with a precomputed relation table that went through the map image section.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "sim/eval/pransam_eval/pransam_eval_lib.h"
#include "sim/io/datasets.h"

namespace sim::pransam_eval {
namespace {

TEST(PransamDataTest, IntelScansAgainstTheGlobalMapWithPrecomputedTable) {
  const Dataset* ds = find_dataset("intel");
  ASSERT_NE(ds, nullptr);
  if (!std::filesystem::exists(data_path(ds->corrected_log))) {
    GTEST_SKIP() << "intel corrected log not found under MMLFW_DATA_DIR (" << data_dir() << ")";
  }
  CaseOptions co;
  co.every = 60;  // 16 scans spread over the log
  co.max_range = 40.0f;
  RealCase c;
  std::string err;
  ASSERT_TRUE(load_real_case("intel", co, &c, &err)) << err;
  TableBuild tb;
  tb.triples = 500000;
  double s = 0;
  ASSERT_TRUE(build_table_section(&c, tb, &s, &err)) << err;
  MatcherHandle m;
  ASSERT_TRUE(make_matcher(c, 2, 2, true, &m, &err)) << err;
  fw::pransam::MatchParams p;
  p.seed = 3;
  p.max_iterations = 100000;
  p.omega_thres = 0.97f;
  p.refine_iterations = 5;
  p.refine_min_quality = 0.85f;
  const ScanMapRun r = run_scan_map(c, m, p);
  EXPECT_EQ(r.n, c.queries.size());
  EXPECT_EQ(r.nothing, 0u);
  // Typically 15-16 of 16; a few scans of intel are ambiguous for a single scan.
  EXPECT_GE(r.correct, r.n - 3) << "correct " << r.correct << " wrong " << r.wrong << " of " << r.n;
}

}  // namespace
}  // namespace sim::pransam_eval
