// pRANSAM (Ch. 4): parallel random sample matching of a scene set A (scan / local map) to a model
// set B (global map) without an initial guess, in 2-D and 3-D (same code, D = 2 or 3).
//
// Reproducible parallelism (our organisation of Fig. 4.3): T logical workers run in ROUNDS on the
// fw::WorkerPool (any pool size; logical worker w runs on pool worker w mod P, in order). In a
// round each worker draws a batch of triples with its own RandomStream(seed, w), keys them, checks
// the OTHER table as it was at the start of the round (a collision, Eq. 4.4), turns collisions into
// hypotheses and rates them against B's contact field; its own inserts are buffered. After the
// barrier the buffered inserts are applied in worker order (overwrite on clash), hypotheses are
// merged in worker order, and the stop test runs. Hence the same seed and T give the same
// hypotheses whatever the pool size or scheduling. Workers 0..τ−1 fill R_A, the others R_B;
// τ = T/2 by default (Theorem 1).
//
// Precomputed mode (Sec. 5.5.2, Theorem 2): R_B comes filled (offline, map image section) and all T
// workers draw from A. Because R_B never changes at run time, an entry written to R_A could never
// produce a later collision, so in this mode workers only probe R_B (R_A is not written).
//
// Quality Ω (Eq. 4.7) uses hard (Eq. 4.31) or fuzzy (Eq. 4.33) contact from the ContactField, with
// the extrapolation shortcut (Eq. 4.8): points of A are visited in a random order and a hypothesis
// is dropped as soon as the 95 % upper bound mean + 1.96/(2√k) falls below the bound to beat
// (Ω_best in stop mode, Ω_thres in collect-all mode).
//
// Memory: everything is taken from a StartupArena in init() (two tables of kNumSlots·12 bytes, the
// contact field, indices, per-worker buffers) and registered with MemoryReport (module "pransam").
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "firmware/base/arena.h"
#include "firmware/base/rng.h"
#include "firmware/base/status.h"
#include "firmware/base/worker_pool.h"
#include "firmware/pransam/contact_field.h"
#include "firmware/pransam/hypothesis.h"
#include "firmware/pransam/point_index.h"
#include "firmware/pransam/relation_table.h"
#include "hal/clock.h"

