// LocalizationSystem: the one start-up builder of "the firmware's localizer". mmlfw, mml-sim,
// mml-eval, the benchmarks, the HIL scenarios and the budget replay all build the localizer here,
// from the same spec, so a figure measured on one is a figure of all.
// Localizers (SystemSpec.localizer):
//   mml-track  [default] MML global localization, confirmed and then tracked on the global map at
//              every scan with an integrity monitor and a protection level (firmware/track)
//   mml        MML global localization alone (dissertation Ch. 5)
//   handoff    MML handing off to MCL tracking (baseline)
//   mcl        MCL global localization (the thesis's baseline)
//   odom       odometry pass-through (dead reckoning)
// The localizer objects are placed in the start-up arena (only the ones the spec needs), so the
// footprint is what the chosen system uses; nothing is allocated after build().
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/app/localizer_names.h"
#include "firmware/base/arena.h"
#include "firmware/base/worker_pool.h"
#include "firmware/map/global_map.h"
#include "firmware/baselines/mcl/mcl_localizer.h"
#include "firmware/mml/handoff_localizer.h"
#include "firmware/mml/mml_localizer.h"
#include "firmware/runtime/localizer.h"
#include "firmware/runtime/odometry_localizer.h"
#include "firmware/track/tracked_localizer.h"

namespace fw {

struct SystemSpec {
  const char* localizer = kDefaultLocalizer;
  int mml_preset = 3;              // C1..C4 (firmware/mml/mml_presets.h)
  std::uint64_t seed = 1;
  std::uint32_t mcl_particles = 30000;  // `mcl` baseline
  // Optional overrides (host tools and tests); null = the shipped configuration. The MML config is
  // still fitted to the map (contact field) by the builder.
  const mml::MmlLocalizerConfig* mml = nullptr;
  const track::TrackOptions* track = nullptr;
  const mcl::MclOptions* mcl = nullptr;
  const mml::HandoffOptions* handoff = nullptr;
  const OdometryLocalizerOptions* odom = nullptr;
  // mml-track: when MML consumes scans and returns results (track/global_context.h); null = the
  // reference schedule (every scan, result on the same scan: deterministic, what the tools measure).
  const track::GlobalScheduleOptions* global_schedule = nullptr;
  // Anytime global search (issue 14): RBSM's end-point window re-centres by at most
  // kAnytimeRecenterCells per step instead of in one 11–22 ms step. Deterministic. (pRANSAM's
  // deadline mode, the time-dependent half, is switched on by start_global_context.)
  bool anytime_global = false;
};
inline constexpr std::uint32_t kAnytimeRecenterCells = 16;

class LocalizationSystem {
 public:
  LocalizationSystem() = default;
  LocalizationSystem(const LocalizationSystem&) = delete;
  LocalizationSystem& operator=(const LocalizationSystem&) = delete;
  ~LocalizationSystem();

  // `table_section` (may be null): the map image's precomputed relation table, read in place.
  // `pool` (may be null): worker threads for RBSM / pRANSAM / MCL. Errors name the part that failed.
  // `work` (optional): where MML's working memory goes (MmlLocalizer::init; several maps share one
  // block: map_set.h). Null = `arena`.
  Status build(const SystemSpec& spec, const GlobalMap& map, const std::uint8_t* table_section,
               std::size_t table_len, StartupArena& arena, WorkerPool* pool, StartupArena* work = nullptr);
  // Bytes the `work` block of build() needs for this spec (0: the localizer has no MML).
  static std::size_t working_bytes(const SystemSpec& spec);
  // Another system has used the shared working memory since this one's last reset: the next reset
  // of MML wipes all of it (MmlLocalizer::mark_working_memory_foreign). Before localizer().reset().
  void mark_working_memory_foreign() {
    if (mml_ != nullptr) mml_->mark_working_memory_foreign();
  }

  bool built() const { return localizer_ != nullptr; }
  Localizer& localizer() { return *localizer_; }
  const Localizer& localizer() const { return *localizer_; }
  const char* name() const { return localizer_ != nullptr ? localizer_->name() : "none"; }
  // The parts (null when the chosen system has none).
  mml::MmlLocalizer* mml() { return mml_; }
  const mml::MmlLocalizer* mml() const { return mml_; }
  track::TrackedLocalizer* tracked() { return tracked_; }
  const track::TrackedLocalizer* tracked() const { return tracked_; }
  mcl::MclLocalizer* mcl() { return mcl_; }
  mml::HandoffLocalizer* handoff() { return handoff_; }
  const mml::HandoffLocalizer* handoff() const { return handoff_; }
  OdometryLocalizer* odom() { return odom_; }
  // mml-track only, start-up: runs the global search on its own thread as the execution-context
  // table declares (`global`, execution_contexts.h); needs a schedule with result_delay_scans ≥ 1.
  // `clock` times the global steps. Other localizers: nothing to start (ok).
  Status start_global_context(bool realtime, const hal::Clock* clock,
                              const ExecutionContext& context = kGlobalContext);
  // The same on a global thread created and shared by the caller (MapSet: one thread, whichever
  // map is active); creates no thread. Other localizers: nothing to attach (ok).
  Status attach_global_thread(track::GlobalThread* thread, const hal::Clock* clock, const ExecutionContext& context);
  void stop_global_context();
  // mml-track: where the threaded global context records each result it takes or drops (the black
  // box, issue 60; hal/global_record_sink.h); null = none. Other localizers: nothing to record.
  void set_global_record_sink(hal::GlobalRecordSink* sink) {
    if (tracked_ != nullptr) tracked_->global_context().set_record_sink(sink);
  }
  // True when MML reads the map image's relation table in place (keep the image mapped).
  bool table_in_use() const;
  // Bytes of the localizer objects (they live in the arena; counted in arena.used()).
  std::size_t object_bytes() const { return object_bytes_; }

 private:
  template <typename T>
  Result<T*> emplace(StartupArena& arena, const char* what);
  Localizer* localizer_ = nullptr;
  OdometryLocalizer* odom_ = nullptr;
  mml::MmlLocalizer* mml_ = nullptr;
  track::TrackedLocalizer* tracked_ = nullptr;
  mcl::MclLocalizer* mcl_ = nullptr;
  mml::HandoffLocalizer* handoff_ = nullptr;
  std::size_t object_bytes_ = 0;
};

}  // namespace fw
