// Host evaluation of the scan matchers (issue 4): scan-matcher-only odometry over the real CARMEN
// logs scored with the relations metric, the pairwise ground-truth experiment (Tables 2.3–2.6 in
// spirit), per-match timing, and map pictures (PNG). Shared by the tool mml-rbsm-eval and the
// benchmark bench_rbsm.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "firmware/base/worker_pool.h"
#include "firmware/baselines/icp/pl_icp.h"
#include "firmware/baselines/icp/trimmed_icp.h"
#include "firmware/rbsm/increment_fusion.h"
#include "firmware/rbsm/rbsm.h"
#include "firmware/rbsm/scan_matching_odometry.h"
#include "sim/io/carmen_log.h"
#include "sim/io/reference_trajectory.h"
#include "sim/io/relations.h"

namespace sim {

// kIcp: the dissertation's trimmed ICP (scan → end-point map, Sec. 2.4); kPlIcp: PL-ICP (Censi
// 2008) laser-to-laser like CSM, the honest ICP baseline of issue 15.
enum class MatcherKind { kRbsm, kIcp, kPlIcp };
// "rbsm", "trimmed-icp", "pl-icp" (file names and printouts).
const char* matcher_name(MatcherKind kind);
// The ICP baselines the tools report beside RBSM: PL-ICP, then trimmed ICP.
std::vector<MatcherKind> icp_baselines();

struct MatcherConfig {
  fw::RbsmOptions rbsm;
  fw::TrimmedIcpOptions icp;
  fw::PlIcpOptions plicp;
  fw::ScanMatchingOdometryOptions front;
  fw::IncrementFusionOptions fusion;  // RBSM ⊕ PL-ICP increments (extension, fuse_increments)
  bool fusion_smooth = true;          // and the fused chain smoothed backwards (fw::smooth_fusion_steps)
  int workers = 1;  // >1: RBSM sampling/weighting over a fw::WorkerPool
};
// 5 cm cells, 1024-cell (51 m) scrolling window, 1000 particles, points up to 15 m, at least 3
// resampling rounds (RbsmOptions::min_iterations; set it to 1 for Alg. 1's stop rule alone).
MatcherConfig default_matcher_config();

// A matcher with its own arena (host side: the block is one vector allocated at construction).
class MatcherInstance {
 public:
  static std::unique_ptr<MatcherInstance> create(MatcherKind kind, const MatcherConfig& config, std::string* error);
  ~MatcherInstance();
  fw::ScanMatcher* matcher() { return matcher_; }
  fw::Rbsm* rbsm() { return rbsm_.get(); }

 private:
  MatcherInstance() = default;
  std::vector<unsigned char> block_;
  fw::StartupArena arena_;
  std::unique_ptr<fw::Rbsm> rbsm_;
  std::unique_ptr<fw::TrimmedIcp> icp_;
  std::unique_ptr<fw::PlIcp> plicp_;
  std::unique_ptr<fw::WorkerPool> pool_;
  fw::ScanMatcher* matcher_ = nullptr;
};

struct OdometryRun {
  std::vector<fw::Se2d> poses;     // one per processed scan (log order)
  std::vector<double> match_ms;    // wall time of each match() call
  std::vector<double> match_cpu_ms;  // CPU time of the calling thread (robust on a loaded machine;
                                     // excludes pool workers)
  std::vector<double> scan_cpu_ms;   // CPU time of the whole step per scan (points, match and the map
                                     // update, i.e. integrate()); every scan, including the first
  std::vector<uint32_t> iterations;  // per match (RBSM rounds / ICP iterations)
  size_t not_converged = 0;        // matches that hit the iteration cap
  size_t failures = 0;             // scans the matcher refused (pose = odometry prediction)
  std::vector<std::string> failure_messages;  // first few
};
// Scan-matching odometry over the first max_scans scans (0 = all). `progress` (optional) is called
// every 500 scans with (scans done, scans to do), e.g. for a progress line (mml-slam).
bool run_scan_matching_odometry(const CarmenLog& log, MatcherKind kind, const MatcherConfig& config, size_t max_scans,
                                OdometryRun* out, std::string* error,
                                const std::function<void(size_t, size_t)>& progress = {});

// RBSM's poses (`absolute`) fused with the increments of PL-ICP's poses (`relative`, same scans) by
// fw::IncrementFusion (an extension of Alg. 1, issue 15), then, when `smooth`, smoothed over the whole
// log by fw::smooth_fusion_steps (offline use: every scan hears the later ones): one pose per scan in
// *out; *gated: updates down-weighted at the gate. False (with *error) when the lengths differ or a
// pose is not finite.
bool fuse_increments(const std::vector<fw::Se2d>& absolute, const std::vector<fw::Se2d>& relative,
                     const fw::IncrementFusionOptions& options, bool smooth, std::vector<fw::Se2d>* out,
                     uint32_t* gated, std::string* error);

// Mean of scan_cpu_ms: CPU per scan including the map update (the throughput figure).
double cpu_ms_per_scan(const OdometryRun& run);

struct ErrorSummary {
  size_t n = 0;
  double mean = 0, p95 = 0, max = 0;
};
ErrorSummary summarize(std::vector<double> values);

struct PairwiseResult {
  std::vector<double> trans_err_m, rot_err_deg, ms;
  size_t failures = 0;
};
// Pairs of consecutive corrected scans (reference poses from the corrected log), every `stride`-th
// pair up to max_pairs: map = first scan, guess = true relative pose ⊕ N(0, σ_xy, σ_θ) noise
// (thesis: 10 cm, 6°); errors of the matched relative pose.
bool run_pairwise(const CarmenLog& log, const std::vector<CorrectedPose>& reference, MatcherKind kind,
                  const MatcherConfig& config, size_t max_pairs, std::uint64_t seed, double sigma_xy,
                  double sigma_theta_deg, PairwiseResult* out, std::string* error);

// Renders every `stride`-th scan at the given poses into a grey end-point image (res m/px) with the
// trajectory in red (and an optional second one in blue) and writes a PNG.
bool write_map_png(const std::string& path, const CarmenLog& log, const std::vector<fw::Se2d>& poses,
                   const std::vector<fw::Se2d>* second_path, double resolution, float max_range, size_t stride,
                   std::string* error);

// Per-dataset paths (raw log, relations, corrected poses) resolved under data_dir().
struct EvalDataset {
  std::string name, raw_log, relations, corrected_poses;
};
bool find_eval_dataset(const std::string& name, EvalDataset* out, std::string* error);

double percentile(std::vector<double> v, double p);
// Mean and population standard deviation over seeds (NaN when empty).
double mean(const std::vector<double>& v);
double stddev(const std::vector<double>& v);

}  // namespace sim