namespace fw::pransam {

constexpr int kMaxLogicalWorkers = 16;

struct MatcherOptions {
  int num_workers = 2;                   // T (logical workers; ≥ pool size is fine)
  std::uint32_t max_scene_points = 4096; // |A| capacity
  std::uint32_t max_model_points = 131072;  // |B| capacity
  std::uint32_t max_index_cells = 65536;    // PointIndex grid capacity per set
  ContactFieldOptions field;
  bool allocate_model_table = true;      // false: only precomputed R_B will be used (saves 6 MB)
  std::uint32_t max_batch = 1024;        // iterations per worker per round (upper bound)
  std::uint32_t collect_capacity = 4096; // collect-all buffer (merged), per-worker buffers the same
};

enum class StopReason : std::uint8_t { kThreshold, kMaxIterations, kDeadline };

struct MatchParams {
  std::uint64_t seed = 1;
  std::uint32_t max_iterations = 100000;  // I_max: total triples drawn over all workers
  float omega_thres = 0.8f;               // Ω_thres
  bool fuzzy = true;                      // Eq. 4.33 instead of Eq. 4.31
  bool extrapolate = true;                // Eq. 4.8
  bool collect_all = false;               // MML mode: run I_max and return all Ω ≥ Ω_thres
  int tau = -1;                           // workers filling R_A (online); −1 = T/2 (Theorem 1)
  float extent = 0.0f;                    // online table extent; 0 = min(diam A, diam B, max_extent)
  float max_extent = 12.0f;
  float min_height_ratio = 0.1f;          // collinear rejection
  // Deadline mode (Sec. 4.4.3, soft real-time): the iteration count is set by the time left. With a
  // clock and deadline_ns ≠ 0 (absolute, on that clock), a round is started only if the previous
  // round's time per iteration predicts it ends before the deadline; the first round always runs.
  // I_max stays the upper bound. Time-dependent, so not reproducible: off in the lockstep tools.
  const hal::Clock* clock = nullptr;
  std::uint64_t deadline_ns = 0;
  // A replay of a deadline stop (issue 60: the black box's global records): stop as the deadline
  // did, before round stop_after_rounds + 1 (stats.stop = kDeadline), without a clock. 0 = off.
  std::uint32_t stop_after_rounds = 0;
  std::uint32_t first_batch = 256;        // round batch starts here and doubles up to max_batch
                                          // (fewer barriers: 2-thread runs on a busy machine suffer less)
  std::uint32_t min_extrapolation_points = 12;
  // Optional local refinement (not in Ch. 4; a robotics engineer's addition, off by default):
  // hypotheses rated Ω ≥ refine_min_quality are polished by refine_iterations Gauss–Newton steps
  // on the interpolated distance field (truncated at refine_cutoff metres) and rated again. A
  // triangle correspondence is only as precise as the point spacing, so without this a correct
  // hypothesis often misses a tight Ω_thres by a few centimetres / a degree.
  std::uint32_t refine_iterations = 0;
  // Optional free-space test for scans (an addition, off by default): A's origin is the sensor.
  // A hypothesis reaching Ω ≥ Ω_thres is rejected when more than max_blocked_fraction of its beams
  // (sensor → point, ignoring the last free_space_margin metres) pass through a point of B: a beam
  // through a wall of the map is impossible. Rejects mirrored / rotated corridor matches.
  bool scene_origin_is_sensor = false;
  float free_space_margin = 0.3f;
  float max_blocked_fraction = 0.1f;
  // 3-D extension of the free-space test (issue 17, not in the dissertation): the sensor need not
  // be A's origin (a cut of an RGB-D frame moved by an unknown transform knows where its camera is
  // in its own frame): its position in A's frame (first D values used). And the test may apply
  // from a lower quality: with free_space_min_quality ≥ 0 every hypothesis with Ω ≥ that value
  // that would become the best (or, collecting, reach Ω_thres) is tested, so a near-symmetric flip
  // of an object (a milk carton turned by 180° fits its own surface) or a slide along a wall cannot
  // become the answer that is reported. < 0 (default): only Ω ≥ Ω_thres, as in 2-D.
  float scene_sensor[3] = {0.0f, 0.0f, 0.0f};
  float free_space_min_quality = -1.0f;
  // A beam is blocked where it comes closer than this to a point of B (metres; 0 = half a field
  // cell, the 2-D grid). A sampled 3-D surface has gaps of a point spacing: a beam crossing it
  // between points passes up to ~0.7 spacing from the nearest one.
  float free_space_block_radius = 0.0f;
  float refine_min_quality = 0.6f;
  float refine_cutoff = 0.4f;
  // At most this many scene points (evenly strided) enter the refinement's normal equations; 0 =
  // all. Three parameters need far fewer points than a local map has, and the refinement of every
  // hypothesis above refine_min_quality is what costs (MML: a full refinement raised the global
  // step's p99 7-15x); the refined hypothesis is rated on the whole scene again.
  std::uint32_t refine_max_points = 0;
  // At most this many refinements per match (0 = no limit), shared evenly by the workers (each stops
  // refining after its share, so the result does not depend on scheduling): the bound on what the
  // refinement can add to a match where hundreds of hypotheses come near the threshold.
  std::uint32_t refine_max_hypotheses = 0;
};

struct MatchStats {
  std::uint64_t iterations = 0;       // triples drawn (all workers)
  std::uint64_t keyed = 0;            // triples that passed the filter and were keyed
  std::uint64_t rejected_collinear = 0, rejected_size = 0, failed_draws = 0;
  std::uint64_t collisions = 0;       // Eq. 4.4 hits
  std::uint64_t flipped = 0;          // Eq. 5.3 rejections (2-D)
  std::uint64_t evaluated = 0;        // hypotheses rated
  std::uint64_t extrapolation_cut = 0;  // rated but dropped early (Eq. 4.8)
  std::uint64_t point_checks = 0;     // contact look-ups
  std::uint64_t refined = 0;          // hypotheses polished (refine_iterations > 0)
  std::uint64_t free_space_rejected = 0;  // Ω ≥ Ω_thres but not after the free-space test
  std::uint32_t rounds = 0;
  StopReason stop = StopReason::kMaxIterations;
};

template <int D>
struct MatchResult {
  bool found = false;             // a hypothesis with Ω ≥ Ω_thres exists
  Hypothesis<D> best;             // highest Ω seen (valid if best_valid)
  bool best_valid = false;
  const Hypothesis<D>* hypotheses = nullptr;  // collect-all: all Ω ≥ Ω_thres in merge order
  std::size_t num_hypotheses = 0;
  std::size_t dropped = 0;        // collect-all hypotheses lost to the bounded buffer
  MatchStats stats;
};

// Work bound of Matcher::fill_model_table: at most kFillDrawsPerTriple draws per wanted triple
// (+ kFillMinDraws), and every kFillCheckEvery draws the fill gives up when it is hopelessly behind
// the pace that cap needs.
constexpr std::uint64_t kFillDrawsPerTriple = 200;
constexpr std::uint64_t kFillMinDraws = 100000;
constexpr std::uint64_t kFillCheckEvery = 4096;  // power of two
static_assert((kFillCheckEvery & (kFillCheckEvery - 1)) == 0, "kFillCheckEvery must be a power of two");

// True when `keyed` keyable triples after `draws` draws cannot reach `triples` within `max_draws`
// draws even at a generous upper bound of the observed keyable rate (keyed + 3·√keyed + 3, three
// standard deviations of the Poisson count): draws are independent and identically distributed,
// so a fill that far behind the needed pace would only spin until the cap and fail there.
inline bool fill_behind_pace(std::uint64_t keyed, std::uint64_t draws, std::uint64_t triples,
                             std::uint64_t max_draws) {
  if (draws == 0 || max_draws == 0 || keyed >= triples) return false;
  const double upper = static_cast<double>(keyed) + 3.0 * std::sqrt(static_cast<double>(keyed)) + 3.0;
  const double pace = static_cast<double>(triples) * static_cast<double>(draws) / static_cast<double>(max_draws);
  return upper < pace;
}

template <int D>
class Matcher {
 public:
  Matcher() = default;
  Matcher(const Matcher&) = delete;
  Matcher& operator=(const Matcher&) = delete;

