#include "sim/eval/mml_eval/mml_systems.h"

#include <time.h>

#include <algorithm>
#include <cstdlib>

#include "firmware/map/map_image.h"
#include "firmware/baselines/mcl/global_map_view.h"
#include "firmware/mml/mml_presets.h"
#include "sim/localizers/localizer_context.h"  // HypothesisPoint (header only)

namespace sim::mmleval {

fw::mml::MmlLocalizerConfig mml_config(int config, std::uint64_t seed) { return fw::mml::mml_preset(config, seed); }
fw::mml::MmlLocalizerConfig mml_track_config(int config, std::uint64_t seed) {
  return fw::mml::mml_track_preset(config, seed);
}

bool OwnedLocalizer::start_pool(int threads, std::string* err) {
  if (threads <= 1) return true;
  pool_ = std::make_unique<fw::WorkerPool>();
  fw::WorkerPoolOptions po;
  po.num_workers = threads;
  po.pin = false;
  const fw::Status s = pool_->start(po);
  if (!s.is_ok()) {
    *err = std::string("worker pool: ") + s.message();
    return false;
  }
  return true;
}

namespace {
const std::uint8_t* table_section(const std::vector<std::uint8_t>& image, std::size_t* len) {
  *len = 0;
  if (image.empty()) return nullptr;
  return fw::find_section(image.data(), image.size(), fw::MapSectionType::kRelationTable2D, len);
}
EvalGlobalMode g_global_mode = EvalGlobalMode::kReference;
std::uint32_t g_global_period = 0;  // 0 = the execution-context table's

class MonotonicClock final : public hal::Clock {
 public:
  std::uint64_t now_ns() const override {
    timespec t{};
    clock_gettime(CLOCK_MONOTONIC, &t);
    return static_cast<std::uint64_t>(t.tv_sec) * 1000000000ull + static_cast<std::uint64_t>(t.tv_nsec);
  }
};
MonotonicClock g_mono_clock;
}  // namespace

void set_eval_global_mode(EvalGlobalMode mode) { g_global_mode = mode; }
void set_eval_global_period(std::uint32_t period_scans) { g_global_period = period_scans; }

std::unique_ptr<OwnedLocalizer> OwnedLocalizer::make(const fw::SystemSpec& spec, const fw::GlobalMap& map,
                                                     const std::vector<std::uint8_t>& image, int threads,
                                                     std::string* err) {
  auto o = std::unique_ptr<OwnedLocalizer>(new OwnedLocalizer());
  if (!o->start_pool(threads, err)) return nullptr;
  fw::Status s = o->arena_.init_mapped(400u << 20, false, spec.localizer);
  if (s.is_ok()) {
    std::size_t len = 0;
    const std::uint8_t* sec = table_section(image, &len);
    fw::SystemSpec sp = spec;
    const fw::track::GlobalScheduleOptions live = fw::track::live_global_schedule(g_global_period);
    const bool track = sp.localizer != nullptr && std::string(sp.localizer) == "mml-track";
    if (track && g_global_mode != EvalGlobalMode::kReference) {
      sp.global_schedule = &live;
      sp.anytime_global = true;
    }
    s = o->system_.build(sp, map, sec, len, o->arena_, o->pool_.get());
    // The inline global steps are timed (GlobalContext::perf_step, StepLog::global_ms): timing only,
    // the steps' results do not depend on it.
    if (s.is_ok() && track && o->system_.tracked() != nullptr) o->system_.tracked()->global_context().set_clock(&g_mono_clock);
    if (s.is_ok() && track && g_global_mode == EvalGlobalMode::kLiveDeadline && o->system_.mml() != nullptr) {
      o->system_.mml()->set_deadline_mode(&g_mono_clock, fw::track::global_context_for(g_global_period).deadline_ns);
    }
    // As mmlfw starts it (not realtime): the thread's clock puts MML in deadline mode.
    if (s.is_ok() && track && g_global_mode == EvalGlobalMode::kThread) {
      s = o->system_.start_global_context(false, &g_mono_clock, fw::track::global_context_for(g_global_period));
    }
  }
  if (!s.is_ok()) {
    *err = s.message();
    return nullptr;
  }
  o->arena_.seal();
  return o;
}

std::unique_ptr<OwnedLocalizer> OwnedLocalizer::make_mml(const fw::GlobalMap& map, const std::vector<std::uint8_t>& image,
                                                         const fw::mml::MmlLocalizerConfig& cfg, int threads,
                                                         std::string* err) {
  fw::SystemSpec spec;
  spec.localizer = "mml";
  spec.mml = &cfg;
  return make(spec, map, image, threads, err);
}

std::unique_ptr<OwnedLocalizer> OwnedLocalizer::make_track(const fw::GlobalMap& map,
                                                           const std::vector<std::uint8_t>& image,
                                                           const fw::mml::MmlLocalizerConfig& cfg,
                                                           const fw::track::TrackOptions& track, int threads,
                                                           std::string* err) {
  fw::SystemSpec spec;
  spec.localizer = "mml-track";
  spec.mml = &cfg;
  spec.track = &track;
  return make(spec, map, image, threads, err);
}

std::unique_ptr<OwnedLocalizer> OwnedLocalizer::make_mcl(const fw::GlobalMap& map, const fw::mcl::MclOptions& opt,
                                                         int threads, std::string* err) {
  fw::SystemSpec spec;
  spec.localizer = "mcl";
  spec.mcl = &opt;
  spec.seed = opt.seed;
  return make(spec, map, {}, threads, err);
}

std::unique_ptr<OwnedLocalizer> OwnedLocalizer::make_handoff(const fw::GlobalMap& map,
                                                             const std::vector<std::uint8_t>& image,
                                                             const fw::mml::MmlLocalizerConfig& cfg,
                                                             const fw::mcl::MclOptions& tracking,
                                                             const fw::mml::HandoffOptions& ho, int threads,
                                                             std::string* err) {
  fw::SystemSpec spec;
  spec.localizer = "handoff";
  spec.mml = &cfg;
  spec.mcl = &tracking;
  spec.handoff = &ho;
  return make(spec, map, image, threads, err);
}

void OwnedLocalizer::hypotheses(std::vector<HypothesisPoint>* out) const {
  out->clear();
  const fw::mml::MmlLocalizer* mml = system_.mml();
  if (mml == nullptr) return;
  if (system_.handoff() != nullptr && system_.handoff()->tracking()) return;
  if (system_.tracked() != nullptr && system_.tracked()->tracking()) return;
  // MML belongs to the global thread: its clusters are not read from here.
  if (system_.tracked() != nullptr && system_.tracked()->global_context().threaded()) return;
  const fw::mml::Interpreter& it = mml->interpreter();
  for (std::size_t i = 0; i < it.cluster_count(); ++i) {
    const fw::mml::Cluster& c = it.clusters()[i];
    HypothesisPoint p;
    p.x = c.x;
    p.y = c.y;
    p.theta = c.theta;
    p.weight = c.rating;
    out->push_back(p);
  }
}

}  // namespace sim::mmleval
