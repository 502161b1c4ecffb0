// The rounds of pRANSAM's workers (Alg. 2): draw, key, collide in the online tables, rate.
#include "firmware/pransam/matcher.h"

#include <cmath>

namespace fw::pransam {

template <int D>
void Matcher<D>::run_worker(int w) {
  WorkerState& st = workers_[w];
  st.num_inserts = 0;
  st.num_collected = 0;
  st.reached = false;
  st.best_valid = false;
  const bool from_a = precomputed_ || w < tau_;
  const PointIndex<D>& idx = from_a ? index_a_ : index_b_;
  const RelationTable& other = from_a ? *model_table_ : table_a_;
  const bool collect = params_.collect_all;
  const float thres = params_.omega_thres;
  float bound = collect ? thres : round_bound_;
  const std::uint64_t refine_share =
      params_.refine_max_hypotheses == 0
          ? 0
          : (params_.refine_max_hypotheses + static_cast<std::uint64_t>(num_workers_) - 1) / static_cast<std::uint64_t>(num_workers_);
  for (std::uint32_t it = 0; it < st.batch; ++it) {
    ++st.stats.iterations;
    Triple t;
    if (!idx.draw(st.rng, &t)) { ++st.stats.failed_draws; continue; }
    std::uint32_t slot;
    const KeyResult kr = key_triple<D>(idx.points(), filter_, &t, &slot);
    if (kr != KeyResult::kOk) {
      if (kr == KeyResult::kCollinear) ++st.stats.rejected_collinear; else ++st.stats.rejected_size;
      continue;
    }
    ++st.stats.keyed;
    if (!precomputed_) st.inserts[st.num_inserts++] = InsertRecord{slot, t};
    const Triple o = other.at(slot);  // the other table as of the round start (Eq. 4.4)
    if (o.empty()) continue;
    ++st.stats.collisions;
    const Triple& ta = from_a ? t : o;
    const Triple& tb = from_a ? o : t;
    TriangleFrame<D> fa, fb;
    if (!triangle_frame<D>(scene_[ta.v[0]], scene_[ta.v[1]], scene_[ta.v[2]], &fa) ||
        !triangle_frame<D>(model_[tb.v[0]], model_[tb.v[1]], model_[tb.v[2]], &fb)) {
      continue;
    }
    Hypothesis<D> h;
    if (!make_hypothesis<D>(fa, fb, &h)) { ++st.stats.flipped; continue; }  // Eq. 5.3
    h.iteration = static_cast<std::uint32_t>(st.first_iteration + it);
    h.worker = static_cast<std::uint16_t>(w);
    ++st.stats.evaluated;
    bool complete = false;
    const bool refining = params_.refine_iterations > 0 && (refine_share == 0 || st.stats.refined < refine_share);
    const float rate_bound = refining && params_.refine_min_quality < bound ? params_.refine_min_quality : bound;
    float q = rate(h, rate_bound, st.rng.uniform_index(scene_n_), &complete, &st.stats.point_checks);
    if (!complete) { ++st.stats.extrapolation_cut; continue; }
    if (refining && q >= params_.refine_min_quality) {
      refine(&h);
      ++st.stats.refined;
      // Collecting, a refined hypothesis below Ω_thres is dropped anyway: the early stop applies.
      q = rate(h, collect ? thres : 0.0f, 0, &complete, &st.stats.point_checks);
      if (!complete) { ++st.stats.extrapolation_cut; continue; }
    }
    // Free-space gate: 2-D tests what reaches Ω_thres; the 3-D extension tests from
    // free_space_min_quality whatever would become the best (or be collected).
    const bool gate = params_.free_space_min_quality < 0.0f
                          ? q >= thres
                          : q >= params_.free_space_min_quality && (collect ? q >= thres : !st.best_valid || q > st.best.quality) &&
                                (collect || q > round_bound_);
    if (params_.scene_origin_is_sensor && gate && blocked_fraction(h) > params_.max_blocked_fraction) {
      ++st.stats.free_space_rejected;
      continue;  // beams through walls of B: impossible pose whatever Ω says
    }
    h.quality = q;
    if (!st.best_valid || q > st.best.quality) {
      st.best = h;
      st.best_valid = true;
    }
    if (!collect && q > bound) bound = q;
    if (q >= thres) {
      if (collect) {
        if (st.num_collected < options_.collect_capacity) st.collected[st.num_collected++] = h; else ++st.dropped;
      } else {
        st.reached = true;
        break;  // stop criterion Ω ≥ Ω_thres
      }
    }
  }
}

template <int D>
void Matcher<D>::round_job(void* ctx, int pool_index, int pool_size) {
  Matcher* m = static_cast<Matcher*>(ctx);
  for (int w = pool_index; w < m->num_workers_; w += pool_size) m->run_worker(w);
}

template <int D>
void Matcher<D>::apply_job(void* ctx, int pool_index, int pool_size) {
  Matcher* m = static_cast<Matcher*>(ctx);
  for (int table = 0; table < 2; ++table) {
    if (table % pool_size != pool_index) continue;
    RelationTable& rt = table == 0 ? m->table_a_ : m->table_b_;
    const int w0 = table == 0 ? 0 : m->tau_;
    const int w1 = table == 0 ? m->tau_ : m->num_workers_;
    for (int w = w0; w < w1; ++w) {  // worker order: later workers overwrite earlier ones
      const WorkerState& st = m->workers_[w];
      for (std::uint32_t i = 0; i < st.num_inserts; ++i) {
        const std::uint32_t slot = st.inserts[i].slot;
        if (!rt.insert(slot, st.inserts[i].triple)) {
          if (m->touched_n_[table] < kMaxTouched) m->touched_[table][m->touched_n_[table]++] = slot;
          else m->touched_overflow_[table] = true;
        }
      }
    }
  }
}

template <int D>
void Matcher<D>::reset_online_table(int table) {
  RelationTable& rt = table == 0 ? table_a_ : table_b_;
  if (!rt.valid()) return;
  if (touched_overflow_[table]) rt.clear(); else rt.clear_slots(touched_[table], touched_n_[table]);
  touched_n_[table] = 0;
  touched_overflow_[table] = false;
}

template void Matcher<2>::run_worker(int w);
template void Matcher<3>::run_worker(int w);
template void Matcher<2>::round_job(void* ctx, int pool_index, int pool_size);
template void Matcher<3>::round_job(void* ctx, int pool_index, int pool_size);
template void Matcher<2>::apply_job(void* ctx, int pool_index, int pool_size);
template void Matcher<3>::apply_job(void* ctx, int pool_index, int pool_size);
template void Matcher<2>::reset_online_table(int table);
template void Matcher<3>::reset_online_table(int table);

}  // namespace fw::pransam
