// AntSLAM (dissertation Ch. 3, Alg. 3; SPEC §2): global map optimisation by ant colony over a map
// built in fragments.
//
// Input per scan: the front end's pose (RBSM scan-matching odometry, firmware/rbsm) and the scan's
// points in the robot frame. The map is cut into fragments: a new one every fragment_length_m
// travelled; its frame F_i is the pose of its first scan. Every scan is stored relative to its
// fragment's frame, so correcting the fragment frames corrects the trajectory. The pose relative
// to the active fragment is tracked with its covariance (Eq. 3.4: x_t = x_{t−1} ⊕ u_t,
// Σ_t = J_x Σ J_xᵀ + J_u G J_uᵀ); when the fragment ends, that gives the adjacent edge
// T(F_i → F_i+1) ~ N(μ, Σ), holding S sampled options (Eq. 3.10, sampled_edge.h). Σ of an edge
// (adjacent or closing) is fitted from poses around it weighted by the sensor model (Eq. 3.9,
// edge_fit.h; EdgeModel::kSensorModel, the default) or, selectable, the Eq. 3.4 covariance itself
// (kMotionModel; loop closures then take the fixed closure_sigma_*). Either way the Eq. 3.4
// covariance is kept beside it for what it is good at: predicting how far a path of edges may
// have drifted (the loop candidates' Mahalanobis distance and the closure gate).
//
// Loop closing, when a fragment a ends: a breadth-first search over the fragment graph (all edge
// weights 1, so it is Dijkstra's shortest fragment sequence) gives for every older fragment c the
// path L from c to a, the predicted transform x = ⊕ L and its covariance (Eq. 3.4 compounding).
// c is a candidate when the Mahalanobis distance between a's poses (mapped by x) and the nearest
// pose of c is below a threshold; candidates are tried nearest first by matching a's points
// against c's with pRANSAM (firmware/pransam): h ~ N(μ_h, Σ_h), accepted when its quality and its
// Mahalanobis distance to x pass the gates. The loop L is then corrected by the ant colony
// (Eq. 3.13–3.14, ant_colony.h) or Levenberg–Marquardt (loop_lm.h) — options.optimizer — and its
// edges, with the new closing edge, are frozen ("corrected loops are frozen").
// Closures in pairs (AntSlamOptions::pair_closures, an extension; closure_pairs.h,
// closure_isolation.h): a closure that fails the gate is kept for the next pair_window fragments;
// when one of the current fragment's gated-out closures forms a consistent cycle with one of them
// (through the two short chains between them) and both fragments' points fit nowhere else on the
// old map around the candidate as well, the loop is closed with it after all — the front end's
// drift model cannot tell a true closure after a long drifting loop from a corridor's alias, two
// agreeing and isolated closures can.
// At the end of the run (finish(), AntSlamOptions::final_refinement, an extension) the whole graph —
// every adjacent and closing edge, frozen or not — is refined once by least squares (graph_refine.h),
// so a late closure's error is not left on the one or two edges its loop still had free.
//
// Borders and EXPLORE → TRAVERSAL (Sec. 3.4, fragment_borders.h; AntSlamOptions::traversal): a
// fragment is explored (mapped) until fragment_length_m, then a border is cut across the path, its
// convex hull is taken and it turns TRAVERSAL for good. When the loop closed at that moment puts the
// robot inside the closing fragment c (right of c's borders, inside its hull), the robot traverses c
// instead of opening a new fragment: its pose is tracked in F_c (Eq. 3.4), nothing is mapped, and it
// moves on into any fragment joined to the current one by an edge (a measured relation) whose region
// it enters. Leaving into unexplored terrain cuts a new border on the fragment left and opens a new
// fragment from it. Fragments form a tree of entry edges (plus closures), not a chain.
// The pose w.r.t. any fragment with its covariance: pose_in_fragment() (on demand). A traversed
// fragment is entered only through a confirmed closure or a direct edge, not on that pose alone.
//
// Embedded rules: all storage from the StartupArena in init(), sized by AntSlamOptions; errors
// as Status; deterministic per seed (pRANSAM and the ants own their streams; the optional
// WorkerPool does not change results).
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/antslam/ant_colony.h"
#include "firmware/antslam/closure_isolation.h"
#include "firmware/antslam/closure_pairs.h"
#include "firmware/antslam/edge_fit.h"
#include "firmware/antslam/field_fit.h"
#include "firmware/antslam/fragment_borders.h"
#include "firmware/antslam/graph_refine.h"
#include "firmware/antslam/loop_lm.h"
#include "firmware/antslam/sampled_edge.h"
#include "firmware/base/arena.h"
#include "firmware/base/status.h"
#include "firmware/base/worker_pool.h"
#include "firmware/pransam/matcher.h"
#include "firmware/scan/scan_points.h"
#include "hal/clock.h"

