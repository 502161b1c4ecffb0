// pRANSAM orchestration (Alg. 2): set-up, the model's relation table, and match() — the rounds of
// the workers (matcher_rounds.cpp) rate (matcher_rating.cpp), refine (matcher_refine.cpp) and test
// free space (matcher_free_space.cpp) per hypothesis.
#include "firmware/pransam/matcher.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "firmware/base/memory_report.h"

namespace fw::pransam {

namespace {
constexpr std::uint64_t kSceneOrderStream = 0x5CE7E0000ull;  // stream of the scene visiting order
constexpr std::uint64_t kFillStream = 0xF111ull;               // offline R_B fill

template <int D>
const char* module_name() { return D == 2 ? "pransam2d" : "pransam3d"; }

template <int D>
bool all_finite(const Point<D>* p, std::size_t n, std::size_t* bad) {
  for (std::size_t i = 0; i < n; ++i) {
    if (!p[i].allFinite()) { *bad = i; return false; }
  }
  return true;
}

// Probes a thinned grid of index triples (about 64 steps per index), stopping at the first keyable one.
template <int D>
bool has_keyable_triple(const Point<D>* scene, std::uint32_t n, const TripleFilter& f) {
  bool any = false;
  for (std::uint32_t i = 0; i < n && !any; ++i) {
    for (std::uint32_t j = i + 1; j < n && !any; j += 1 + n / 64) {
      for (std::uint32_t k = j + 1; k < n && !any; k += 1 + n / 64) {
        Triple t;
        t.v[0] = i; t.v[1] = j; t.v[2] = k;
        std::uint32_t slot;
        any = key_triple<D>(scene, f, &t, &slot) == KeyResult::kOk;
      }
    }
    if (n > 64) i += n / 64;
  }
  return any;
}

// Random visiting order of A for the extrapolation (Eq. 4.8): Fisher–Yates from the seed.
void shuffle_scene_order(std::uint32_t* order, std::uint32_t n, std::uint64_t seed) {
  RandomStream rng(seed, kSceneOrderStream);
  for (std::uint32_t i = 0; i < n; ++i) order[i] = i;
  for (std::uint32_t i = n - 1; i > 0; --i) {
    const std::uint32_t j = rng.uniform_index(i + 1);
    const std::uint32_t tmp = order[i];
    order[i] = order[j];
    order[j] = tmp;
  }
}

// Sec. 4.4.3: stop when the next round, at the last round's rate, would end past the deadline.
bool next_round_misses_deadline(std::uint64_t round_start, std::uint64_t deadline_ns, std::uint64_t last_round_ns,
                                std::uint64_t last_round_total, std::uint64_t round_total) {
  const std::uint64_t predicted =
      last_round_total > 0 ? last_round_ns * round_total / last_round_total : last_round_ns;
  return round_start >= deadline_ns || deadline_ns - round_start < predicted;
}

// One worker's counters added to the match's.
void add_stats(MatchStats* s, const MatchStats& ws) {
  s->iterations += ws.iterations;
  s->keyed += ws.keyed;
  s->rejected_collinear += ws.rejected_collinear;
  s->rejected_size += ws.rejected_size;
  s->failed_draws += ws.failed_draws;
  s->collisions += ws.collisions;
  s->flipped += ws.flipped;
  s->evaluated += ws.evaluated;
  s->extrapolation_cut += ws.extrapolation_cut;
  s->point_checks += ws.point_checks;
  s->refined += ws.refined;
  s->free_space_rejected += ws.free_space_rejected;
}
}  // namespace

template <int D>
std::size_t Matcher<D>::working_bytes(const MatcherOptions& o) {
  constexpr std::size_t a = 64;  // worst alignment padding per allocation
  const std::size_t scene = o.max_scene_points;
  std::size_t n = kNumSlots * sizeof(Triple) + a;                // R_A
  n += 2 * (scene * 4 + a) + (static_cast<std::size_t>(o.max_index_cells) + 1) * 4 + a;  // scene index
  n += scene * 4 + a + kMaxTouched * 4 + a;                                      // order, touched A
  n += static_cast<std::size_t>(o.num_workers) *
       (o.max_batch * sizeof(InsertRecord) + a + o.collect_capacity * sizeof(Hypothesis<D>) + a);
  return n + o.collect_capacity * sizeof(Hypothesis<D>) + a;                     // merged
}

template <int D>
Status Matcher<D>::init(const MatcherOptions& options, StartupArena& arena, WorkerPool* pool, StartupArena* work) {
  if (options.num_workers < 1 || options.num_workers > kMaxLogicalWorkers) {
    return Status::error(Errc::kInvalidArgument, "pransam options: num_workers %d outside [1, %d]",
                         options.num_workers, kMaxLogicalWorkers);
  }
  if (options.max_scene_points < 3 || options.max_model_points < 3 || options.max_batch < 1 ||
      options.collect_capacity < 1) {
    return Status::error(Errc::kInvalidArgument,
                         "pransam options: max_scene_points/max_model_points must be >= 3, max_batch and "
                         "collect_capacity >= 1");
  }
  options_ = options;
  pool_ = pool;
  // The same order of allocations as with one arena, so a single localizer's layout is unchanged.
  StartupArena& wk = work != nullptr ? *work : arena;
  FW_RETURN_IF_ERROR(table_a_.allocate(wk, D == 2 ? "R_A (2d)" : "R_A (3d)"));
  if (options.allocate_model_table) FW_RETURN_IF_ERROR(table_b_.allocate(arena, D == 2 ? "R_B (2d)" : "R_B (3d)"));
  FW_RETURN_IF_ERROR(field_.init(options.field, arena));
  FW_RETURN_IF_ERROR(index_a_.init(options.max_scene_points, options.max_index_cells, wk, "scene index"));
  FW_RETURN_IF_ERROR(index_b_.init(options.max_model_points, options.max_index_cells, arena, "model index"));
  Result<std::uint32_t*> order = wk.allocate_array<std::uint32_t>(options.max_scene_points, "pransam order");
  if (!order) return order.status();
  scene_order_ = *order;
  Result<std::uint32_t*> ta = wk.allocate_array<std::uint32_t>(kMaxTouched, "pransam touched A");
  Result<std::uint32_t*> tb = arena.allocate_array<std::uint32_t>(kMaxTouched, "pransam touched B");
  if (!ta) return ta.status();
  if (!tb) return tb.status();
  touched_[0] = *ta;
  touched_[1] = *tb;
  // The worker states hold pointers into the buffers: they belong to this matcher (the arena).
  Result<WorkerState*> ws = arena.allocate_array<WorkerState>(static_cast<std::size_t>(options.num_workers),
                                                              "pransam workers");
  if (!ws) return ws.status();
  workers_ = *ws;
  for (int w = 0; w < options.num_workers; ++w) {
    Result<InsertRecord*> ins = wk.allocate_array<InsertRecord>(options.max_batch, "pransam inserts");
    Result<Hypothesis<D>*> col = wk.allocate_array<Hypothesis<D>>(options.collect_capacity, "pransam collected");
    if (!ins) return ins.status();
    if (!col) return col.status();
    workers_[w].inserts = *ins;
    workers_[w].collected = *col;
  }
  Result<Hypothesis<D>*> merged = wk.allocate_array<Hypothesis<D>>(options.collect_capacity, "pransam merged");
  if (!merged) return merged.status();
  merged_ = *merged;
  const std::size_t per_worker = sizeof(WorkerState) + options.max_batch * sizeof(InsertRecord) +
                                 options.collect_capacity * sizeof(Hypothesis<D>);
  FW_RETURN_IF_ERROR(MemoryReport::instance().add(
      {module_name<D>(), "workers+hypotheses",
       per_worker * static_cast<std::size_t>(options.num_workers) + options.collect_capacity * sizeof(Hypothesis<D>) +
           2 * kMaxTouched * 4 + options.max_scene_points * 4,
       options.collect_capacity, nullptr}));
  initialized_ = true;
  return Status::ok();
}

template <int D>
Status Matcher<D>::set_model(const Point<D>* points, std::size_t n, const char* name) {
  if (!initialized_) return Status::error(Errc::kNotInitialized, "pransam: set_model('%s') before init", name);
  model_ = nullptr;
  model_n_ = 0;
  precomputed_ = false;
  if (points == nullptr || n < 3) {
    return Status::error(Errc::kInvalidArgument, "pransam model '%s': %zu points (need >= 3)", name,
                         points == nullptr ? std::size_t(0) : n);
  }
  if (n > options_.max_model_points) {
    return Status::error(Errc::kCapacityExceeded, "pransam model '%s': %zu points > capacity %u", name, n,
                         options_.max_model_points);
  }
  std::size_t bad = 0;
  if (!all_finite<D>(points, n, &bad)) {
    return Status::error(Errc::kInvalidArgument, "pransam model '%s': point %zu is not finite", name, bad);
  }
  FW_RETURN_IF_ERROR(field_.build(points, n, name));
  model_min_ = points[0];
  model_max_ = points[0];
  for (std::size_t i = 1; i < n; ++i) {
    model_min_ = model_min_.cwiseMin(points[i]);
    model_max_ = model_max_.cwiseMax(points[i]);
  }
  model_ = points;
  model_n_ = static_cast<std::uint32_t>(n);
  model_index_extent_ = -1.0f;
  if (table_b_.valid()) table_b_.clear();
  touched_n_[1] = 0;
  touched_overflow_[1] = false;
  return Status::ok();
}

template <int D>
Status Matcher<D>::use_precomputed_table(const Triple* slots, float extent, const char* name) {
  if (model_ == nullptr) return Status::error(Errc::kNotInitialized, "%s: set_model() first", name);
  if (slots == nullptr || !(extent > 0.0f) || !std::isfinite(extent)) {
    return Status::error(Errc::kInvalidArgument, "%s: no slots or extent %g not positive", name,
                         static_cast<double>(extent));
  }
  // Every stored index must address the model set (a corrupt section must not read out of bounds).
  std::size_t filled = 0;
  for (std::size_t s = 0; s < kNumSlots; ++s) {
    if (slots[s].empty()) continue;
    for (int k = 0; k < 3; ++k) {
      if (slots[s].v[k] >= model_n_) {
        return Status::error(Errc::kCorruptData, "%s: slot %zu refers to point %u but the model has %u points", name,
                             s, slots[s].v[k], model_n_);
      }
    }
    ++filled;
  }
  if (filled == 0) return Status::error(Errc::kInvalidArgument, "%s: table is empty", name);
  if (slots == table_b_.data()) {
    table_b_.set_extent(extent);
    model_table_ = &table_b_;
  } else {
    precomp_table_.attach_read_only(slots, extent);
    model_table_ = &precomp_table_;
  }
  precomputed_ = true;
  return Status::ok();
}

template <int D>
Status Matcher<D>::fill_model_table(std::uint64_t seed, std::uint64_t triples, float extent, float min_height_ratio) {
  if (model_ == nullptr) return Status::error(Errc::kNotInitialized, "pransam fill: set_model() first");
  if (!table_b_.valid()) {
    return Status::error(Errc::kNotInitialized, "pransam fill: R_B not allocated (allocate_model_table = false)");
  }
  if (!(extent > 0.0f) || triples == 0) {
    return Status::error(Errc::kInvalidArgument, "pransam fill: extent %g and triples %llu must be positive",
                         static_cast<double>(extent), static_cast<unsigned long long>(triples));
  }
  FW_RETURN_IF_ERROR(index_b_.build(model_, model_n_, extent, "model index"));
  model_index_extent_ = extent;
  precomputed_ = false;
  table_b_.clear();
  table_b_.set_extent(extent);
  touched_overflow_[1] = true;  // an online match afterwards must clear the whole table
  const TripleFilter filter{extent, min_height_ratio, 0.0f};
  RandomStream rng(seed, kFillStream);
  std::uint64_t keyed = 0, draws = 0;
  // The work is bounded by what the map can give: at most kFillDrawsPerTriple draws per wanted
  // triple, and the fill gives up as soon as it is statistically behind the pace that cap needs
  // (a map with a handful of occupied cells keys no triple at all; it used to spin through all
  // 400 million draws of a 2-million-triple table at start-up).
  const std::uint64_t max_draws = triples * kFillDrawsPerTriple + kFillMinDraws;
  bool hopeless = false;
  while (keyed < triples && draws < max_draws) {
    ++draws;
    if ((draws & (kFillCheckEvery - 1)) == 0 && fill_behind_pace(keyed, draws, triples, max_draws)) {
      hopeless = true;
      break;
    }
    Triple t;
    if (!index_b_.draw(rng, &t)) continue;
    std::uint32_t slot;
    if (key_triple<D>(model_, filter, &t, &slot) != KeyResult::kOk) continue;
    table_b_.insert(slot, t);
    ++keyed;
  }
  if (keyed < triples) {
    if (keyed == 0) {
      return Status::error(Errc::kNumerical,
                           "pransam fill: map has too few occupied points for a relation table: no keyable triple "
                           "after %llu draws over %u points (extent %.1f m)",
                           static_cast<unsigned long long>(draws), model_n_, static_cast<double>(extent));
    }
    return Status::error(Errc::kNumerical,
                         "pransam fill: only %llu of %llu triples keyable after %llu draws over %u points%s",
                         static_cast<unsigned long long>(keyed), static_cast<unsigned long long>(triples),
                         static_cast<unsigned long long>(draws), model_n_,
                         hopeless ? " (keyable rate too low for the draw cap; gave up early)" : "");
  }
  return Status::ok();
}

template <int D>
void Matcher<D>::reset() {
  if (!initialized_) return;
  // R_A is only written online; R_B only when it is not the (read-only or start-up) model table.
  reset_online_table(0);
  if (!precomputed_) reset_online_table(1);
  for (int w = 0; w < options_.num_workers; ++w) {
    WorkerState& st = workers_[w];
    st.rng.reseed(0, 0);
    st.num_inserts = 0;
    st.num_collected = 0;
    st.dropped = 0;
    st.best = Hypothesis<D>{};
    st.best_valid = false;
    st.reached = false;
    st.batch = 0;
    st.first_iteration = 0;
    st.stats = MatchStats{};
  }
  scene_ = nullptr;
  scene_n_ = 0;
  params_ = MatchParams{};
  filter_ = TripleFilter{};
  num_workers_ = 0;
  tau_ = 0;
  round_bound_ = 0.0f;
}

// Inputs match() cannot work with, in the order they are reported.
template <int D>
Status Matcher<D>::check_match_input(const Point<D>* scene, std::size_t n, const MatchParams& params) const {
  if (!initialized_) return Status::error(Errc::kNotInitialized, "pransam match: matcher not initialised");
  if (model_ == nullptr) return Status::error(Errc::kNotInitialized, "pransam match: no model set (set_model)");
  if (((params.refine_iterations > 0 && refine_fn_ == nullptr) || params.scene_origin_is_sensor) &&
      !field_.has_distance()) {
    return Status::error(Errc::kInvalidArgument,
                         "pransam match: refinement / free-space test need the distance field "
                         "(ContactFieldOptions.keep_distance = false)");
  }
  if (scene == nullptr || n < 3) {
    return Status::error(Errc::kInvalidArgument, "pransam scene: %zu points (need >= 3)",
                         scene == nullptr ? std::size_t(0) : n);
  }
  if (n > options_.max_scene_points) {
    return Status::error(Errc::kCapacityExceeded, "pransam scene: %zu points > capacity %u", n,
                         options_.max_scene_points);
  }
  std::size_t bad = 0;
  if (!all_finite<D>(scene, n, &bad)) {
    return Status::error(Errc::kInvalidArgument, "pransam scene: point %zu is not finite", bad);
  }
  if (!(params.omega_thres >= 0.0f && params.omega_thres <= 1.0f) || params.max_iterations == 0 ||
      params.first_batch == 0) {
    return Status::error(Errc::kInvalidArgument,
                         "pransam params: omega_thres %g outside [0,1], or max_iterations/first_batch zero",
                         static_cast<double>(params.omega_thres));
  }
  return Status::ok();
}

// Online matching fills R_B as it goes and needs workers on both sides of τ (Theorem 1).
template <int D>
Status Matcher<D>::check_online_workers(int T, int tau) const {
  if (precomputed_) return Status::ok();
  if (!table_b_.valid()) {
    return Status::error(Errc::kNotInitialized, "pransam match: no precomputed table and R_B not allocated");
  }
  if (T < 2 || tau < 1 || tau > T - 1) {
    return Status::error(Errc::kInvalidArgument,
                         "pransam params: online matching needs T >= 2 and 1 <= tau <= T-1 (T %d, tau %d)", T, tau);
  }
  return Status::ok();
}

// Extent of the relation tables: the precomputed table's, the caller's, or from the sets' diameters.
template <int D>
Status Matcher<D>::choose_extent(const Point<D>* scene, std::size_t n, const MatchParams& params,
                                 float* extent_out) const {
  Point<D> lo = scene[0], hi = scene[0];
  for (std::size_t i = 1; i < n; ++i) {
    lo = lo.cwiseMin(scene[i]);
    hi = hi.cwiseMax(scene[i]);
  }
  float extent;
  if (precomputed_) {
    extent = model_table_->extent();
  } else if (params.extent > 0.0f) {
    extent = params.extent;
  } else {
    // Sides longer than the smaller set's diameter can never correspond.
    extent = (hi - lo).norm();
    const float db = (model_max_ - model_min_).norm();
    if (db < extent) extent = db;
    if (params.max_extent > 0.0f && params.max_extent < extent) extent = params.max_extent;
    extent *= 1.001f;
  }
  if (!(extent > 0.0f)) return Status::error(Errc::kInvalidArgument, "pransam scene: all points coincide");
  *extent_out = extent;
  return Status::ok();
}

// Per-match state read by the workers, the scene index and, online, empty tables at this extent.
template <int D>
Status Matcher<D>::prepare_match(const Point<D>* scene, std::size_t n, const MatchParams& params, int tau,
                                 float extent) {
  const int T = options_.num_workers;
  scene_ = scene;
  scene_n_ = static_cast<std::uint32_t>(n);
  params_ = params;
  num_workers_ = T;
  tau_ = precomputed_ ? T : tau;
  filter_ = TripleFilter{extent, params.min_height_ratio, 0.0f};
  FW_RETURN_IF_ERROR(index_a_.build(scene, scene_n_, extent, "scene"));
  if (!precomputed_) {
    reset_online_table(0);
    reset_online_table(1);
    table_a_.set_extent(extent);
    table_b_.set_extent(extent);
    if (model_index_extent_ != extent) {
      FW_RETURN_IF_ERROR(index_b_.build(model_, model_n_, extent, "model index"));
      model_index_extent_ = extent;
    }
    model_table_ = &table_b_;
  }
  return Status::ok();
}

// Worker w draws from RandomStream(seed, w): the same seed and T give the same hypotheses.
template <int D>
void Matcher<D>::seed_workers(std::uint64_t seed) {
  const int T = options_.num_workers;
  for (int w = 0; w < T; ++w) {
    workers_[w].rng.reseed(seed, static_cast<std::uint64_t>(w));
    workers_[w].stats = MatchStats{};
    workers_[w].dropped = 0;
  }
}

// Rounds until I_max iterations, a worker reaching Ω_thres, or (deadline mode) the deadline; the
// batch per worker doubles every round up to max_batch.
template <int D>
auto Matcher<D>::run_rounds(const MatchParams& params, MatchResult<D>* out) -> RoundTally {
  const int T = options_.num_workers;
  RoundTally tally;
  round_bound_ = 0.0f;
  std::uint64_t done = 0;
  std::uint32_t batch = params.first_batch < options_.max_batch ? params.first_batch : options_.max_batch;
  const bool deadline_mode = params.clock != nullptr && params.deadline_ns != 0;
  std::uint64_t last_round_ns = 0, last_round_total = 0;
  while (done < params.max_iterations && !tally.reached) {
    const std::uint64_t remaining = params.max_iterations - done;
    const std::uint64_t round_total = remaining < static_cast<std::uint64_t>(batch) * static_cast<std::uint64_t>(T)
                                          ? remaining
                                          : static_cast<std::uint64_t>(batch) * static_cast<std::uint64_t>(T);
    std::uint64_t round_start = 0;
    if (params.stop_after_rounds != 0 && tally.rounds >= params.stop_after_rounds) {
      tally.deadline_hit = true;
      break;
    }
    if (deadline_mode) {
      round_start = params.clock->now_ns();
      if (tally.rounds > 0 &&
          next_round_misses_deadline(round_start, params.deadline_ns, last_round_ns, last_round_total, round_total)) {
        tally.deadline_hit = true;
        break;
      }
    }
    plan_round(round_total, done);
    run_round();
    merge_round(out, &tally);
    if (out->best_valid) round_bound_ = out->best.quality;
    done += round_total;
    ++tally.rounds;
    if (deadline_mode) {
      last_round_ns = params.clock->now_ns() - round_start;
      last_round_total = round_total;
    }
    if (batch < options_.max_batch) batch = batch * 2 < options_.max_batch ? batch * 2 : options_.max_batch;
  }
  return tally;
}

// Worker w takes its contiguous share of the round's iteration numbers.
template <int D>
void Matcher<D>::plan_round(std::uint64_t round_total, std::uint64_t done) {
  const int T = options_.num_workers;
  for (int w = 0; w < T; ++w) {
    std::size_t b, e;
    WorkerPool::partition(static_cast<std::size_t>(round_total), w, T, &b, &e);
    workers_[w].batch = static_cast<std::uint32_t>(e - b);
    workers_[w].first_iteration = done + b;
  }
}

// The workers' batches, then (online) their buffered inserts after the barrier.
template <int D>
void Matcher<D>::run_round() {
  if (pool_ != nullptr && pool_->running()) pool_->run(&Matcher::round_job, this); else round_job(this, 0, 1);
  if (!precomputed_) {
    if (pool_ != nullptr && pool_->running()) pool_->run(&Matcher::apply_job, this); else apply_job(this, 0, 1);
  }
}

// Merge in worker order.
template <int D>
void Matcher<D>::merge_round(MatchResult<D>* out, RoundTally* tally) {
  const int T = options_.num_workers;
  for (int w = 0; w < T; ++w) {
    const WorkerState& st = workers_[w];
    if (st.best_valid && (!out->best_valid || st.best.quality > out->best.quality)) {
      out->best = st.best;
      out->best_valid = true;
    }
    for (std::uint32_t i = 0; i < st.num_collected; ++i) {
      if (tally->merged_n < options_.collect_capacity) {
        merged_[tally->merged_n++] = st.collected[i];
      } else {
        ++tally->dropped;
      }
    }
    tally->reached = tally->reached || st.reached;
  }
}

template <int D>
Status Matcher<D>::match(const Point<D>* scene, std::size_t n, const MatchParams& params, MatchResult<D>* out) {
  if (out == nullptr) return Status::error(Errc::kInvalidArgument, "pransam match: no result object");
  *out = MatchResult<D>{};
  FW_RETURN_IF_ERROR(check_match_input(scene, n, params));
  const int T = options_.num_workers;
  const int tau = params.tau < 0 ? T / 2 : params.tau;
  FW_RETURN_IF_ERROR(check_online_workers(T, tau));
  float extent = 0.0f;
  FW_RETURN_IF_ERROR(choose_extent(scene, n, params, &extent));
  FW_RETURN_IF_ERROR(prepare_match(scene, n, params, tau, extent));
  // A has to contain at least one keyable triple, otherwise no hypothesis can ever exist.
  if (!has_keyable_triple<D>(scene, scene_n_, filter_)) {
    return Status::error(Errc::kInvalidArgument,
                         "pransam scene: no usable triple (%zu points all collinear, coincident or wider than the "
                         "table extent %.2f m)", n, static_cast<double>(extent));
  }
  shuffle_scene_order(scene_order_, scene_n_, params.seed);
  seed_workers(params.seed);
  const RoundTally tally = run_rounds(params, out);
  MatchStats& s = out->stats;
  std::size_t dropped = tally.dropped;
  for (int w = 0; w < T; ++w) {
    add_stats(&s, workers_[w].stats);
    dropped += workers_[w].dropped;
  }
  s.rounds = tally.rounds;
  s.stop = tally.reached        ? StopReason::kThreshold
           : tally.deadline_hit ? StopReason::kDeadline
                                : StopReason::kMaxIterations;
  out->hypotheses = merged_;
  out->num_hypotheses = tally.merged_n;
  out->dropped = dropped;
  out->found = out->best_valid && out->best.quality >= params.omega_thres;
  return Status::ok();
}

template class Matcher<2>;
template class Matcher<3>;

}  // namespace fw::pransam
