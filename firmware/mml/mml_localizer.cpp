#include "firmware/mml/mml_localizer.h"

#include <algorithm>

#include <cmath>

#include "firmware/pransam/relation_table_io.h"

namespace fw {
namespace mml {

Status MmlLocalizerConfig::validate() const {
  FW_RETURN_IF_ERROR(mml.validate());
  FW_RETURN_IF_ERROR(rbsm.validate());
  FW_RETURN_IF_ERROR(local_map.validate());
  FW_RETURN_IF_ERROR(front_end.validate());
  if (mml.max_local_map_points > matcher.max_scene_points) {
    return Status::error(Errc::kInvalidArgument,
                         "MmlLocalizerConfig: mml.max_local_map_points %u > matcher.max_scene_points %u",
                         mml.max_local_map_points, matcher.max_scene_points);
  }
  if (mml.max_hypotheses > matcher.collect_capacity) {
    return Status::error(Errc::kInvalidArgument, "MmlLocalizerConfig: mml.max_hypotheses %u > matcher.collect_capacity %u",
                         mml.max_hypotheses, matcher.collect_capacity);
  }
  return Status::ok();
}

MmlLocalizerConfig default_mml_config() {
  MmlLocalizerConfig c;
  c.local_map.fragment_length_m = 2.0f;
  c.local_map.keep_last = 0;
  c.local_map.point_capacity = 16384;
  c.front_end.scan.max_range = 8.0f;
  c.rbsm.max_range = 8.0f;
  c.matcher.num_workers = 2;
  c.matcher.max_scene_points = 2048;
  c.matcher.collect_capacity = 2048;
  c.match.collect_all = true;
  c.match.fuzzy = true;
  c.match.extrapolate = true;
  return c;
}

Status fill_global_relation_table(const MmlLocalizerConfig& config, pransam::Matcher<2>* matcher) {
  return matcher->fill_model_table(config.mml.seed ^ 0x5eedull, config.mml.table_triples, config.mml.table_extent_m,
                                   config.match.min_height_ratio);
}

namespace {
// pRANSAM's refinement (MatchParams::refine_iterations) on the global map's own distance field:
// the contact field keeps no second copy (fit_contact_field_to_map). Read-only, so the matcher's
// workers may call it concurrently.
bool map_distance_for_refine(const void* ctx, const pransam::Point<2>& p, float* d, pransam::Point<2>* grad) {
  const GlobalMap& m = *static_cast<const GlobalMap*>(ctx);
  float gx = 0.0f, gy = 0.0f;
  const float v = m.distance_bilinear(p(0), p(1), -1.0f, &gx, &gy);
  if (!(v >= 0.0f)) return false;
  *d = v;
  (*grad)(0) = gx;
  (*grad)(1) = gy;
  return true;
}
bool in_unmapped_space(const void* ctx, const pransam::Point<2>& p) {
  return static_cast<const UnmappedSpace*>(ctx)->contains(p(0), p(1));
}
}  // namespace

std::size_t MmlLocalizer::working_bytes(const MmlLocalizerConfig& c) {
  constexpr std::size_t a = 64;  // worst alignment padding per allocation
  std::size_t n = Rbsm::required_arena_bytes(c.rbsm) + c.local_map.point_capacity * sizeof(Point2f) + a;
  n += pransam::Matcher<2>::working_bytes(c.matcher);
  n += c.mml.max_local_map_points * sizeof(Point2f) + a + kMaxHypotheses * sizeof(PoseHypothesis) + a;
  if (c.mml.reduce_observations) {
    n += (c.mml.reduction_max_observations + 2) * std::size_t{c.mml.reduction_observation_points} * sizeof(Point2f) + a;
  }
  return n;
}

Status MmlLocalizer::init(const MmlLocalizerConfig& config, const GlobalMap& map, const std::uint8_t* table_section,
                          std::size_t table_len, StartupArena& arena, WorkerPool* pool, StartupArena* work) {
  FW_RETURN_IF_ERROR(config.validate());
  if (!map.valid() || map.points == nullptr || map.num_points < 3) {
    return Status::error(Errc::kInvalidArgument, "MmlLocalizer: global map is empty (%u occupied points)", map.num_points);
  }
  config_ = config;
  map_ = map;
  FW_RETURN_IF_ERROR(interp_.init(config.mml));
  // Same order of allocations as with one arena: a single localizer's layout is unchanged.
  StartupArena& wk = work != nullptr ? *work : arena;
  FW_RETURN_IF_ERROR(rbsm_.init(config.rbsm, wk, pool));
  FW_RETURN_IF_ERROR(local_map_.init(config.local_map, wk));
  FW_RETURN_IF_ERROR(front_end_.init(config.front_end, &rbsm_, &local_map_));
  pransam::MatcherOptions mo = config.matcher;
  // The model capacity is the map's point count when the map is larger than the default: sized once
  // here, at start-up, from the map the robot is given (a 138 × 84 m building has ~150,000 wall points).
  mo.max_model_points = std::max(mo.max_model_points, map.num_points);
  const bool have_section = config.mml.precomputed_table && table_section != nullptr && table_len > 0;
  mo.allocate_model_table = !have_section;
  FW_RETURN_IF_ERROR(matcher_.init(mo, arena, pool, work));
  FW_RETURN_IF_ERROR(matcher_.set_model(map.points, map.num_points, "global map"));
  matcher_.set_refine_distance(&map_distance_for_refine, &map_);
  if (config.mml.unmapped_space_min_area_m2 > 0.0f) {
    UnmappedSpaceOptions uo;
    uo.min_area_m2 = config.mml.unmapped_space_min_area_m2;
    FW_RETURN_IF_ERROR(unmapped_.build(map, uo, arena));
    if (unmapped_.unmapped_blocks() > 0) matcher_.set_unmapped_space(&in_unmapped_space, &unmapped_);
  }
  if (config.mml.precomputed_table) {
    if (have_section) {
      pransam::RelationTableSection sec;
      FW_RETURN_IF_ERROR(pransam::parse_relation_table_section(table_section, table_len, 2,
                                                               reinterpret_cast<const float*>(map.points),
                                                               map.num_points, &sec, "map image relation table"));
      FW_RETURN_IF_ERROR(matcher_.use_precomputed_table(sec.slots, sec.extent, "map image relation table"));
    } else {
      // No offline table in the image: fill R_B once at start-up (Theorem 2, h triples).
      FW_RETURN_IF_ERROR(fill_global_relation_table(config, &matcher_));
      const pransam::RelationTable& t = matcher_.model_table();
      FW_RETURN_IF_ERROR(matcher_.use_precomputed_table(t.data(), config.mml.table_extent_m, "start-up relation table"));
    }
  }
  scene_capacity_ = config.mml.max_local_map_points;
  Result<Point2f*> sp = wk.allocate_array<Point2f>(scene_capacity_, "mml local map points");
  if (!sp) return sp.status();
  scene_ = *sp;
  Result<PoseHypothesis*> hp = wk.allocate_array<PoseHypothesis>(kMaxHypotheses, "mml hypotheses");
  if (!hp) return hp.status();
  hyps_ = *hp;
  rule_ = ReductionRule(config.mml);
  if (config.mml.reduce_observations) {
    const std::size_t per = config.mml.reduction_observation_points;
    const std::size_t slots = config.mml.reduction_max_observations + 2;
    Result<Point2f*> rp = wk.allocate_array<Point2f>(slots * per, "mml reduced observations");
    if (!rp) return rp.status();
    for (std::size_t i = 0; i < config.mml.reduction_max_observations; ++i) red_[i].pts = *rp + i * per;
    pending_prev_.pts = *rp + (slots - 2) * per;
    pending_cur_.pts = *rp + (slots - 1) * per;
    FW_RETURN_IF_ERROR(MemoryReport::instance().add(
        {"mml", "reduced observations (Eq. 5.28-5.30)", slots * per * sizeof(Point2f), slots, nullptr}));
  }
  FW_RETURN_IF_ERROR(MemoryReport::instance().add({"mml", "interpreter", sizeof(Interpreter), kMaxHypotheses, nullptr}));
  FW_RETURN_IF_ERROR(MemoryReport::instance().add({"mml", "observations", sizeof(observations_), kMaxUnknownWindow, nullptr}));
  initialized_ = true;
  reset();
  return Status::ok();
}

// Back to exactly the state after init(): a trial's result must not depend on the trials before
// it. The front end resets RBSM (streams reseeded, end-point window un-centred) and the local map;
// the matcher drops its online tables; everything this object keeps between steps is cleared here,
// counters included (they describe the run since the last reset).
void MmlLocalizer::reset() {
  front_end_.reset();
  matcher_.reset();
  interp_.reset();
  observations_.clear();
  last_ = InterpretResult();
  num_scene_ = 0;
  matched_points_ = 0;
  num_scan_pts_ = 0;
  have_h_ = false;
  last_h_ = Se2f();
  steps_ = 0;
  front_end_failures_ = 0;
  no_match_steps_ = 0;
  have_wheel_ = false;
  prev_wheel_ = Se2f();
  tracked_valid_ = false;
  tracked_pose_ = Se2f();
  tracked_bad_steps_ = tracked_unlocalized_steps_ = 0;
  last_refine_ = RefineResult();
  last_unique_ = UniquenessResult();
  unique_rejections_ = 0;
  rivals_.reset();
  last_rival_ = RivalCheck();
  rival_rejections_ = 0;
  pending_ = false;
  pending_h_ = Se2f();
  pending_cov_ = Eigen::Matrix3f::Identity();
  pending_steps_ = pending_isolations_ = 0;
  last_out_ = hal::PoseEstimate();
  have_newest_ = false;
  newest_id_ = 0;
  corrections_applied_ = 0;
  last_correction_ = CorrectionResult();
  rule_ = ReductionRule(config_.mml);
  red_head_ = red_count_ = 0;
  for (ReducedObservation& r : red_) r.fragment_id = r.n = 0;
  // step() swaps the two pending buffers every step: put them back in init()'s order.
  if (pending_cur_.pts != nullptr && pending_cur_.pts < pending_prev_.pts) {
    Point2f* const t = pending_prev_.pts;
    pending_prev_.pts = pending_cur_.pts;
    pending_cur_.pts = t;
  }
  pending_prev_.fragment_id = pending_prev_.n = 0;
  pending_cur_.fragment_id = pending_cur_.n = 0;
  have_prev_obs_ = have_cur_obs_ = false;
  observations_accepted_ = 0;
  localized_prev_ = localized_before_prev_ = false;
}

namespace {
bool is_identity(const Se2f& t) { return t.x == 0.0f && t.y == 0.0f && t.theta == 0.0f; }
}  // namespace

// The robot pose in the corrected local map: the newest fragment's correction T_N as a transform
// of the local map, C_N = (F_N ⊕ T_N) ⊖ F_N, applied to the RBSM pose.
Se2f MmlLocalizer::corrected_pose(const Se2f& rbsm_pose) const {
  if (local_map_.num_fragments() == 0) return rbsm_pose;
  const FragmentView v = local_map_.fragment(local_map_.num_fragments() - 1);
  // Uncorrected: exactly the RBSM pose (no rounding, so MML behaves bit-identically until the
  // first correction).
  if (is_identity(v.correction)) return rbsm_pose;
  return v.frame.compose(v.scan_matcher_frame.inverse()).compose(rbsm_pose);
}

void MmlLocalizer::capture_observation(const Se2f& rbsm_pose) {
  have_cur_obs_ = false;
  if (num_scan_pts_ == 0 || local_map_.num_fragments() == 0) return;
  const FragmentView v = local_map_.fragment(local_map_.num_fragments() - 1);
  // Stored in the newest fragment's (scan-matcher) frame, like the fragment's own points, so a
  // correction of that fragment moves the observation with it.
  const Se2f frag_from_sensor = v.scan_matcher_frame.inverse().compose(rbsm_pose);
  const std::size_t cap = config_.mml.reduction_observation_points;
  const std::size_t stride = (num_scan_pts_ + cap - 1) / cap;
  pending_cur_.fragment_id = v.id;
  pending_cur_.n = 0;
  for (std::size_t i = 0; i < num_scan_pts_ && pending_cur_.n < cap; i += stride) {
    pending_cur_.pts[pending_cur_.n++] = frag_from_sensor.transform_point(scan_pts_[i]);
  }
  have_cur_obs_ = pending_cur_.n > 0;
}

void MmlLocalizer::accept_observation(const ReducedObservation& ob) {
  const std::size_t cap = config_.mml.reduction_max_observations;
  if (red_count_ == cap) {  // full: the oldest accepted observation goes
    red_head_ = (red_head_ + 1) % cap;
    --red_count_;
  }
  ReducedObservation& dst = red_[(red_head_ + red_count_) % cap];
  dst.fragment_id = ob.fragment_id;
  dst.n = ob.n;
  for (std::uint32_t i = 0; i < ob.n; ++i) dst.pts[i] = ob.pts[i];
  ++red_count_;
  ++observations_accepted_;
}

void MmlLocalizer::append_observation(const ReducedObservation& ob, std::size_t stride, std::size_t* k) {
  std::size_t fi = 0;
  if (!local_map_.find_fragment(ob.fragment_id, &fi)) return;  // its fragment was dropped (keep_last)
  const Se2f frame = local_map_.fragment(fi).frame;
  for (std::uint32_t i = 0; i < ob.n; ++i, ++*k) {
    if (*k % stride != 0 || num_scene_ >= scene_capacity_) continue;
    scene_[num_scene_++] = frame.transform_point(ob.pts[i]);
  }
}

// Eq. 5.28–5.30: the reduced local map = accepted observations + the undecided t−1 and t.
Status MmlLocalizer::gather_reduced_map() {
  const std::size_t cap = config_.mml.reduction_max_observations;
  // Observations of dropped fragments are gone for good (ids grow along the ring).
  while (red_count_ > 0) {
    std::size_t fi = 0;
    if (local_map_.find_fragment(red_[red_head_].fragment_id, &fi)) break;
    red_head_ = (red_head_ + 1) % cap;
    --red_count_;
  }
  std::size_t total = 0;
  for (std::size_t i = 0; i < red_count_; ++i) total += red_[(red_head_ + i) % cap].n;
  if (have_prev_obs_) total += pending_prev_.n;
  if (have_cur_obs_) total += pending_cur_.n;
  const std::size_t stride = total > scene_capacity_ ? (total + scene_capacity_ - 1) / scene_capacity_ : 1;
  num_scene_ = 0;
  std::size_t k = 0;
  for (std::size_t i = 0; i < red_count_; ++i) append_observation(red_[(red_head_ + i) % cap], stride, &k);
  if (have_prev_obs_) append_observation(pending_prev_, stride, &k);
  if (have_cur_obs_) append_observation(pending_cur_, stride, &k);
  return Status::ok();
}

// Eq. 5.23–5.27: move the newest fragments onto the global map under H_best. Only in a step that
// ends `localized` (all checks of this step passed, including the pose refiner's) and whose best
// cluster passes the rating test (r > δ_r, ≥ min_cluster_hypotheses members): a correction under
// a merely well-rated cluster made wrong clusters self-consistent on fr-clinic (a false
// `localized` 108 m off), so the correction keeps a confirmed pose's local map consistent and
// never takes part in deciding which pose it is. H_best = the best-quality hypothesis of that cluster.
void MmlLocalizer::correct_local_map(const Se2f& mml_pose) {
  const MmlOptions& mo = config_.mml;
  if (last_.status != hal::LocalizationStatus::kLocalized || !last_.c_rating || interp_.cluster_count() == 0 ||
      local_map_.num_fragments() == 0) {
    return;
  }
  const Cluster* cl = interp_.clusters();
  std::size_t best = 0;
  for (std::size_t i = 1; i < interp_.cluster_count(); ++i)
    if (cl[i].rating > cl[best].rating) best = i;
  if (cl[best].end <= cl[best].begin) return;
  const PoseHypothesis* hy = interp_.hypotheses();
  std::uint32_t bh = cl[best].begin;
  for (std::uint32_t i = cl[best].begin; i < cl[best].end; ++i)
    if (hy[i].quality > hy[bh].quality) bh = i;
  // Hypotheses are robot poses H ⊕ x_local, so H_best = robot ⊖ x_local.
  const Se2f h_best = Se2f(hy[bh].x, hy[bh].y, hy[bh].theta).compose(mml_pose.inverse());
  CorrectionParams cp;
  cp.iterations = mo.correction_iterations;
  cp.step = mo.correction_step;
  cp.clip_m = mo.correction_clip_m;
  cp.max_shift_m = mo.correction_max_shift_m;
  cp.max_rotation_rad = mo.correction_max_rotation_rad;
  const std::size_t nf = local_map_.num_fragments();
  const std::size_t first = nf > mo.correction_fragments ? nf - mo.correction_fragments : 0;
  for (std::size_t f = first; f < nf; ++f) {
    const FragmentView v = local_map_.fragment(f);
    if (v.size() < mo.correction_min_points) continue;
    const std::size_t stride = (v.size() + mo.correction_points - 1) / mo.correction_points;
    std::size_t m = 0;
    for (std::size_t i = 0; i < v.size() && m < mo.correction_points; i += stride) corr_pts_[m++] = v[i];
    last_correction_ = correct_fragment(map_, h_best.compose(v.frame), corr_pts_, m, cp);
    if (last_correction_.applied) {
      if (local_map_.set_correction(f, v.correction.compose(last_correction_.delta)).is_ok()) ++corrections_applied_;
    }
  }
}

Status MmlLocalizer::gather_local_map() {
  const std::size_t total = local_map_.total_points();
  const std::size_t stride = total > scene_capacity_ ? (total + scene_capacity_ - 1) / scene_capacity_ : 1;
  num_scene_ = 0;
  std::size_t k = 0;
  for (std::size_t f = 0; f < local_map_.num_fragments(); ++f) {
    const FragmentView v = local_map_.fragment(f);
    for (std::size_t i = 0; i < v.size(); ++i, ++k) {
      if (k % stride != 0 || num_scene_ >= scene_capacity_) continue;
      scene_[num_scene_++] = v.frame.transform_point(v[i]);
    }
  }
  return Status::ok();
}

// Eq. 5.37: mean contact fraction of the last τ_up observations under H_best.
float MmlLocalizer::unknown_contact(const Se2f& h) const {
  if (observations_.empty()) return 1.0f;
  double sum = 0.0;
  std::size_t used = 0;
  const float eps = config_.mml.contact_distance_m;
  for (std::size_t o = 0; o < observations_.size(); ++o) {
    const Observation& ob = observations_[o];
    if (ob.n == 0) continue;
    std::uint32_t hit = 0;
    for (std::uint32_t i = 0; i < ob.n; ++i) {
      const Point2f p = h.transform_point(ob.pts[i]);
      if (map_.distance_at(p.x(), p.y(), 1e9f) < eps) ++hit;
    }
    sum += static_cast<double>(hit) / ob.n;
    ++used;
  }
  return used > 0 ? static_cast<float>(sum / used) : 1.0f;
}

// One MML step (Fig. 5.5) as named stages: (1) RBSM front end, (2) the observation memory of
// Eq. 5.37, (3) the local map handed to pRANSAM, (4) pRANSAM collect-all against the global map,
// (5) interpretation (Eq. 5.8–5.29, unknown regions), (6) the published pose, (7) publication.
Status MmlLocalizer::step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) {
  const hal::CompleteReasonOnExit reason_on_exit{out};  // every estimate says why it is not `localized`
  if (!initialized_) return Status::error(Errc::kNotInitialized, "MmlLocalizer: step() before init()");
  if (out == nullptr) return Status::error(Errc::kInvalidArgument, "MmlLocalizer: null output");
  if (!std::isfinite(odom.x) || !std::isfinite(odom.y) || !std::isfinite(odom.theta)) {
    return Status::error(Errc::kInvalidArgument, "MmlLocalizer: non-finite odometry at scan %u", scan.scan_id);
  }
  const std::uint64_t step_begin_ns = deadline_clock_ != nullptr ? deadline_clock_->now_ns() : 0;
  last_deadline_rounds_ = 0;
  Se2f rbsm_pose, local_pose;
  bool used = false;
  FW_RETURN_IF_ERROR(front_end_stage(scan, odom, &rbsm_pose, &local_pose, &used));
  if (!used) {
    // A scan RBSM cannot use (e.g. no valid returns in an open space) is bad luck, not a fault:
    // count it and repeat the last estimate; the next good scan continues the local map.
    ++front_end_failures_;
    *out = last_out_;
    out->timestamp_ns = scan.timestamp_ns;
    out->scan_id = scan.scan_id;
    return Status::ok();
  }
  remember_observation(scan, local_pose);
  *out = hal::PoseEstimate();
  out->timestamp_ns = scan.timestamp_ns;
  out->scan_id = scan.scan_id;
  out->mode = hal::LocalizationMode::kGlobal;
  bool enough = false;
  FW_RETURN_IF_ERROR(local_map_stage(rbsm_pose, &enough));
  if (!enough) {
    out->status = hal::LocalizationStatus::kSearching;
    last_out_ = *out;
    return Status::ok();
  }
  float omega_thres = 0.0f;
  const std::uint64_t match_begin_ns = deadline_clock_ != nullptr ? deadline_clock_->now_ns() : 0;
  if (deadline_clock_ != nullptr) perf_front_end_.add_ns(match_begin_ns - step_begin_ns);
  const std::size_t nh = global_match_stage(local_pose, step_begin_ns, &omega_thres);
  const std::uint64_t match_end_ns = deadline_clock_ != nullptr ? deadline_clock_->now_ns() : 0;
  if (deadline_clock_ != nullptr) perf_match_.add_ns(match_end_ns - match_begin_ns);
  const Se2f wheel(odom.x, odom.y, odom.theta);
  // x_r of Eq. 5.8 from the wheel odometry (thesis); the RBSM pose can slip in corridors.
  const Se2f odom_delta = have_wheel_ ? prev_wheel_.between(wheel) : Se2f();
  FW_RETURN_IF_ERROR(interpretation_stage(nh, omega_thres, odom_delta));
  if (config_.mml.rival_memory) rivals_.observe(interp_.clusters(), interp_.cluster_count(), local_pose, config_.mml, steps_);
  published_pose_stage(odom_delta, local_pose);
  prev_wheel_ = wheel;
  have_wheel_ = true;
  if (config_.mml.correct_local_map) correct_local_map(local_pose);
  publish(out);
  if (deadline_clock_ != nullptr) perf_after_match_.add_ns(deadline_clock_->now_ns() - match_end_ns);
  return Status::ok();
}

// (1) RBSM: scan → local map. `local_pose` is the RBSM pose with the local map's correction;
// `used` = false when RBSM could not use the scan.
Status MmlLocalizer::front_end_stage(const hal::LaserScan& scan, const hal::Odometry& odom, Se2f* rbsm_pose,
                                     Se2f* local_pose, bool* used) {
  *used = front_end_.step(scan, odom, local_pose).is_ok();
  if (!*used) return Status::ok();
  ++steps_;
  matched_points_ = 0;
  *rbsm_pose = *local_pose;
  if (config_.mml.correct_local_map && local_map_.num_fragments() > 0) {
    // A new fragment inherits its predecessor's correction (as a local-map transform): RBSM's
    // drift is continuous, so the new fragment starts where the corrected map continues.
    const std::size_t nf = local_map_.num_fragments();
    const FragmentView v = local_map_.fragment(nf - 1);
    if ((!have_newest_ || v.id != newest_id_) && nf >= 2 && !is_identity(local_map_.fragment(nf - 2).correction)) {
      const FragmentView p = local_map_.fragment(nf - 2);
      const Se2f c_prev = p.frame.compose(p.scan_matcher_frame.inverse());
      FW_RETURN_IF_ERROR(local_map_.set_correction(nf - 1, v.scan_matcher_frame.inverse().compose(c_prev).compose(v.scan_matcher_frame)));
    }
    have_newest_ = true;
    newest_id_ = v.id;
    *local_pose = corrected_pose(*rbsm_pose);
  }
  return Status::ok();
}

// (2) A subsample of this observation (local frame) for Eq. 5.37, and the scan's end-points for
// the published-pose refinement.
void MmlLocalizer::remember_observation(const hal::LaserScan& scan, const Se2f& local_pose) {
  ScanPointsResult sr;
  ScanPointsOptions so = config_.front_end.scan;
  num_scan_pts_ = 0;
  if (!scan_to_points(scan, so, scan_pts_, hal::LaserScan::kMaxBeams, &sr).is_ok() || sr.count == 0) return;
  num_scan_pts_ = sr.count;
  Observation ob;
  const std::size_t stride = (sr.count + kUnknownPointsPerObservation - 1) / kUnknownPointsPerObservation;
  for (std::size_t i = 0; i < sr.count && ob.n < kUnknownPointsPerObservation; i += stride) {
    ob.pts[ob.n++] = local_pose.transform_point(scan_pts_[i]);
  }
  if (observations_.size() >= config_.mml.tau_up) { Observation d; observations_.pop(&d); }
  observations_.push_overwrite(ob);
}

// (3) The scene pRANSAM matches: the whole local map, or the information-rich observations
// (Sec. 5.4). `enough` = the local map is large enough to match (Fig. 5.5, t = 0).
Status MmlLocalizer::local_map_stage(const Se2f& rbsm_pose, bool* enough) {
  if (config_.mml.reduce_observations) {
    capture_observation(rbsm_pose);
    if (local_map_.total_points() < config_.mml.min_local_map_points) {
      // Before matching starts (t = 0 of Fig. 5.5) every observation is kept: the first one is
      // needed to rule out hypotheses the later, informative ones leave open.
      if (have_cur_obs_) accept_observation(pending_cur_);
      have_cur_obs_ = have_prev_obs_ = false;
      rule_.reset();
    }
    FW_RETURN_IF_ERROR(gather_reduced_map());
  } else {
    FW_RETURN_IF_ERROR(gather_local_map());
  }
  *enough = local_map_.total_points() >= config_.mml.min_local_map_points && num_scene_ >= 3;
  return Status::ok();
}

// (4) pRANSAM collect-all against the global map at the adaptive threshold (Sec. 5.3.3); the
// hypotheses as robot poses in hyps_. Returns their number. A failed match (e.g. all triples of a
// degenerate local map rejected) is "no hypotheses".
std::size_t MmlLocalizer::global_match_stage(const Se2f& local_pose, std::uint64_t step_begin_ns,
                                             float* omega_thres) {
  pransam::MatchParams mp = config_.match;
  mp.collect_all = true;
  mp.max_iterations = config_.mml.matching_iterations;
  mp.omega_thres = interp_.omega_thres();
  *omega_thres = mp.omega_thres;
  // Refinement (mml_track_preset) only for the hypotheses a few hundredths short of this step's
  // threshold, not for everything above the floor when the threshold is high (mit-killian's
  // corridors: the global step's p99 8.8 → 32.6 ms refining from the floor).
  mp.refine_min_quality = std::fmax(config_.match.refine_min_quality, mp.omega_thres - config_.mml.refine_window);
  mp.seed = config_.mml.seed * 1000003ull + steps_;  // a fresh, reproducible stream per step
  pransam::MatchResult<2> mr;
  matched_points_ = num_scene_;
  if (deadline_clock_ != nullptr && deadline_budget_ns_ > 0) {
    mp.clock = deadline_clock_;
    mp.deadline_ns = step_begin_ns + static_cast<std::uint64_t>(static_cast<double>(deadline_budget_ns_) * deadline_share_);
  }
  mp.stop_after_rounds = forced_deadline_rounds_;
  forced_deadline_rounds_ = 0;
  const Status ms = matcher_.match(scene_, num_scene_, mp, &mr);
  if (!ms.is_ok()) return 0;
  if (mr.stats.stop == pransam::StopReason::kDeadline) {
    ++deadline_stops_;
    last_deadline_rounds_ = mr.stats.rounds;
  }
  std::size_t nh = 0;
  Se2f best_h;
  float best_q = -1.0f;
  for (std::size_t i = 0; i < mr.num_hypotheses && nh < config_.mml.max_hypotheses; ++i) {
    const Se2f h = pransam::to_se2(mr.hypotheses[i]);
    const Se2f robot = h.compose(local_pose);
    PoseHypothesis& o = hyps_[nh++];
    o.x = robot.x;
    o.y = robot.y;
    o.theta = robot.theta;
    o.quality = mr.hypotheses[i].quality;
    o.roll = 0.0f;  // flipped 2-D frames are already rejected inside pRANSAM (Eq. 5.3)
    o.pitch = 0.0f;
    if (o.quality > best_q) { best_q = o.quality; best_h = h; }
  }
  if (best_q >= 0.0f) { last_h_ = best_h; have_h_ = true; }
  return nh;
}

// (5) Interpretation of the hypotheses (Eq. 5.8–5.17), the observation-selection rule (Eq. 5.29)
// and the unknown-region test (Eq. 5.37, plus steps without any match).
Status MmlLocalizer::interpretation_stage(std::size_t nh, float omega_thres, const Se2f& odom_delta) {
  InterpretInput in;
  in.hypotheses = hyps_;
  in.count = nh;
  in.have_odom_delta = have_wheel_;
  in.odom_delta = odom_delta;
  FW_RETURN_IF_ERROR(interp_.interpret(in, &last_));
  if (config_.mml.reduce_observations) {
    // Eq. 5.29 on f(t) = |C(t)|: a crossing accepts observation t−1; t becomes the undecided t−1.
    // Extension: nothing is accepted while localized (the pose was known before observation t−1
    // arrived, so it cannot be information-rich about which pose it is); f(t) keeps feeding the rule.
    const bool accept = rule_.push(last_.cluster_count);
    if (accept && have_prev_obs_ && !localized_before_prev_) {
      accept_observation(pending_prev_);
    }
    Point2f* const spare = pending_prev_.pts;
    pending_prev_ = pending_cur_;
    pending_cur_.pts = spare;
    pending_cur_.n = 0;
    have_prev_obs_ = have_cur_obs_;
    have_cur_obs_ = false;
  }
  if (have_h_) {
    interp_.report_unknown(unknown_contact(last_h_), static_cast<std::uint32_t>(observations_.size()), &last_);
  }
  const MmlOptions& mo = config_.mml;
  if (last_.hypotheses_valid == 0 && nh == 0 && omega_thres <= mo.omega_thres_min + 1e-6f &&
      local_map_.total_points() >= 2u * mo.min_local_map_points) {
    ++no_match_steps_;
  } else {
    no_match_steps_ = 0;
  }
  if (mo.detect_unknown && mo.outside_map_no_match_steps > 0 && no_match_steps_ >= mo.outside_map_no_match_steps &&
      last_.status != hal::LocalizationStatus::kLocalized) {
    last_.status = hal::LocalizationStatus::kOutsideMap;
  }
  return Status::ok();
}

// (6) Published pose (pose_refiner.h). Once a `localized` cluster pose is confirmed by refining the
// newest scan against the global map, that pose is tracked with the wheel odometry and refined
// every step; it replaces x_prev of Eq. 5.8, so a cluster that drifts away from it (a slipping
// local map in a corridor) fails Eq. 5.14 instead of dragging the estimate along.
void MmlLocalizer::published_pose_stage(const Se2f& odom_delta, const Se2f& local_pose) {
  const MmlOptions& mo = config_.mml;
  if (!mo.refine_pose || num_scan_pts_ == 0) return;
  const std::size_t stride = (num_scan_pts_ + mo.refine_points - 1) / mo.refine_points;
  std::size_t m = 0;
  for (std::size_t i = 0; i < num_scan_pts_; i += stride) refine_pts_[m++] = scan_pts_[i];
  const RefineOptions ro;
  const bool loc = last_.status == hal::LocalizationStatus::kLocalized;
  if (tracked_valid_ && mo.track_when_localized) {
    const Se2f pred = tracked_pose_.compose(odom_delta);
    last_refine_ = refine_pose(map_, refine_pts_, m, pred, ro);
    tracked_pose_ = last_refine_.pose;  // = pred when rejected
    tracked_bad_steps_ = last_refine_.accepted ? 0 : tracked_bad_steps_ + 1;
    tracked_unlocalized_steps_ = loc ? 0 : tracked_unlocalized_steps_ + 1;
    if (tracked_bad_steps_ >= mo.tracked_max_rejected_steps ||
        tracked_unlocalized_steps_ >= mo.tracked_max_unlocalized_steps ||
        last_.status == hal::LocalizationStatus::kOutsideMap) {
      tracked_valid_ = false;
      // The scans stopped fitting the map around the tracked pose: not sure any more.
      interp_.drop_soft();
      if (last_.status == hal::LocalizationStatus::kLocalized) last_.status = hal::LocalizationStatus::kAmbiguous;
    }
  }
  if (!tracked_valid_ && last_.status == hal::LocalizationStatus::kLocalized) {
    last_refine_ = refine_pose(map_, refine_pts_, m, last_.pose, ro);
    bool unique = true;
    if (last_refine_.accepted && mo.unique_check) {
      unique = refined_pose_unique(refine_pts_, m, ro);
      if (!unique) ++unique_rejections_;
    }
    if (last_refine_.accepted && unique && !isolation_confirmed(local_pose)) {
      unique = false;
      pending_ = !last_rival_.candidate_rejected;
      pending_h_ = last_refine_.pose.compose(local_pose.inverse());
      pending_cov_ = last_.cov;
      pending_steps_ = 0;
    }
    if (last_refine_.accepted && unique) {
      pending_ = false;
      tracked_valid_ = true;
      tracked_pose_ = last_refine_.pose;
      tracked_bad_steps_ = tracked_unlocalized_steps_ = 0;
    } else {
      // The newest scan does not fit the map at the cluster pose, or fits a rival pose along the
      // corridor as well: not sure after all (and no soft rule on the strength of this step).
      last_.status = hal::LocalizationStatus::kAmbiguous;
      interp_.drop_soft();
    }
  } else if (!tracked_valid_ && pending_) {
    recheck_pending(local_pose, refine_pts_, m);
  }
  if (tracked_valid_) {
    interp_.set_previous_pose(tracked_pose_);
    last_.pose = tracked_pose_;
    last_.have_pose = true;
  }
}

// pose_uniqueness.h on the refined pose of this step (last_refine_).
bool MmlLocalizer::refined_pose_unique(const Point2f* pts, std::size_t m, const RefineOptions& ro) {
  const MmlOptions& mo = config_.mml;
  UniquenessOptions uo;
  uo.clip_m = ro.clip_m;
  uo.max_shift_m = mo.unique_max_shift_m;
  uo.shift_step_m = mo.unique_shift_step_m;
  uo.margin = mo.unique_margin;
  last_unique_ = check_pose_uniqueness(map_, pts, m, last_refine_.pose, uo);
  return last_unique_.unique;
}

// A pending candidate (held back only by open rivals): the same checks as at isolation, on this
// step's scan and the grown local map, while MML has nothing better to say (not `localized`, not
// outside the map). Isolated once every rival is contradicted; dropped when a rival fits better,
// when the scan no longer fits it, or after tracked_max_unlocalized_steps steps (the local map's
// drift is bounded only so long).
void MmlLocalizer::recheck_pending(const Se2f& local_pose, const Point2f* pts, std::size_t m) {
  const MmlOptions& mo = config_.mml;
  if (last_.status == hal::LocalizationStatus::kOutsideMap || ++pending_steps_ > mo.tracked_max_unlocalized_steps) {
    pending_ = false;
    return;
  }
  const RefineOptions ro;
  last_refine_ = refine_pose(map_, pts, m, pending_h_.compose(local_pose), ro);
  if (!last_refine_.accepted) {
    pending_ = false;
    return;
  }
  if (mo.unique_check) {
    if (!refined_pose_unique(pts, m, ro)) return;  // still pending: a corridor alias may resolve too
  }
  if (!isolation_confirmed(local_pose)) {
    if (last_rival_.candidate_rejected) pending_ = false;
    return;
  }
  pending_ = false;
  ++pending_isolations_;
  last_.status = hal::LocalizationStatus::kLocalized;
  last_.cov = pending_cov_;
  tracked_valid_ = true;
  tracked_pose_ = last_refine_.pose;
  tracked_bad_steps_ = tracked_unlocalized_steps_ = 0;
}

// Rival memory (rival_memory.h): the refined candidate is isolated only if the local map
// contradicts every remembered rival, not merely because the rivals left this step's clusters.
bool MmlLocalizer::isolation_confirmed(const Se2f& local_pose) {
  if (!config_.mml.rival_memory) return true;
  const Se2f h_best = last_refine_.pose.compose(local_pose.inverse());
  last_rival_ = rivals_.check(map_, scene_, num_scene_, h_best, local_pose, config_.mml);
  if (!last_rival_.resolved) ++rival_rejections_;
  return last_rival_.resolved;
}

// (7) The estimate of this step, remembered for a step the front end cannot use.
void MmlLocalizer::publish(hal::PoseEstimate* out) {
  localized_before_prev_ = localized_prev_;
  localized_prev_ = last_.status == hal::LocalizationStatus::kLocalized;
  out->status = last_.status;
  if (last_.have_pose) {
    out->x = last_.pose.x;
    out->y = last_.pose.y;
    out->theta = last_.pose.theta;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) out->cov[r * 3 + c] = last_.cov(r, c);
  }
  out->hypothesis_count = static_cast<std::uint16_t>(last_.hypotheses_valid > 65535 ? 65535 : last_.hypotheses_valid);
  out->cluster_count = static_cast<std::uint16_t>(last_.cluster_count > 65535 ? 65535 : last_.cluster_count);
  out->rating = last_.best_rating;
  last_out_ = *out;
}

}  // namespace mml
}  // namespace fw