namespace fw::antslam {

enum class LoopOptimizer : std::uint8_t { kAntColony, kLevenbergMarquardt };
// Σ of an edge: Eq. 3.9 (sensor-model-weighted poses, edge_fit.h) or Eq. 3.4 (motion model).
enum class EdgeModel : std::uint8_t { kSensorModel, kMotionModel };

struct AntSlamOptions {
  // Capacities (arena).
  std::uint32_t max_scans = 32768;
  std::uint32_t max_fragments = 1024;
  std::uint32_t max_closures = 1024;
  std::uint32_t max_points_per_fragment = 2048;
  std::uint32_t max_keyframes_per_fragment = 128;
  std::uint32_t max_loop_steps = 1024;
  std::uint32_t samples_per_edge = 40;  // S = |T| (Eq. 3.10)

  double fragment_length_m = 5.0;  // thesis: 5 m (10 m for long loops)
  // Eq. 3.4 motion noise G of an increment u: var_xy = a·|u| + floor, var_θ = b·|u| + c·|u_θ| + floor.
  double var_xy_per_m = 0.02 * 0.02;
  double var_theta_per_m = 0.004 * 0.004;
  double var_theta_per_rad = 0.01 * 0.01;
  double var_floor = 1e-8;
  EdgeModel edge_model = EdgeModel::kSensorModel;
  EdgeFitOptions edge_fit;

  // Points kept for matching: a keyframe every keyframe_step_m or keyframe_turn_rad.
  double keyframe_step_m = 0.3;
  double keyframe_turn_rad = 0.3;
  std::uint32_t beam_stride = 2;
  std::uint32_t min_fragment_points = 60;

  // Loop closing.
  std::uint32_t min_fragment_gap = 3;    // c ≤ a − gap
  double overlap_radius_m = 1.5;         // poses this close count as the same place …
  double candidate_mahalanobis = 3.0;    // … and beyond it the Mahalanobis gate
  std::uint32_t max_candidates = 3;      // pRANSAM tries per fragment, nearest first
  float min_closure_quality = 0.55f;     // pRANSAM Ω of the accepted hypothesis
  double closure_gate_chi2 = 16.3;       // (h − x)ᵀ(Σ_x + Σ_h)⁻¹(h − x), 3 dof, 99.9 %
  double closure_sigma_xy = 0.05;        // Σ_h (m)
  double closure_sigma_theta = 0.01745;  // Σ_h (rad)
  double frozen_cov_scale = 0.1;         // a corrected (frozen) edge's covariance in the path prediction
  // Closure refinement (field_fit.h, an addition): pRANSAM's h and the prediction x are both
  // refined on the candidate's distance field; the prediction wins unless h fits better by this.
  bool refine_closure = true;
  std::uint32_t refine_iterations = 15;
  float refine_cutoff_start = 0.5f, refine_cutoff_end = 0.15f;
  float prefer_prediction_margin = -1.0f;  // < 0: always pRANSAM's h (measured on intel: preferring
                                           // the prediction, 0.02, made the long relations worse)
  // Closures confirmed in pairs (closure_pairs.h, an extension of Alg. 3): a closure gated out
  // against the prediction is closed after all when it forms a consistent cycle (closure_gate_chi2)
  // with a gated-out closure of one of the last pair_window active fragments, the candidate
  // fragments at most pair_max_hops apart, and both closures pass the gate in heading alone. The front end's drift model cannot tell a true closure
  // after a long, drifting loop from a corridor's alias; two closures of successive fragments that
  // agree through the short chains between them can.
  bool pair_closures = true;
  std::uint32_t pair_window = 2;
  std::uint32_t pair_max_hops = 4;
  // A pair-confirmed closure must also be isolated on the old map around its candidate
  // (closure_isolation.h): no rival pose of both fragments' points fits as well. The model is the
  // old fragments within isolation.hops of the candidate, at most isolation_max_points points
  // (thinned evenly beyond), on a field of at most isolation_field_cells cells.
  bool pair_isolation = true;
  // Closures that pass the gate must be isolated too, among the rivals the gate also admits
  // (a rival the prediction rules out is no alias); one that is not waits for a pair like a gated-out
  // one. Measured (README, AntSLAM section): Alg. 3's gate alone accepted five alias closures 4–21 m
  // off on mit-killian seed 3; with this test none, on every log and seed checked.
  bool gate_isolation = true;
  IsolationOptions isolation;
  std::uint32_t isolation_max_points = 16384;
  std::size_t isolation_field_cells = std::size_t(1) << 21;
  pransam::MatcherOptions matcher;       // sizes taken from max_points_per_fragment in validate()
  pransam::MatchParams match;