  // Allocates everything. `pool` may be null (inline, one thread) and must outlive the matcher.
  // `work` (optional): where the working memory goes — R_A, the scene index and order, R_A's
  // touched list, the workers' insert and hypothesis buffers — sized by the options alone, so
  // several matchers of which only one runs at a time may share it (firmware/app/map_set.h); the
  // model's parts (R_B, contact field, model index) stay in `arena`. Null = all in `arena`.
  Status init(const MatcherOptions& options, StartupArena& arena, WorkerPool* pool, StartupArena* work = nullptr);
  // Upper bound of what init() takes from `work` (alignment included).
  static std::size_t working_bytes(const MatcherOptions& options);
  // Another matcher has written the shared working memory since this one last reset: the next
  // reset() empties R_A whole (its touched list only knows this matcher's writes).
  void mark_working_memory_foreign() { touched_overflow_[0] = true; }

  // Sets the model set B (non-owning). Builds the contact field and the sampler index and clears
  // the online R_B. Drops any precomputed table.
  Status set_model(const Point<D>* points, std::size_t n, const char* name = "model");
  // Uses a precomputed R_B over the model set last given to set_model (see relation_table_io.h).
  Status use_precomputed_table(const Triple* slots, float extent, const char* name = "precomputed table");
  bool has_precomputed_table() const { return precomputed_; }

  // Offline fill of R_B (Theorem 2): draws from B until `triples` have been keyed, using the
  // table extent `extent`. Leaves the table in R_B for serialisation (model_table()). The work is
  // bounded by what B can give (kFillDrawsPerTriple, fill_behind_pace): a degenerate map (a few
  // occupied cells, all collinear, ...) fails within milliseconds with an error that says so.
  Status fill_model_table(std::uint64_t seed, std::uint64_t triples, float extent, float min_height_ratio);
  const RelationTable& model_table() const { return table_b_; }
  const RelationTable& scene_table() const { return table_a_; }

  // Back to the state right after init() + set_model() (+ a precomputed table, which is kept):
  // online relation tables R_A / R_B emptied with their statistics, per-worker state and buffers
  // cleared. match() itself derives everything else from its MatchParams (worker streams from
  // params.seed, round counters, Ω_best bound), so after reset() the same calls give bit-identical
  // results whatever was matched before.
  void reset();

  // Matches A (non-owning, finite points) to B. Errors: not initialised, no model, |A| < 3,
  // NaN/inf point, capacity, all triples of A rejected (collinear or too large).
  Status match(const Point<D>* scene, std::size_t n, const MatchParams& params, MatchResult<D>* out);

