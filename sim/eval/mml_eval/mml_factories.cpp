// Registry entries for the simulator (sim/cli/localizer_factory.cpp): "mml-track", "mml", "mcl", "handoff".
// Uses only the registry's header types, so sim_mml does not link the registry (no cycle).
#include <cstdlib>

#include "sim/localizers/localizer_context.h"
#include "sim/eval/mml_eval/mml_systems.h"

namespace sim::mmleval {

namespace {

std::string check_keys(const std::string& who, const std::map<std::string, std::string>& options,
                       const std::vector<std::string>& known) {
  std::string bad;
  for (const auto& kv : options) {
    bool ok = false;
    for (const auto& k : known) ok = ok || k == kv.first;
    if (!ok) bad += (bad.empty() ? "" : ", ") + kv.first;
  }
  if (bad.empty()) return {};
  std::string list;
  for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
  return "localizer " + who + ": unknown option(s) " + bad + " (known: " + list + ")";
}

bool parse_int(const std::map<std::string, std::string>& o, const std::string& key, long lo, long hi, long* v,
               const std::string& who, std::string* err) {
  const auto it = o.find(key);
  if (it == o.end()) return true;
  char* end = nullptr;
  const long x = std::strtol(it->second.c_str(), &end, 10);
  if (end == it->second.c_str() || *end != '\0' || x < lo || x > hi) {
    *err = "localizer " + who + ": option " + key + "='" + it->second + "' (expected an integer in [" +
           std::to_string(lo) + ", " + std::to_string(hi) + "])";
    return false;
  }
  *v = x;
  return true;
}

// correct=0|1 / reduce=0|1: local map correction (Eq. 5.23–5.27) / reduction (Eq. 5.28–5.30);
// pool=0|1: best-cluster support pooled over consistent steps (interpretation.cpp); keep=0|1: the
// pool and streak kept across steps without hypotheses; contested=0|1: the pool kept across
// consistent steps with a rival cluster; rivals=0|1:
// the rival memory (rival_memory.h; 0 only to measure what it does).
bool apply_local_map_options(const std::map<std::string, std::string>& o, const std::string& who,
                             fw::mml::MmlLocalizerConfig* cfg, std::string* err) {
  long correct = cfg->mml.correct_local_map ? 1 : 0, reduce = cfg->mml.reduce_observations ? 1 : 0;
  long pool = cfg->mml.pool_cluster_support ? 1 : 0, rivals = cfg->mml.rival_memory ? 1 : 0;
  long keep = cfg->mml.keep_support_across_empty_steps ? 1 : 0;
  long contested = cfg->mml.keep_support_across_contested_steps ? 1 : 0;
  if (!parse_int(o, "correct", 0, 1, &correct, who, err)) return false;
  if (!parse_int(o, "rivals", 0, 1, &rivals, who, err)) return false;
  if (!parse_int(o, "reduce", 0, 1, &reduce, who, err)) return false;
  if (!parse_int(o, "pool", 0, 1, &pool, who, err)) return false;
  if (!parse_int(o, "keep", 0, 1, &keep, who, err)) return false;
  if (!parse_int(o, "contested", 0, 1, &contested, who, err)) return false;
  cfg->mml.correct_local_map = correct != 0;
  cfg->mml.reduce_observations = reduce != 0;
  cfg->mml.pool_cluster_support = pool != 0;  // MmlOptions::pool_cluster_support (on in mml-track)
  cfg->mml.rival_memory = rivals != 0;
  cfg->mml.keep_support_across_empty_steps = keep != 0;  // MmlOptions::keep_support_across_empty_steps (on in mml-track)
  cfg->mml.keep_support_across_contested_steps = contested != 0;  // ..._contested_steps (on in mml-track)
  return true;
}

std::unique_ptr<fw::Localizer> wrap_hooks(std::unique_ptr<OwnedLocalizer> o, const LocalizerContext& ctx) {
  if (o && ctx.hooks) {
    OwnedLocalizer* raw = o.get();
    ctx.hooks->hypotheses = [raw](std::vector<HypothesisPoint>* out) { raw->hypotheses(out); };
    ctx.hooks->global_context = [raw]() -> fw::track::GlobalContext* {
      return raw->tracked() != nullptr ? &raw->tracked()->global_context() : nullptr;
    };
    ctx.hooks->wait_cause = [raw]() -> const char* {
      return raw->tracked() != nullptr ? raw->tracked()->wait_cause() : "none";
    };
  }
  return o;
}

}  // namespace

std::unique_ptr<fw::Localizer> make_mml_localizer(const LocalizerContext& ctx, std::string* err) {
  const std::string bad = check_keys("mml", ctx.options, {"config", "iterations", "correct", "reduce", "pool", "keep", "contested", "rivals"});
  if (!bad.empty()) { *err = bad; return nullptr; }
  if (ctx.global_map == nullptr) { *err = "localizer mml: needs a global map"; return nullptr; }
  long config = 3, iters = 0;
  if (!parse_int(ctx.options, "config", 1, 4, &config, "mml", err)) return nullptr;
  if (!parse_int(ctx.options, "iterations", 1000, 10000000, &iters, "mml", err)) return nullptr;
  auto cfg = mml_config(static_cast<int>(config), ctx.seed);
  if (iters > 0) cfg.mml.matching_iterations = static_cast<std::uint32_t>(iters);
  if (!apply_local_map_options(ctx.options, "mml", &cfg, err)) return nullptr;
  static const std::vector<std::uint8_t> kEmpty;
  return wrap_hooks(OwnedLocalizer::make_mml(*ctx.global_map, ctx.map_image ? *ctx.map_image : kEmpty, cfg,
                                             ctx.threads, err),
                    ctx);
}

std::unique_ptr<fw::Localizer> make_mcl_localizer(const LocalizerContext& ctx, std::string* err) {
  const std::string bad = check_keys("mcl", ctx.options, {"particles", "model", "kld", "inject"});
  if (!bad.empty()) { *err = bad; return nullptr; }
  if (ctx.global_map == nullptr) { *err = "localizer mcl: needs a global map"; return nullptr; }
  long particles = 30000, kld = 0, inject = 0;
  if (!parse_int(ctx.options, "particles", 100, static_cast<long>(fw::mcl::kMaxParticles), &particles, "mcl", err))
    return nullptr;
  if (!parse_int(ctx.options, "kld", 0, 1, &kld, "mcl", err)) return nullptr;
  if (!parse_int(ctx.options, "inject", 0, 1, &inject, "mcl", err)) return nullptr;
  auto opt = mcl_baseline_options(static_cast<std::uint32_t>(particles), ctx.seed);
  const auto m = ctx.options.find("model");
  if (m != ctx.options.end()) {
    if (m->second == "field") {
      opt.model = fw::mcl::SensorModel::kLikelihoodField;
    } else if (m->second != "beam") {
      *err = "localizer mcl: option model='" + m->second + "' (expected beam or field)";
      return nullptr;
    }
  }
  opt.kld_sampling = kld != 0;
  opt.random_injection = inject != 0;
  return wrap_hooks(OwnedLocalizer::make_mcl(*ctx.global_map, opt, ctx.threads, err), ctx);
}

std::unique_ptr<fw::Localizer> make_handoff_localizer(const LocalizerContext& ctx, std::string* err) {
  const std::string bad = check_keys("handoff", ctx.options, {"config", "correct", "reduce", "pool", "keep", "contested", "rivals"});
  if (!bad.empty()) { *err = bad; return nullptr; }
  if (ctx.global_map == nullptr) { *err = "localizer handoff: needs a global map"; return nullptr; }
  long config = 3;
  if (!parse_int(ctx.options, "config", 1, 4, &config, "handoff", err)) return nullptr;
  auto cfg = mml_config(static_cast<int>(config), ctx.seed);
  if (!apply_local_map_options(ctx.options, "handoff", &cfg, err)) return nullptr;
  static const std::vector<std::uint8_t> kEmpty;
  return wrap_hooks(OwnedLocalizer::make_handoff(*ctx.global_map, ctx.map_image ? *ctx.map_image : kEmpty, cfg,
                                                 mcl_tracking_options(ctx.seed), fw::mml::HandoffOptions(),
                                                 ctx.threads, err),
                    ctx);
}

}  // namespace sim::mmleval