  // Borders, convex hull and EXPLORE → TRAVERSAL (Sec. 3.4; see above). Off (default): every
  // fragment is explored and a revisit opens new fragments that close loops with the old ones —
  // measured better on the CARMEN logs (firmware/antslam/README.md: traversal closes fewer loops).
  bool traversal = false;
  BorderOptions border;
  std::uint32_t max_borders_per_fragment = 8;
  std::uint32_t max_hull_points = 256;
  // While traversing, the scan is fitted on the traversed fragment's distance field every keyframe
  // step (track_in_fragment); off: the pose in the fragment is the front end's increments only.
  // Measured: aces better, intel / fr079 / fr-clinic worse than traversal off (README) — off by default.
  bool traversal_tracking = false;

  LoopOptimizer optimizer = LoopOptimizer::kAntColony;
  AntColonyOptions aco;
  LoopLmOptions lm;
  // Final refinement (graph_refine.h, an extension of Alg. 3): when the run ends (finish()), every
  // fragment frame is refined against every edge at once — the frozen loops included — so the
  // error of a late closure is spread over the whole graph instead of its one or two free edges.
  // On by default (measured 2026-11-29, seed 1, ACO, README AntSLAM section: intel 0.0366 → 0.0253 m,
  // aces 0.165 → 0.147, fr079 0.0449 → 0.0440, mit-killian 0.0587 → 0.0582; fr-clinic 0.359 → 0.379
  // worse). false = Alg. 3 as published (loops corrected and frozen, nothing after).
  bool final_refinement = true;
  GraphRefineOptions graph;
  std::uint64_t seed = 1;
  Status validate() const;
};
// Defaults tuned for the CARMEN logs (pRANSAM parameters for whole fragments).
AntSlamOptions default_antslam_options();

struct AntSlamStats {
  std::uint32_t candidates = 0;        // pRANSAM matches tried
  std::uint32_t rejected_quality = 0;  // best hypothesis below min_closure_quality
  std::uint32_t rejected_gate = 0;     // too far from the prediction
  std::uint32_t prediction_kept = 0;   // refined prediction fitted as well as pRANSAM's h
  std::uint32_t sensor_fits = 0;       // edges whose Σ came from the sensor model (Eq. 3.9)
  std::uint32_t motion_fallbacks = 0;  // edges that kept the Eq. 3.4 Σ (no fit possible: too few points)
  std::uint32_t loops = 0;             // loops closed and corrected
  std::uint32_t pair_loops = 0;        // of them, closed by a consistent pair (closure_pairs.h)
  std::uint32_t pairs_not_isolated = 0;  // consistent pairs refused: a rival fits as well (closure_isolation.h)
  std::uint32_t gated_not_isolated = 0;  // closures within the gate refused: a rival within the gate fits as well
  std::uint32_t dropped_points = 0;    // points beyond a fragment's capacity
  std::uint32_t borders = 0;           // borders cut (each stored on both sides)
  std::uint32_t no_border = 0;         // a fragment left where Eq. 3.7 found no point on one side
  std::uint32_t dropped_borders = 0;   // beyond max_borders_per_fragment
  std::uint32_t no_hull = 0;           // fragments whose hull did not fit max_hull_points (never entered)
  std::uint32_t traversals = 0;        // entries into a TRAVERSAL fragment
  std::uint32_t traversal_scans = 0;   // scans tracked in a TRAVERSAL fragment (not mapped)
  std::uint32_t traversal_fits = 0;    // of them, fitted on the fragment's field and accepted
  double aco_initial_cost = 0, aco_final_cost = 0;  // sums over the loops
  std::uint64_t optimizer_ns = 0;      // time in the loop optimiser (with a clock)
  // Final refinement (final_refinement): W of the whole graph before/after, steps, time.
  double graph_initial_cost = 0, graph_final_cost = 0;
  std::uint32_t graph_iterations = 0, graph_cg_iterations = 0;
  std::uint64_t graph_ns = 0;
  std::uint64_t matcher_ns = 0;        // time in pRANSAM (with a clock)
};

struct ClosureRecord {
  std::uint32_t from = 0, to = 0;  // candidate c, active fragment a
  std::uint32_t path_edges = 0;
  float quality = 0;         // pRANSAM Ω
  float gate_chi2 = 0;       // (h − x)ᵀ(Σ_x + Σ_h)⁻¹(h − x)
  float shift_m = 0;         // |h − x| (translation): how far the loop was open
  float cost_before = 0, cost_after = 0;  // W of the loop (Eq. 3.13) before/after the optimiser
  std::uint32_t pair_with = 0;  // closed by a consistent pair (closure_pairs.h): the other fragment + 1; 0: by the gate
  float pair_chi2 = 0, isolation_z = 0;  // the pair's cycle χ² and the isolation test's z (closure_isolation.h)
};

class AntSlam {
 public:
  static std::size_t required_arena_bytes(const AntSlamOptions& options);
  // `clock` (optional) times the optimiser and pRANSAM; `pool` (optional) runs pRANSAM and the ants.
  Status init(const AntSlamOptions& options, StartupArena& arena, WorkerPool* pool = nullptr,
              const hal::Clock* clock = nullptr);
  const AntSlamOptions& options() const { return options_; }