  const MatcherOptions& options() const { return options_; }
  const ContactField<D>& field() const { return field_; }
  // Space the model set knows nothing about (the global map's unmapped space, map/unmapped_space.h):
  // while set_unmapped_active(true), a point there counts as hard contact — it is no evidence
  // against the hypothesis, because the robot may stand in that space and see anything there.
  // `in_unmapped` is set once at start-up; the switch may change between match() calls.
  using RegionFn = bool (*)(const void* ctx, const Point<D>& p);
  void set_unmapped_space(RegionFn in_unmapped, const void* ctx) {
    unmapped_fn_ = in_unmapped;
    unmapped_ctx_ = ctx;
  }
  void set_unmapped_active(bool on) { unmapped_active_ = on && unmapped_fn_ != nullptr; }
  bool unmapped_active() const { return unmapped_active_; }
  // Optional distance source for the refinement (MatchParams::refine_iterations) in place of the
  // contact field's float distance: a model that already has a distance field (the global map's)
  // need not keep a second one (ContactFieldOptions::keep_distance = false saves 4 bytes per cell).
  // `fn` gives the distance and its gradient at p, false where it is unknown. Start-up only.
  using DistanceFn = bool (*)(const void* ctx, const Point<D>& p, float* d, Point<D>* grad);
  void set_refine_distance(DistanceFn fn, const void* ctx) {
    refine_fn_ = fn;
    refine_ctx_ = ctx;
  }

 private:
  static constexpr std::size_t kMaxTouched = 1u << 18;  // touched-slot list per table
  struct InsertRecord {
    std::uint32_t slot;
    Triple triple;
  };
  struct alignas(64) WorkerState {
    RandomStream rng;
    InsertRecord* inserts = nullptr;
    std::uint32_t num_inserts = 0;
    Hypothesis<D>* collected = nullptr;
    std::uint32_t num_collected = 0;
    std::uint64_t dropped = 0;
    Hypothesis<D> best;
    bool best_valid = false;
    bool reached = false;
    std::uint32_t batch = 0;
    std::uint64_t first_iteration = 0;
    MatchStats stats;
  };
  // What match()'s rounds leave for the result.
  struct RoundTally {
    std::size_t merged_n = 0;   // hypotheses in merged_
    std::size_t dropped = 0;    // collect-all hypotheses lost to merged_'s capacity
    std::uint32_t rounds = 0;
    bool reached = false;       // a worker reached Ω_thres (stop mode)
    bool deadline_hit = false;  // deadline mode stopped before I_max
  };

  // Steps of match() (matcher.cpp).
  Status check_match_input(const Point<D>* scene, std::size_t n, const MatchParams& params) const;
  Status check_online_workers(int T, int tau) const;
  Status choose_extent(const Point<D>* scene, std::size_t n, const MatchParams& params, float* extent_out) const;
  Status prepare_match(const Point<D>* scene, std::size_t n, const MatchParams& params, int tau, float extent);
  void seed_workers(std::uint64_t seed);
  RoundTally run_rounds(const MatchParams& params, MatchResult<D>* out);
  void plan_round(std::uint64_t round_total, std::uint64_t done);
  void run_round();
  void merge_round(MatchResult<D>* out, RoundTally* tally);

  static void round_job(void* ctx, int pool_index, int pool_size);
  static void apply_job(void* ctx, int pool_index, int pool_size);
  void run_worker(int w);
  void reset_online_table(int table);
  void refine(Hypothesis<D>* h) const;
  float blocked_fraction(const Hypothesis<D>& h) const;
  float rate(const Hypothesis<D>& h, float bound, std::uint32_t start, bool* complete, std::uint64_t* checks) const;

  MatcherOptions options_;
  WorkerPool* pool_ = nullptr;
  bool initialized_ = false;
  RelationTable table_a_, table_b_;
  RelationTable precomp_table_;          // read-only view of a precomputed R_B
  const RelationTable* model_table_ = &table_b_;
  bool precomputed_ = false;
  std::uint32_t* touched_[2] = {nullptr, nullptr};  // slots filled during the last match
  std::size_t touched_n_[2] = {0, 0};
  bool touched_overflow_[2] = {false, false};
  float model_index_extent_ = -1.0f;
  ContactField<D> field_;
  DistanceFn refine_fn_ = nullptr;
  const void* refine_ctx_ = nullptr;
  RegionFn unmapped_fn_ = nullptr;
  const void* unmapped_ctx_ = nullptr;
  bool unmapped_active_ = false;
  PointIndex<D> index_a_, index_b_;
  const Point<D>* model_ = nullptr;
  std::uint32_t model_n_ = 0;
  Point<D> model_min_, model_max_;
  std::uint32_t* scene_order_ = nullptr;
  WorkerState* workers_ = nullptr;
  Hypothesis<D>* merged_ = nullptr;

  // Per-match state read by the workers.
  const Point<D>* scene_ = nullptr;
  std::uint32_t scene_n_ = 0;
  MatchParams params_;
  TripleFilter filter_;
  int num_workers_ = 0;
  int tau_ = 0;
  float round_bound_ = 0.0f;  // Ω_best as of the round start (stop mode)
};

extern template class Matcher<2>;
extern template class Matcher<3>;

}  // namespace fw::pransam
