// pRANSAM experiments on real data (Sec. 4.5 on ../shared/data) and on the synthetic 3-D scene.
// Query = one real scan of a SLAM-corrected log (every k-th), truth = its corrected laser pose,
// model = the dataset's global map (sim/map/global_maps.h, occupied cell centres of the compiled
// map image). A match is CORRECT when the returned pose is within 0.30 m and 5° of the truth,
// WRONG when a hypothesis reached Ω_thres but is farther, NOTHING when none reached Ω_thres.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "firmware/base/arena.h"
#include "firmware/base/worker_pool.h"
#include "firmware/map/global_map.h"
#include "firmware/pransam/matcher.h"

namespace sim::pransam_eval {

using P2 = fw::pransam::Point<2>;
using P3 = fw::pransam::Point<3>;

struct ScanQuery {
  std::size_t index = 0;  // scan index in the corrected log
  double x = 0, y = 0, theta = 0;  // corrected laser pose (truth)
  std::vector<P2> points;          // sensor frame
};

struct RealCase {
  std::string dataset;
  std::vector<std::uint8_t> image;        // compiled map image (+ relation table section when built)
  std::unique_ptr<fw::StartupArena> map_arena;
  fw::GlobalMap map;
  std::vector<ScanQuery> queries;
  float eps_hard = 0.10f, eps_soft = 0.20f;  // contact thresholds used by make_matcher (metres)
};

struct CaseOptions {
  std::size_t every = 10;      // every k-th scan of the corrected log
  float max_range = 12.0f;     // beams beyond are dropped (metres)
  float min_range = 0.1f;
  std::size_t max_queries = 0; // 0 = all
};

// Loads (building/caching if needed) the global map of `dataset` and the queries.
bool load_real_case(const std::string& dataset, const CaseOptions& options, RealCase* out, std::string* error);

struct TableBuild {
  std::uint64_t triples = 2000000;  // h (Sec. 5.5.2)
  float extent = 10.0f;
  float min_height_ratio = 0.1f;
  std::uint64_t seed = 2012;
};

// Fills R_B offline for the case's map and appends it to the case's image as a
// kRelationTable2D section (MapImageWriter::add_section); returns the build time.
bool build_table_section(RealCase* c, const TableBuild& build, double* seconds, std::string* error);

struct MatcherHandle {
  std::unique_ptr<fw::StartupArena> arena;
  std::unique_ptr<fw::WorkerPool> pool;
  std::unique_ptr<fw::pransam::Matcher<2>> matcher;
};

// A matcher on `pool_threads` pool threads (0 = inline) with T logical workers over the case's
// map; precomputed: uses the image's relation table section (find_section + parse).
bool make_matcher(const RealCase& c, int pool_threads, int T, bool precomputed, MatcherHandle* out,
                  std::string* error);

// Classification of the RETURNED pose (pRANSAM returns its best hypothesis when Ω_thres was
// reached or I_max ran out, Sec. 4.3): correct / wrong by the criterion, nothing = no hypothesis
// at all (or an error status). below_thres counts returned poses whose Ω stayed below Ω_thres.
struct ScanMapRun {
  std::size_t n = 0, correct = 0, wrong = 0, nothing = 0, below_thres = 0, correct_below_thres = 0;
  std::vector<double> ms;           // per query
  std::vector<double> iterations;   // per query
  std::vector<double> collisions;
  std::vector<double> best_quality;
  std::vector<double> trans_err, rot_err_deg;  // of the returned pose (found or best)
  double p50() const;
  double p99() const;
  double mean_iterations() const;
  double total_ms() const;
  double success() const { return n ? static_cast<double>(correct) / static_cast<double>(n) : 0.0; }
};

struct Criterion {
  double max_trans = 0.30, max_rot_deg = 5.0;
};

ScanMapRun run_scan_map(const RealCase& c, MatcherHandle& m, const fw::pransam::MatchParams& params,
                        const Criterion& crit = Criterion(), bool verbose = false);

// Theorem 1: average Ω_best and collisions vs I_max for τ = 1..T−1 (online, stop only at I_max).
struct Theorem1Row {
  int tau = 0;
  std::uint32_t max_iterations = 0;
  double mean_best_quality = 0, mean_collisions = 0, mean_ms = 0, success = 0;
};
std::vector<Theorem1Row> theorem1(const RealCase& c, int T, const std::vector<std::uint32_t>& imax,
                                  std::size_t queries, std::uint64_t seed, std::string* error);

// Synthetic 3-D: two overlapping independently sampled crops of the textured room, the scene
// moved by a seeded random rigid transform; success = translation < 0.25 m and every RPY angle < 3°.
struct ThreeDRun {
  std::size_t trials = 0, success = 0;
  std::vector<double> ms, trans_err, rot_err_deg;
  double p50() const;
};
ThreeDRun run_3d(std::size_t trials, int pool_threads, std::uint32_t max_iterations, std::string* error,
                 std::uint32_t refine_iterations = 0, float refine_min_quality = 0.45f);

// Same seed ⇒ identical hypothesis set on 1 and 2 pool threads (collect-all, real scan).
bool determinism_check(const RealCase& c, bool precomputed, std::string* detail);

double percentile(std::vector<double> v, double q);

}  // namespace sim::pransam_eval