  // One scan: the front end's pose (world) and the scan's points in the robot frame.
  Status add_scan(const Se2d& frontend_pose, const Point2f* points, std::size_t count);
  // End of the run: tries to close a loop with the last fragment, then (final_refinement) refines
  // every fragment frame against every edge.
  Status finish();
  // The final refinement itself (finish() runs it when final_refinement is on): the fragment frames
  // and every edge's value from the whole graph's least-squares frames (graph_refine.h). A caller
  // that wants Alg. 3's map as well runs finish() with the option off, reads it, then this.
  Status refine_whole_graph();

  std::uint32_t num_scans() const { return num_scans_; }
  std::uint32_t num_fragments() const { return num_fragments_; }
  std::uint32_t num_edges() const { return num_edges_; }
  std::uint32_t num_closures() const { return num_closures_; }
  // The corrected pose of scan i (world = frame of the first scan's front-end pose):
  // F_f ⊕ δ(α) ⊕ x_rel. Addition to Ch. 3 (not in the dissertation): the correction of the
  // fragment's outgoing edge, δ = t_f ⊕ ⊖μ_f (the chosen option against the measured mean), is
  // spread over the fragment in proportion to the distance travelled (α from 0 at F_f to 1 at
  // F_f+1), so the trajectory stays continuous where fragments meet instead of jumping by the
  // whole correction (measured on intel: see README, AntSLAM section).
  Se2d scan_pose(std::uint32_t i) const;
  Se2d fragment_pose(std::uint32_t f) const { return world_[f]; }
  std::uint32_t fragment_first_scan(std::uint32_t f) const { return fragment_first_scan_[f]; }
  const Point2f* fragment_points(std::uint32_t f, std::uint32_t* count) const {
    *count = num_points_[f];
    return points_ + static_cast<std::size_t>(f) * options_.max_points_per_fragment;
  }
  enum class FragmentState : std::uint8_t { kExplore = 0, kTraversal = 1 };
  FragmentState fragment_state(std::uint32_t f) const { return state_[f]; }
  const Border* fragment_borders(std::uint32_t f, std::uint32_t* count) const {
    *count = num_borders_[f];
    return borders_ + static_cast<std::size_t>(f) * options_.max_borders_per_fragment;
  }
  const Point2f* fragment_hull(std::uint32_t f, std::uint32_t* count) const {
    *count = hull_size_[f];
    return hull_ + static_cast<std::size_t>(f) * options_.max_hull_points;
  }
  // The fragment the robot is in (the newest one while exploring) and whether it is traversing.
  std::uint32_t active_fragment() const { return active_; }
  bool traversing() const { return traversing_; }
  // The robot's pose w.r.t. fragment c and its covariance (Eq. 3.4): the pose tracked in the active
  // fragment compounded along the shortest fragment sequence c → active (frozen edges at
  // frozen_cov_scale, as the loop candidates' prediction). Computed on demand instead of propagated
  // for every fragment at every scan (same mean and covariance to first order, O(edges) per query
  // instead of O(fragments) per scan). False when c is unknown or not connected.
  bool pose_in_fragment(std::uint32_t c, Se2d* pose, Mat3* cov);
  const SampledEdge& edge(std::uint32_t i) const { return edges_[i]; }
  const ClosureRecord& closure(std::uint32_t i) const { return closures_[i]; }
  const AntSlamStats& stats() const { return stats_; }

