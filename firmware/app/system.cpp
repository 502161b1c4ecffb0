#include "firmware/app/system.h"

#include <cstring>
#include <new>

#include "firmware/baselines/mcl/global_map_view.h"
#include "firmware/baselines/mcl/mcl_presets.h"
#include "firmware/mml/mml_presets.h"

namespace fw {

// Placement in the arena: the objects are large (fixed arrays) and only the chosen ones take memory.
template <typename T>
Result<T*> LocalizationSystem::emplace(StartupArena& arena, const char* what) {
  Result<void*> r = arena.allocate(sizeof(T), alignof(T), what);
  if (!r) return r.status();
  object_bytes_ += sizeof(T);
  FW_RETURN_IF_ERROR(MemoryReport::instance().add({"system", what, sizeof(T), 1, nullptr}));
  return new (*r) T();
}

LocalizationSystem::~LocalizationSystem() {
  stop_global_context();
  // The arena owns the bytes; run the destructors (host tools build and drop systems).
  if (tracked_) tracked_->~TrackedLocalizer();
  if (handoff_) handoff_->~HandoffLocalizer();
  if (mcl_) mcl_->~MclLocalizer();
  if (mml_) mml_->~MmlLocalizer();
  if (odom_) odom_->~OdometryLocalizer();
}

Status LocalizationSystem::start_global_context(bool realtime, const hal::Clock* clock,
                                                const ExecutionContext& context) {
  if (tracked_ == nullptr) return Status::ok();
  return tracked_->global_context().start_thread(context, realtime, clock);
}

Status LocalizationSystem::attach_global_thread(track::GlobalThread* thread, const hal::Clock* clock,
                                                const ExecutionContext& context) {
  if (tracked_ == nullptr) return Status::ok();
  return tracked_->global_context().attach_thread(thread, context, clock);
}

void LocalizationSystem::stop_global_context() {
  if (tracked_ != nullptr) tracked_->global_context().stop_thread();
}

bool LocalizationSystem::table_in_use() const { return mml_ != nullptr && mml_->using_precomputed_table(); }

namespace {
bool uses_mml(const char* name) { return std::strcmp(name, "mcl") != 0 && std::strcmp(name, "odom") != 0; }

// MML's config for the spec before it is fitted to a map (the fit changes the contact field only,
// which is the map's part, never the working memory).
mml::MmlLocalizerConfig spec_mml_config(const SystemSpec& spec, bool tracked) {
  mml::MmlLocalizerConfig mc = spec.mml != nullptr ? *spec.mml
                               : tracked ? mml::mml_track_preset(spec.mml_preset, spec.seed)
                                         : mml::mml_preset(spec.mml_preset, spec.seed);
  if (spec.anytime_global) mc.rbsm.grid.recenter_step_cells = kAnytimeRecenterCells;
  return mc;
}
}  // namespace

std::size_t LocalizationSystem::working_bytes(const SystemSpec& spec) {
  const char* name = spec.localizer != nullptr ? spec.localizer : kDefaultLocalizer;
  if (!is_known_localizer(name) || !uses_mml(name)) return 0;
  return mml::MmlLocalizer::working_bytes(spec_mml_config(spec, std::strcmp(name, "mml-track") == 0));
}

Status LocalizationSystem::build(const SystemSpec& spec, const GlobalMap& map, const std::uint8_t* table_section,
                                 std::size_t table_len, StartupArena& arena, WorkerPool* pool, StartupArena* work) {
  if (built()) return Status::error(Errc::kInvalidArgument, "localization system: already built");
  const char* name = spec.localizer != nullptr ? spec.localizer : kDefaultLocalizer;
  if (!is_known_localizer(name)) {
    return Status::error(Errc::kInvalidArgument, "localization system: unknown localizer '%s' (known: %s)", name,
                         kKnownLocalizers);
  }
  if (std::strcmp(name, "odom") == 0) {
    const OdometryLocalizerOptions oo = spec.odom != nullptr ? *spec.odom : OdometryLocalizerOptions();
    FW_RETURN_IF_ERROR(oo.validate());
    Result<OdometryLocalizer*> r = emplace<OdometryLocalizer>(arena, "OdometryLocalizer");
    if (!r) return r.status();
    odom_ = *r;
    *odom_ = OdometryLocalizer(oo);
    localizer_ = odom_;
    return Status::ok();
  }
  if (!map.valid()) {
    return Status::error(Errc::kInvalidArgument, "localization system: localizer '%s' needs a global map (map = ...)", name);
  }
  const bool want_mml = std::strcmp(name, "mcl") != 0;
  const bool want_mcl = std::strcmp(name, "mcl") == 0 || std::strcmp(name, "handoff") == 0;
  if (want_mml) {
    const bool tracked = std::strcmp(name, "mml-track") == 0;
    // pRANSAM's contact field must cover this map (it is sized from the map, not the preset).
    const mml::MmlLocalizerConfig mc = mml::fit_contact_field_to_map(spec_mml_config(spec, tracked), map);
    Result<mml::MmlLocalizer*> r = emplace<mml::MmlLocalizer>(arena, "MmlLocalizer");
    if (!r) return r.status();
    mml_ = *r;
    const Status s = mml_->init(mc, map, table_section, table_len, arena, pool, work);
    if (!s) return Status::error(s.code(), "localizer mml: %s", s.message());
  }
  if (want_mcl) {
    const bool handoff = std::strcmp(name, "handoff") == 0;
    const mcl::MclOptions mo = spec.mcl != nullptr ? *spec.mcl
                               : handoff           ? mcl::mcl_tracking_options(spec.seed)
                                                   : mcl::mcl_baseline_options(spec.mcl_particles, spec.seed);
    Result<mcl::MclLocalizer*> r = emplace<mcl::MclLocalizer>(arena, "MclLocalizer");
    if (!r) return r.status();
    mcl_ = *r;
    // Hand-off tracking is cheap: single-threaded (no pool hand-over latency).
    const Status s = mcl_->init(mo, mcl::map_view_from_global(map), handoff ? nullptr : pool);
    if (!s) return Status::error(s.code(), "localizer mcl: %s", s.message());
  }
  if (std::strcmp(name, "mml") == 0) {
    localizer_ = mml_;
  } else if (std::strcmp(name, "mcl") == 0) {
    localizer_ = mcl_;
  } else if (std::strcmp(name, "handoff") == 0) {
    Result<mml::HandoffLocalizer*> r = emplace<mml::HandoffLocalizer>(arena, "HandoffLocalizer");
    if (!r) return r.status();
    handoff_ = *r;
    const Status s = handoff_->init(spec.handoff != nullptr ? *spec.handoff : mml::HandoffOptions(), mml_, mcl_);
    if (!s) return Status::error(s.code(), "localizer handoff: %s", s.message());
    localizer_ = handoff_;
  } else {  // mml-track
    Result<track::TrackedLocalizer*> r = emplace<track::TrackedLocalizer>(arena, "TrackedLocalizer");
    if (!r) return r.status();
    tracked_ = *r;
    const Status s = tracked_->init(spec.track != nullptr ? *spec.track : track::TrackOptions(), map, mml_,
                                    spec.global_schedule != nullptr ? *spec.global_schedule
                                                                    : track::GlobalScheduleOptions());
    if (!s) return Status::error(s.code(), "localizer mml-track: %s", s.message());
    localizer_ = tracked_;
  }
  return Status::ok();
}

}  // namespace fw
