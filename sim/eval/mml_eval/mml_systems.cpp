#include "sim/eval/mml_eval/mml_systems.h"

#include <algorithm>
#include <cstdlib>

#include "firmware/map/map_image.h"
#include "firmware/mcl/global_map_view.h"
#include "firmware/mml/mml_presets.h"
#include "sim/cli/localizer_factory.h"  // HypothesisPoint (header only)

namespace sim::mmleval {

fw::mml::MmlLocalizerConfig mml_config(int config, std::uint64_t seed) { return fw::mml::mml_preset(config, seed); }

fw::mcl::MclOptions mcl_baseline_options(std::uint32_t particles, std::uint64_t seed) {
  fw::mcl::MclOptions o;
  o.num_particles = particles;
  o.model = fw::mcl::SensorModel::kBeam;
  o.num_beams = 18;
  o.seed = seed;
  return o;
}

// 1000 particles × 30 beams: with 500 × 60 the cloud slid 0.5 m during an in-place turn in intel's
// centre room and in an aces corridor (one hand-off failure each, bench of 2026-11-22); 2000 × 60
// also fixed both at 3.5 ms per scan, this keeps the step near 1 ms.
fw::mcl::MclOptions mcl_tracking_options(std::uint64_t seed) {
  fw::mcl::MclOptions o;
  o.num_particles = 1000;
  o.model = fw::mcl::SensorModel::kLikelihoodField;
  o.num_beams = 30;
  o.lf_sigma_m = 0.08f;
  o.alpha1 = o.alpha3 = 0.05f;
  o.alpha2 = o.alpha4 = 0.02f;
  o.resample_neff_ratio = 0.5f;
  o.seed = seed;
  return o;
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
fw::mml::MmlLocalizerConfig adapt_to_map(const fw::mml::MmlLocalizerConfig& cfg, const fw::GlobalMap& map) {
  return fw::mml::fit_contact_field_to_map(cfg, map);
}

const std::uint8_t* table_section(const std::vector<std::uint8_t>& image, std::size_t* len) {
  *len = 0;
  if (image.empty()) return nullptr;
  return fw::find_section(image.data(), image.size(), fw::MapSectionType::kRelationTable2D, len);
}
}  // namespace

std::unique_ptr<OwnedLocalizer> OwnedLocalizer::make_mml(const fw::GlobalMap& map, const std::vector<std::uint8_t>& image,
                                                         const fw::mml::MmlLocalizerConfig& cfg, int threads,
                                                         std::string* err) {
  auto o = std::unique_ptr<OwnedLocalizer>(new OwnedLocalizer());
  if (!o->start_pool(threads, err)) return nullptr;
  fw::Status s = o->arena_.init_mapped(400u << 20, false, "mml");
  if (s.is_ok()) {
    o->mml_ = std::make_unique<fw::mml::MmlLocalizer>();
    std::size_t len = 0;
    const std::uint8_t* sec = table_section(image, &len);
    s = o->mml_->init(adapt_to_map(cfg, map), map, sec, len, o->arena_, o->pool_.get());
  }
  if (!s.is_ok()) {
    *err = std::string("localizer mml: ") + s.message();
    return nullptr;
  }
  o->arena_.seal();
  o->inner_ = o->mml_.get();
  return o;
}

std::unique_ptr<OwnedLocalizer> OwnedLocalizer::make_mcl(const fw::GlobalMap& map, const fw::mcl::MclOptions& opt,
                                                         int threads, std::string* err) {
  auto o = std::unique_ptr<OwnedLocalizer>(new OwnedLocalizer());
  if (!o->start_pool(threads, err)) return nullptr;
  o->mcl_ = std::make_unique<fw::mcl::MclLocalizer>();
  const fw::Status s = o->mcl_->init(opt, fw::mcl::map_view_from_global(map), o->pool_.get());
  if (!s.is_ok()) {
    *err = std::string("localizer mcl: ") + s.message();
    return nullptr;
  }
  o->inner_ = o->mcl_.get();
  return o;
}

std::unique_ptr<OwnedLocalizer> OwnedLocalizer::make_handoff(const fw::GlobalMap& map,
                                                             const std::vector<std::uint8_t>& image,
                                                             const fw::mml::MmlLocalizerConfig& cfg,
                                                             const fw::mcl::MclOptions& tracking,
                                                             const fw::mml::HandoffOptions& ho, int threads,
                                                             std::string* err) {
  auto o = std::unique_ptr<OwnedLocalizer>(new OwnedLocalizer());
  if (!o->start_pool(threads, err)) return nullptr;
  fw::Status s = o->arena_.init_mapped(400u << 20, false, "handoff");
  if (s.is_ok()) {
    o->mml_ = std::make_unique<fw::mml::MmlLocalizer>();
    std::size_t len = 0;
    const std::uint8_t* sec = table_section(image, &len);
    s = o->mml_->init(adapt_to_map(cfg, map), map, sec, len, o->arena_, o->pool_.get());
  }
  if (s.is_ok()) {
    o->mcl_ = std::make_unique<fw::mcl::MclLocalizer>();
    // Tracking is cheap: single-threaded (no pool hand-over latency).
    s = o->mcl_->init(tracking, fw::mcl::map_view_from_global(map), nullptr);
  }
  if (s.is_ok()) {
    o->handoff_ = std::make_unique<fw::mml::HandoffLocalizer>();
    s = o->handoff_->init(ho, o->mml_.get(), o->mcl_.get());
  }
  if (!s.is_ok()) {
    *err = std::string("localizer handoff: ") + s.message();
    return nullptr;
  }
  o->arena_.seal();
  o->inner_ = o->handoff_.get();
  return o;
}

std::size_t OwnedLocalizer::static_bytes() const {
  std::size_t b = arena_.used();
  if (mml_) b += sizeof(fw::mml::MmlLocalizer);
  if (mcl_) b += sizeof(fw::mcl::MclLocalizer);
  if (handoff_) b += sizeof(fw::mml::HandoffLocalizer);
  return b;
}

void OwnedLocalizer::hypotheses(std::vector<HypothesisPoint>* out) const {
  out->clear();
  if (!mml_) return;
  if (handoff_ && handoff_->tracking()) return;
  const fw::mml::Interpreter& it = mml_->interpreter();
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