 private:
  // A new EXPLORE fragment entered from `parent` (the active one; none for the first) at the
  // tracked pose rel_ in F_parent.
  Status start_fragment(const Se2d& frontend_pose, const Point2f* points, std::size_t count);
  // Sec. 3.4: the fragment's exploration ends (border, hull, TRAVERSAL), and with traversal on the
  // loop is closed first and the robot may enter the closing fragment instead of a new one.
  Status end_exploration(const Se2d& frontend_pose, const Point2f* points, std::size_t count);
  // One scan while traversing: stay, move into a fragment joined by an edge, or open a new one.
  Status traverse(const Se2d& frontend_pose, const Point2f* points, std::size_t count);
  // Border of fragment f at the robot's pose `at` (F_f), stored on f; *out for the fragment entered.
  bool cut_border(std::uint32_t f, const Se2d& at, Border* out);
  void add_border(std::uint32_t f, const Border& b);
  bool inside(std::uint32_t f, const Se2d& at) const;
  // Enter TRAVERSAL fragment g from the active fragment; `g_from_active` = F_active in F_g.
  void enter(std::uint32_t g, const Se2d& g_from_active, const Mat3& extra_cov);
  void track_in_fragment(std::uint32_t f, const Point2f* points, std::size_t count);
  bool use_fragment_model(std::uint32_t f);  // the matcher's model (and field) = f's points
  Status open_fragment_from(std::uint32_t parent, const Border* crossed, const Se2d& frontend_pose,
                            const Point2f* points, std::size_t count);
  bool keyframe_due() const;  // moved keyframe_step_m or turned keyframe_turn_rad since the last keyframe
  Mat3 closure_prior() const;  // Σ_h from the closure sigmas
  // `predict_cov`: the edge's Eq. 3.4 covariance for path predictions (SampledEdge::predict_cov).
  Status add_edge(std::uint32_t from, std::uint32_t to, const Se2d& mean, const Mat3& cov, const Mat3& predict_cov,
                  std::uint32_t* index);
  // Eq. 3.9 Σ of `scene` placed at `pose` on the matcher's current model; false when no fit is possible.
  bool sensor_model_cov(const Point2f* scene, std::size_t n, const Se2d& pose, Mat3* cov);
  Status close_loop(std::uint32_t a);
  // Steps of close_loop() (antslam.cpp).
  std::uint32_t find_candidates(std::uint32_t a, std::uint32_t* cand);
  bool candidate_distance(std::uint32_t c, std::uint32_t a, std::uint32_t n, double* m) const;
  // Matches c against a; closes the loop when the closure passes the gate, else appends it to
  // gated[] (capacity kMaxCandidates) for the pair test.
  Status try_closure(std::uint32_t a, std::uint32_t c, bool* closed, ClosureCandidate* gated, std::uint32_t* num_gated);
  // `pair`: the record's pair fields (nullptr: closed by the gate).
  Status close_with(std::uint32_t a, const ClosureCandidate& k, std::uint32_t n, bool* closed,
                    const ClosureRecord* pair = nullptr);
  // closure_pairs.h: closes a's loop with one of its gated-out candidates that forms a consistent
  // cycle with a pending one of the last pair_window fragments (and agrees with every other such).
  Status try_pair_closure(std::uint32_t a, const ClosureCandidate* gated, std::uint32_t num_gated, bool* closed);
  // F_to in F_from along the current BFS tree (rooted at `to`), with its Eq. 3.4 covariance; false
  // when not connected or more than max_steps apart.
  bool chain(std::uint32_t from, std::uint32_t to, std::uint32_t max_steps, Se2d* x, Mat3* cov);
  // closure_isolation.h for the pair p, q (aa = F_q.a in F_p.a; p nullptr: q alone): both fragments'
  // points against the old fragments around q.c, rivals limited by `prior` when given. Leaves the
  // BFS tree rooted at q.c.
  bool closure_isolated(const ClosureCandidate* p, const ClosureCandidate& q, const Se2d& aa, float* z,
                     const IsolationPrior* prior = nullptr);
  bool match_closure(std::uint32_t a, std::uint32_t c, const Se2d& x, Se2d* h, float* quality);
  Se2d refine_hypothesis(const Point2f* scene, std::uint32_t n, const Se2d& h, const Se2d& x);
  Mat3 closure_cov(const Point2f* scene, std::uint32_t n, const Se2d& h);
  Status optimize_loop(std::uint32_t n, const Se2d& h, const Mat3& cov_h, double* w0, double* w1);
  Se2d freeze_loop(std::uint32_t n);
  void shortest_paths(std::uint32_t a);  // BFS from a: parent_edge_, hops_
  // Path c → a as steps (forward/backward) into steps_; returns the number of steps.
  std::uint32_t build_path(std::uint32_t c, std::uint32_t a);
  void compound_path(std::uint32_t n, Se2d* x, Mat3* cov) const;
  void recompute_world();
  std::uint64_t now() const { return clock_ ? clock_->now_ns() : 0; }

