// Host-side construction of the MML / MCL / hand-off localizers for a loaded global map: owns the
// start-up arena, the worker pool and the (large) localizer objects; used by the evaluation
// harness (mml-eval, bench_mml) and by the simulator's localizer registry (make_*_localizer).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "firmware/app/system.h"
#include "firmware/base/arena.h"
#include "firmware/base/worker_pool.h"
#include "firmware/map/global_map.h"
#include "firmware/baselines/mcl/mcl_localizer.h"
#include "firmware/baselines/mcl/mcl_presets.h"
#include "firmware/mml/handoff_localizer.h"
#include "firmware/mml/mml_localizer.h"
#include "firmware/runtime/localizer.h"

namespace sim {
struct LocalizerContext;
struct HypothesisPoint;
}  // namespace sim

namespace sim::mmleval {

// MML configurations compared (our reading of Tables 5.1–5.4; the thesis's UFLMS/UBB/PRT/MI
// columns; local map correction and reduction are separate switches, MmlOptions.correct_local_map
// and reduce_observations, off in C1–C4):
//   C1: online relation tables, full local map, Bollinger, 30k iterations
//   C2: precomputed table, full local map, Bollinger, 30k iterations
//   C3: precomputed table, fixed local map (last 8 fragments of 2 m), Bollinger, 30k iterations
//   C4: as C3 with 60k iterations
fw::mml::MmlLocalizerConfig mml_config(int config, std::uint64_t seed);
// The MML part of mml-track (fw::mml::mml_track_preset: pooled cluster support on).
fw::mml::MmlLocalizerConfig mml_track_config(int config, std::uint64_t seed);
// MCL presets: firmware/baselines/mcl/mcl_presets.h (shared with the firmware).
using fw::mcl::mcl_baseline_options;
using fw::mcl::mcl_tracking_options;

// A localizer together with everything it needs (arena, pool), built by the firmware's one
// start-up builder (firmware/app/system.h) exactly as mmlfw builds it. reset()/step() forward.
// mml-track's global search in the evaluation (issue 14; mml-eval --global):
//   kReference      every scan, result on the same scan (default; the figures of record)
//   kLive           mmlfw's live schedule (execution_contexts.h: every scan, result 1 scan
//                   later, moved by odometry) + the RBSM window re-centre spread over steps; inline,
//                   deterministic — what the threaded firmware computes when every global step is on time
//   kLiveDeadline   kLive + pRANSAM deadline mode at the global context's deadline (time-dependent)
//   kThread         mmlfw's global_context = thread: kLive's schedule with MML on its own thread in
//                   deadline mode (time-dependent; the black box records when each result was taken
//                   and --replay-blackbox replays it bit for bit, issue 60)
enum class EvalGlobalMode { kReference, kLive, kLiveDeadline, kThread };
void set_eval_global_mode(EvalGlobalMode mode);
// kLive / kLiveDeadline: MML on every n-th scan, its result n scans later, its deadline n scan periods
// — mmlfw's config key global_period_scans (1..8; default 1, the execution-context table's).
void set_eval_global_period(std::uint32_t period_scans);

class OwnedLocalizer : public fw::Localizer {
 public:
  const char* name() const override { return system_.name(); }
  void reset() override { system_.localizer().reset(); }
  fw::Status step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) override {
    return system_.localizer().step(scan, odom, out);
  }
  fw::Status set_pose_hint(const hal::PoseHint& hint) override { return system_.localizer().set_pose_hint(hint); }
  hal::HintStatus hint_status() const override {
    return system_.built() ? system_.localizer().hint_status() : hal::HintStatus::kNone;
  }
  // Hypotheses (best clusters of the last MML step) for pictures; empty while tracking and for MCL.
  void hypotheses(std::vector<HypothesisPoint>* out) const;
  fw::LocalizationSystem& system() { return system_; }
  fw::mml::MmlLocalizer* mml() { return system_.mml(); }
  fw::mcl::MclLocalizer* mcl() { return system_.mcl(); }
  fw::mml::HandoffLocalizer* handoff() { return system_.handoff(); }
  fw::track::TrackedLocalizer* tracked() { return system_.tracked(); }
  std::size_t arena_bytes() const { return arena_.used(); }
  // Static memory of the firmware objects + arena (what a robot would reserve), bytes.
  std::size_t static_bytes() const { return arena_.used(); }

  // The general builder: `spec` as mmlfw's config gives it (overrides allowed). `image` = the
  // compiled map image bytes (for a precomputed relation table section); may be empty. `threads` ≥ 1.
  static std::unique_ptr<OwnedLocalizer> make(const fw::SystemSpec& spec, const fw::GlobalMap& map,
                                              const std::vector<std::uint8_t>& image, int threads, std::string* err);
  // Shorthands used by the evaluation (configs given explicitly).
  static std::unique_ptr<OwnedLocalizer> make_mml(const fw::GlobalMap& map, const std::vector<std::uint8_t>& image,
                                                  const fw::mml::MmlLocalizerConfig& cfg, int threads,
                                                  std::string* err);
  static std::unique_ptr<OwnedLocalizer> make_track(const fw::GlobalMap& map, const std::vector<std::uint8_t>& image,
                                                    const fw::mml::MmlLocalizerConfig& cfg,
                                                    const fw::track::TrackOptions& track, int threads, std::string* err);
  static std::unique_ptr<OwnedLocalizer> make_mcl(const fw::GlobalMap& map, const fw::mcl::MclOptions& opt,
                                                  int threads, std::string* err);
  static std::unique_ptr<OwnedLocalizer> make_handoff(const fw::GlobalMap& map, const std::vector<std::uint8_t>& image,
                                                      const fw::mml::MmlLocalizerConfig& cfg,
                                                      const fw::mcl::MclOptions& tracking,
                                                      const fw::mml::HandoffOptions& ho, int threads,
                                                      std::string* err);

 private:
  // Declaration order = destruction order reversed: the system (objects in the arena) goes first.
  std::unique_ptr<fw::WorkerPool> pool_;
  fw::StartupArena arena_;
  fw::LocalizationSystem system_;
  bool start_pool(int threads, std::string* err);
};

// Simulator registry entries (sim/cli/localizer_factory): "mml-track", "mml", "mcl", "handoff".
// Options (--opt k=v): mml: config=1..4, iterations=N, correct=0|1 (local map correction,
// Eq. 5.23–5.27), reduce=0|1 (local map reduction, Eq. 5.28–5.30); mcl: particles=N,
// model=beam|field, kld=0|1, inject=0|1; handoff: config=1..4, correct=0|1, reduce=0|1.
std::unique_ptr<fw::Localizer> make_mml_localizer(const LocalizerContext& ctx, std::string* err);
std::unique_ptr<fw::Localizer> make_track_localizer(const LocalizerContext& ctx, std::string* err);
// "TT,TR,RR,RT" (each in 0..10) → the tracker's odometry noise model (as mmlfw's config key
// odom_noise); false, `to` unchanged, when malformed.
bool set_odom_noise(const std::string& value, fw::track::TrackOptions* to);
// "M,DEG" (metres in 0..1, degrees in 0..28) → the tracker's per-step odometry noise (as mmlfw's
// config key odom_noise_per_step); false, `to` unchanged, when malformed.
bool set_odom_noise_per_step(const std::string& value, fw::track::TrackOptions* to);
std::unique_ptr<fw::Localizer> make_mcl_localizer(const LocalizerContext& ctx, std::string* err);
std::unique_ptr<fw::Localizer> make_handoff_localizer(const LocalizerContext& ctx, std::string* err);

}  // namespace sim::mmleval