namespace sim::mmleval {

bool set_odom_noise(const std::string& value, fw::track::TrackOptions* to) {
  float v[4];
  const char* p = value.c_str();
  for (int i = 0; i < 4; ++i) {
    char* end = nullptr;
    const double d = std::strtod(p, &end);
    const char want = i < 3 ? ',' : '\0';
    if (end == p || *end != want || !(d >= 0.0 && d <= 10.0)) return false;
    v[i] = static_cast<float>(d);
    p = end + 1;
  }
  to->odom_trans_per_m = v[0];
  to->odom_trans_per_rad = v[1];
  to->odom_rot_per_rad = v[2];
  to->odom_rot_per_m = v[3];
  return true;
}

bool set_odom_noise_per_step(const std::string& value, fw::track::TrackOptions* to) {
  const char* p = value.c_str();
  char* end = nullptr;
  const double m = std::strtod(p, &end);
  if (end == p || *end != ',' || !(m >= 0.0 && m <= 1.0)) return false;
  p = end + 1;
  const double deg = std::strtod(p, &end);
  if (end == p || *end != '\0' || !(deg >= 0.0 && deg <= 28.0)) return false;
  to->odom_trans_per_step_m = static_cast<float>(m);
  to->odom_rot_per_step_rad = static_cast<float>(deg * 0.017453292519943295);
  return true;
}

// odom_noise=TT,TR,RR,RT and odom_noise_per_step=M,DEG → the tracker's odometry noise model.
static bool parse_odom_noise(const std::map<std::string, std::string>& options, fw::track::TrackOptions* to,
                             std::string* err) {
  const auto it = options.find("odom_noise");
  if (it != options.end() && !set_odom_noise(it->second, to)) {
    *err = "localizer mml-track: option odom_noise='" + it->second + "' (expected four numbers TT,TR,RR,RT in 0..10)";
    return false;
  }
  const auto ps = options.find("odom_noise_per_step");
  if (ps != options.end() && !set_odom_noise_per_step(ps->second, to)) {
    *err = "localizer mml-track: option odom_noise_per_step='" + ps->second +
           "' (expected M,DEG: metres in 0..1 and degrees in 0..28 per scan step)";
    return false;
  }
  return true;
}

// odom_slip=RATE,MAX → declared wheel slips (TrackOptions::odom_slip_per_100m, odom_slip_max_m).
static bool parse_odom_slip(const std::map<std::string, std::string>& options, fw::track::TrackOptions* to,
                            std::string* err) {
  const auto it = options.find("odom_slip");
  if (it == options.end()) return true;
  const char* p = it->second.c_str();
  char* end = nullptr;
  const double rate = std::strtod(p, &end);
  bool ok = end != p && *end == ',' && rate >= 0.0 && rate <= 1000.0;
  double max_m = 0.0;
  if (ok) {
    p = end + 1;
    max_m = std::strtod(p, &end);
    ok = end != p && *end == '\0' && max_m >= 0.0 && max_m <= 100.0;
  }
  if (!ok) {
    *err = "localizer mml-track: option odom_slip='" + it->second + "' (expected RATE,MAX_M: slips per 100 m in 0..1000, metres in 0..100)";
    return false;
  }
  to->odom_slip_per_100m = static_cast<float>(rate);
  to->odom_slip_max_m = static_cast<float>(max_m);
  return true;
}

// off=NAME[+NAME...] → those rules of TrackOptions off, on=NAME[+NAME...] → on (the ablations of
// issue 56: what each rule buys on the generated corpus, `mml-eval --corpus N --opt off=NAME`; on=
// for a rule off by default, heading_fault_local_recovery).
static bool parse_rule_switches(const std::map<std::string, std::string>& options, fw::track::TrackOptions* to,
                            fw::mml::MmlOptions* mo, std::string* err) {
  using T = fw::track::TrackOptions;
  static const std::pair<const char*, bool T::*> kRules[] = {
      {"outside_map_needs_clean_exit", &T::outside_map_needs_clean_exit},
      {"wheels_bind_mml_without_carry", &T::wheels_bind_mml_without_carry},
      {"alias_check", &T::alias_check},
      {"refit_at_better_rival", &T::refit_at_better_rival},
      {"alias_valley_is_one_mode", &T::alias_valley_is_one_mode},
      {"alias_valley_drops_information", &T::alias_valley_drops_information},
      {"heading_fault_local_recovery", &T::heading_fault_local_recovery},
      {"repin_needs_confirmation", &T::repin_needs_confirmation},
      {"confidence_extent_xy", &T::confidence_extent_xy},
      {"confidence_cap_with_update", &T::confidence_cap_with_update},
      {"confidence_cap_needs_a_pinned_axis", &T::confidence_cap_needs_a_pinned_axis},
      {"cover_unfused_update", &T::cover_unfused_update},
      {"confirm_alias_beyond_alert", &T::confirm_alias_beyond_alert},
      {"alias_rival_must_be_credible", &T::alias_rival_must_be_credible},
      {"alias_trust_needs_steady_fit", &T::alias_trust_needs_steady_fit},
      {"confirm_fix", &T::confirm_fix},
      {"hint_awaits_mml", &T::hint_awaits_mml},
      {"confirm_fix_on_past_scans", &T::confirm_fix_on_past_scans}};
  for (const char* key : {"off", "on"}) {
    const bool value = key[1] == 'n';
    const auto it = options.find(key);
    if (it == options.end()) continue;
    std::string rest = it->second;
    while (!rest.empty()) {
      const std::size_t plus = rest.find('+');
      const std::string name = rest.substr(0, plus);
      rest = plus == std::string::npos ? "" : rest.substr(plus + 1);
      // MML's: the unmapped-space hypothesis before the first fix (map/unmapped_space.h).
      bool found = !value && name == "unmapped_space_contact";
      if (found) mo->unmapped_space_min_area_m2 = 0.0f;
      for (const auto& [rule, member] : kRules) {
        if (name == rule) {
          to->*member = value;
          found = true;
        }
      }
      if (!found) {
        std::string list = "unmapped_space_contact";
        for (const auto& r : kRules) list += ", " + std::string(r.first);
        *err = "localizer mml-track: option " + std::string(key) + "='" + it->second + "': unknown rule '" + name + "' (rules: " + list + ")";
        return false;
      }
    }
  }
  return true;
}

// The product's system (firmware default): MML fix confirmed and tracked with a protection level.
// Options: config=1..4, correct=0|1, reduce=0|1, pool=0|1, keep=0|1, contested=0|1, rivals=0|1 (MML part); alert=M (alert limit, metres);
// odom_noise=TT,TR,RR,RT and odom_noise_per_step=M,DEG (the tracker's odometry noise model, as
// mmlfw's config keys of the same names);
// valley=0|1 (TrackOptions::alias_valley_is_one_mode; default 1, as TrackOptions);
// outside_clean=0|1 (TrackOptions::outside_map_needs_clean_exit; default 1, as TrackOptions);
// wheels_bind=0|1 (TrackOptions::wheels_bind_mml_without_carry; default 1, as TrackOptions);
// odom_slip=RATE,MAX (declared wheel slips, as mmlfw's config key); off=RULE[+RULE...], on=RULE[+RULE...] (ablation);
// global=ref|live|live-deadline|thread (the global search's schedule, mml_systems.h EvalGlobalMode;
// default ref; thread = mmlfw's global_context = thread, on its own thread);
// global_period=1..8 (with live / live-deadline / thread: mmlfw's global_period_scans; default 1).
std::unique_ptr<fw::Localizer> make_track_localizer(const LocalizerContext& ctx, std::string* err) {
  const std::string bad = check_keys("mml-track", ctx.options, {"config", "correct", "reduce", "pool", "keep", "contested", "rivals", "alert", "odom_noise", "odom_noise_per_step", "valley", "outside_clean", "wheels_bind", "odom_slip", "off", "on", "global", "global_period"});
  if (!bad.empty()) { *err = bad; return nullptr; }
  if (ctx.global_map == nullptr) { *err = "localizer mml-track: needs a global map"; return nullptr; }
  const auto g = ctx.options.find("global");
  if (g != ctx.options.end()) {  // mml-eval's --global, for mml-sim and the corpus (a setting of the process)
    if (g->second == "ref") set_eval_global_mode(EvalGlobalMode::kReference);
    else if (g->second == "live") set_eval_global_mode(EvalGlobalMode::kLive);
    else if (g->second == "live-deadline") set_eval_global_mode(EvalGlobalMode::kLiveDeadline);
    else if (g->second == "thread") set_eval_global_mode(EvalGlobalMode::kThread);
    else {
      *err = "localizer mml-track: option global='" + g->second + "' (expected ref, live, live-deadline or thread)";
      return nullptr;
    }
  }
  long period = 1;  // global_period=N: mmlfw's global_period_scans (with global=live or live-deadline)
  if (!parse_int(ctx.options, "global_period", 1, 8, &period, "mml-track", err)) return nullptr;
  if (ctx.options.count("global_period") > 0) set_eval_global_period(static_cast<std::uint32_t>(period));
  long config = 3;
  if (!parse_int(ctx.options, "config", 1, 4, &config, "mml-track", err)) return nullptr;
  auto cfg = mml_track_config(static_cast<int>(config), ctx.seed);
  if (!apply_local_map_options(ctx.options, "mml-track", &cfg, err)) return nullptr;
  fw::track::TrackOptions to;
  const auto a = ctx.options.find("alert");
  if (a != ctx.options.end()) {
    char* end = nullptr;
    const double v = std::strtod(a->second.c_str(), &end);
    if (end == a->second.c_str() || *end != '\0' || !(v > 0.0 && v <= 100.0)) {
      *err = "localizer mml-track: option alert='" + a->second + "' (expected metres in (0, 100])";
      return nullptr;
    }
    to.alert_limit_m = static_cast<float>(v);
    if (to.lost_limit_m < to.alert_limit_m) to.lost_limit_m = to.alert_limit_m;
  }
  if (!parse_odom_noise(ctx.options, &to, err) || !parse_odom_slip(ctx.options, &to, err)) return nullptr;
  long valley = to.alias_valley_is_one_mode ? 1 : 0;  // default: TrackOptions'
  if (!parse_int(ctx.options, "valley", 0, 1, &valley, "mml-track", err)) return nullptr;
  to.alias_valley_is_one_mode = valley == 1;
  long outside_clean = to.outside_map_needs_clean_exit ? 1 : 0;
  if (!parse_int(ctx.options, "outside_clean", 0, 1, &outside_clean, "mml-track", err)) return nullptr;
  to.outside_map_needs_clean_exit = outside_clean == 1;
  long wheels_bind = to.wheels_bind_mml_without_carry ? 1 : 0;
  if (!parse_int(ctx.options, "wheels_bind", 0, 1, &wheels_bind, "mml-track", err)) return nullptr;
  to.wheels_bind_mml_without_carry = wheels_bind == 1;
  if (!parse_rule_switches(ctx.options, &to, &cfg.mml, err)) return nullptr;
  static const std::vector<std::uint8_t> kEmpty;
  return wrap_hooks(OwnedLocalizer::make_track(*ctx.global_map, ctx.map_image ? *ctx.map_image : kEmpty, cfg, to,
                                               ctx.threads, err),
                    ctx);
}

}  // namespace sim::mmleval