  AntSlamOptions options_;
  bool initialized_ = false;
  WorkerPool* pool_ = nullptr;
  const hal::Clock* clock_ = nullptr;
  RandomStream edge_rng_;
  pransam::Matcher<2> matcher_;
  AntColony aco_;
  LoopLm lm_;
  GraphRefine graph_;
  AntSlamStats stats_;

  // Scans.
  std::uint32_t num_scans_ = 0;
  std::uint32_t* scan_fragment_ = nullptr;
  Se2d* scan_rel_ = nullptr;  // scan pose in its fragment's frame
  float* scan_along_ = nullptr;  // distance travelled in its fragment before this scan (m)
  // Fragments.
  std::uint32_t num_fragments_ = 0;
  Se2d* frontend_frame_ = nullptr;  // F_i in the front end's world
  Se2d* world_ = nullptr;           // F_i corrected
  std::uint32_t* fragment_first_scan_ = nullptr;
  double* fragment_length_ = nullptr;  // distance travelled in the fragment (m)
  std::uint32_t* adjacent_edge_ = nullptr;  // edge index of F_i → the fragment opened at its end (kNoEdge: none)
  std::uint32_t* entry_edge_ = nullptr;     // edge from the fragment F_i was opened from (i ≥ 1)
  FragmentState* state_ = nullptr;
  Border* borders_ = nullptr;               // [fragment][max_borders_per_fragment], fragment frame
  std::uint32_t* num_borders_ = nullptr;
  Point2f* hull_ = nullptr;                 // [fragment][max_hull_points], fragment frame, CCW
  std::uint32_t* hull_size_ = nullptr;
  Point2f* hull_scratch_ = nullptr;         // max_points_per_fragment
  std::uint32_t active_ = 0;
  bool traversing_ = false;
  std::uint32_t pending_parent_ = 0;        // the fragment start_fragment() opens from
  std::uint32_t model_of_ = 0xffffffffu;    // the fragment whose field the matcher holds (none: ~0)
  // The last closure of close_loop(): its fragment and Σ_h (for entering it).
  bool last_closed_ = false;
  std::uint32_t last_closure_c_ = 0;
  Mat3 last_closure_cov_ = Mat3::Zero();
  Point2f* points_ = nullptr;               // [fragment][max_points_per_fragment], fragment frame
  std::uint32_t* num_points_ = nullptr;
  Se2d* keyframes_ = nullptr;               // [fragment][max_keyframes_per_fragment], fragment frame
  std::uint32_t* num_keyframes_ = nullptr;
  // Edges (adjacent and closing) and their options.
  std::uint32_t num_edges_ = 0, max_edges_ = 0;
  SampledEdge* edges_ = nullptr;
  Se2d* edge_options_ = nullptr;
  double* edge_option_cost_ = nullptr;
  std::uint32_t num_closures_ = 0;
  ClosureRecord* closures_ = nullptr;
  // Active fragment tracking (Eq. 3.4).
  Se2d last_frontend_;
  Se2d rel_;
  Mat3 rel_cov_ = Mat3::Zero();
  double travelled_ = 0.0;
  Se2d last_keyframe_;
  bool have_keyframe_ = false;
  // Loop-closing scratch.
  std::int32_t* parent_edge_ = nullptr;
  std::uint32_t* hops_ = nullptr;
  std::uint32_t* queue_ = nullptr;
  LoopStep* steps_ = nullptr;
  Se2d* values_ = nullptr;
  ClosureCandidateRing pending_;  // gated-out closures of the last pair_window fragments
  pransam::ContactField<2> iso_field_;  // the old map around a pair's candidate
  Point2f* iso_model_ = nullptr;        // isolation_max_points
  Point2f* iso_scene_ = nullptr;        // 2 × max_points_per_fragment
  CellSample* iso_cells_ = nullptr;     // 2 × max_points_per_fragment
};

}  // namespace fw::antslam
