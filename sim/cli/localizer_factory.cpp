#include "sim/cli/localizer_factory.h"

#include <algorithm>

#include "firmware/runtime/odometry_localizer.h"
#include "sim/eval/mml_eval/mml_systems.h"

namespace sim {

namespace {

struct Entry {
  std::string name, description;
  LocalizerFactoryFn fn;
};

std::unique_ptr<fw::Localizer> make_odom(const LocalizerContext& ctx, std::string* err) {
  const std::string bad = unknown_option_keys("odom", ctx.options, {"anchor"});
  if (!bad.empty()) {
    *err = bad;
    return nullptr;
  }
  fw::OdometryLocalizerOptions opt;
  const auto it = ctx.options.find("anchor");
  const std::string anchor = it == ctx.options.end() ? "origin" : it->second;
  if (anchor == "truth") {
    if (!ctx.has_true_start) {
      *err = "localizer odom: anchor=truth needs a known start pose (synthetic world or --reference)";
      return nullptr;
    }
    opt.initial_pose = ctx.true_start.cast<float>();
  } else if (anchor != "origin") {
    *err = "localizer odom: option anchor='" + anchor + "' (expected origin or truth)";
    return nullptr;
  }
  const fw::Status s = opt.validate();
  if (!s.is_ok()) {
    *err = std::string("localizer odom: ") + s.message();
    return nullptr;
  }
  return std::make_unique<fw::OdometryLocalizer>(opt);
}

// The built-in table. Owners: add your localizer here ({"mml", "...", &make_mml}).
std::vector<Entry>& registry() {
  static std::vector<Entry> entries = {
      {"mml-track",
       "MML global fix, confirmed and tracked on the global map at every scan with a protection level (firmware "
       "default); --opt config=1..4, alert=M, odom_noise=TT,TR,RR,RT, odom_noise_per_step=M,DEG, valley=0|1 (default 1), outside_clean=0|1 (default 1), global=ref|live|live-deadline|thread (default ref)",
       &mmleval::make_track_localizer},
      {"odom", "odometry pass-through (dead reckoning; status always searching); --opt anchor=origin|truth",
       &make_odom},
      {"mml", "MML global localization (RBSM local map + pRANSAM + Ch. 5 constraints); --opt config=1..4, iterations=N",
       &mmleval::make_mml_localizer},
      {"mcl", "MCL baseline (beam model, 18 beams); --opt particles=N, model=beam|field, kld=0|1, inject=0|1",
       &mmleval::make_mcl_localizer},
      {"handoff", "MML global localization handing off to MCL tracking; --opt config=1..4",
       &mmleval::make_handoff_localizer},
  };
  return entries;
}

}  // namespace

void register_localizer(const std::string& name, const std::string& description, LocalizerFactoryFn fn) {
  for (Entry& e : registry()) {
    if (e.name == name) {
      e.description = description;
      e.fn = std::move(fn);
      return;
    }
  }
  registry().push_back({name, description, std::move(fn)});
}

std::vector<LocalizerInfo> localizer_names() {
  std::vector<LocalizerInfo> out;
  for (const Entry& e : registry()) out.push_back({e.name, e.description});
  return out;
}

std::unique_ptr<fw::Localizer> make_localizer(const std::string& name, const LocalizerContext& ctx, std::string* err) {
  for (const Entry& e : registry()) {
    if (e.name == name) {
      std::string local;
      auto loc = e.fn(ctx, &local);
      if (!loc && err) *err = local.empty() ? "localizer " + name + ": could not be created" : local;
      return loc;
    }
  }
  if (err) {
    std::string list;
    for (const Entry& e : registry()) list += (list.empty() ? "" : ", ") + e.name;
    *err = "unknown localizer '" + name + "' (available: " + list + ")";
  }
  return nullptr;
}

}  // namespace sim
