// run_grounding, the verdicts, and the JSON and Markdown outputs.
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "sim/eval/grounding/grounding.h"
#include "sim/io/datasets.h"
#include "sim/map/global_maps.h"
#ifdef MMLFW_GROUND_ODOMETRY_PROFILES
#include "sim/world/odometry_profiles.h"
#endif
#ifdef MMLFW_GROUND_SENSOR_PROFILES
#include "sim/world/sensor_profiles.h"
#endif

namespace sim::ground {

namespace {

bool wanted(const GroundOptions& opt, const std::string& name) {
  if (opt.logs.empty()) return true;
  for (const std::string& l : opt.logs) {
    if (l == name) return true;
  }
  return false;
}

bool within(double x, double lo, double hi) { return std::isfinite(x) && x >= lo && x <= hi; }

std::string key_name(const std::string& name) {
  std::string k = name;
  for (char& c : k) {
    if (c == '-' || c == '.' || c == ' ') c = '_';
  }
  return k;
}

void progress(const GroundOptions& opt, const std::string& what) {
  if (!opt.progress) return;
  std::fprintf(stderr, "mml-ground: %s\n", what.c_str());
  std::fflush(stderr);
}

void run_real(const GroundOptions& opt, GroundReport* r) {
  for (const std::string& ds : odometry_datasets()) {
    if (!wanted(opt, ds)) continue;
    progress(opt, "odometry of " + ds + " ...");
    OdometryMeasure m;
    std::string err;
    if (!measure_log_odometry(ds, opt, &m, &err)) m.note = "not measured: " + err;
    r->odometry.push_back(m);
  }
  const char* skipped[][2] = {{"mit-killian", "no raw odometry in the log (ODOM records absent)"},
                              {"fr101", "corrected log only (no raw odometry)"},
                              {"fr-campus", "corrected log only (no raw odometry)"}};
  for (const auto& s : skipped) {
    if (!wanted(opt, s[0])) continue;
    OdometryMeasure m;
    m.name = s[0];
    m.note = std::string("skipped: ") + s[1];
    r->odometry.push_back(m);
  }
  for (const std::string& ds : residual_datasets()) {
    if (!wanted(opt, ds)) continue;
    progress(opt, "scan-to-map residuals of " + ds + " (map: " + global_map_yaml_path(ds) + ") ...");
    ResidualMeasure m;
    std::string err;
    if (!measure_log_residuals(ds, opt, &m, &err)) {
      m.name = ds;
      m.note = "not measured: " + err;
    }
    r->residuals.push_back(m);
  }
}

void run_simulated(const GroundOptions& opt, GroundReport* r) {
  std::vector<std::pair<std::string, OdometryNoiseOptions>> wheels;
#ifdef MMLFW_GROUND_ODOMETRY_PROFILES
  for (const OdometryProfile& p : odometry_profiles()) wheels.emplace_back(p.name, p.wheels);
  r->profiles_available = true;
#else
  wheels.emplace_back("white-default", OdometryNoiseOptions{});
#endif
  for (const auto& [name, w] : wheels) {
    progress(opt, "odometry profile " + name + " (" + std::to_string(opt.sim_seeds) + " runs in " + opt.world + ") ...");
    OdometryMeasure m;
    std::string err;
    if (!measure_profile_odometry(name, w, opt, &m, &err)) m.note = "not measured: " + err;
    r->odometry.push_back(m);
  }
  std::vector<std::pair<std::string, LaserModelOptions>> lasers;
#ifdef MMLFW_GROUND_SENSOR_PROFILES
  for (const SensorProfile& p : sensor_profiles()) lasers.emplace_back(p.name, p.laser);
  r->sensor_profiles_available = true;
#else
  lasers.emplace_back("default-laser", LaserModelOptions{});
#endif
  for (const auto& [name, l] : lasers) {
    progress(opt, "sensor profile " + name + " ...");
    ResidualMeasure m;
    std::string err;
    if (!measure_sensor_residuals(name, l, opt, &m, &err)) m.note = "not measured: " + err;
    r->residuals.push_back(m);
  }
}

}  // namespace

bool odometry_resembles(const OdometryErrorSummary& p, const OdometryErrorSummary& l) {
  return within(p.trans_p50, l.trans_p10, l.trans_p90) && within(l.trans_p50, p.trans_p10, p.trans_p90) &&
         within(p.head_deg_per_m_p50, l.head_deg_per_m_p10, l.head_deg_per_m_p90) &&
         within(l.head_deg_per_m_p50, p.head_deg_per_m_p10, p.head_deg_per_m_p90);
}

bool residuals_resemble(const ResidualSummary& p, const ResidualSummary& l) {
  return within(p.p90, l.p50, l.p99) && within(l.p90, p.p50, p.p99);
}

void add_verdicts(GroundReport* r) {
  r->verdicts.clear();
  for (const OdometryMeasure& p : r->odometry) {
    if (p.is_log || !p.measured) continue;
    Verdict v{p.name, true, {}, p.through_ref, {}};
    for (const OdometryMeasure& l : r->odometry) {
      if (!l.is_log || !l.measured) continue;
      if (odometry_resembles(p.long_w, l.long_w)) v.resembles.push_back(l.name);
      if (p.through_ref && odometry_resembles(p.long_w_ref, l.long_w)) v.resembles_through_ref.push_back(l.name);
    }
    r->verdicts.push_back(v);
  }
  for (const ResidualMeasure& p : r->residuals) {
    if (p.is_log || !p.measured) continue;
    Verdict v{p.name, false, {}, false, {}};
    for (const ResidualMeasure& l : r->residuals) {
      if (l.is_log && l.measured && residuals_resemble(p.s, l.s)) v.resembles.push_back(l.name);
    }
    r->verdicts.push_back(v);
  }
}

GroundReport run_grounding(const GroundOptions& opt) {
  GroundReport r;
  r.data_dir = data_dir();
  for (const Dataset& d : datasets()) {
    const std::string f = !d.raw_log.empty() ? d.raw_log : d.corrected_log;
    if (!f.empty() && std::filesystem::exists(data_path(f))) r.data_present = true;
  }
  GroundOptions o = opt;
  if (opt.real && r.data_present) run_real(opt, &r);
  for (const OdometryMeasure& m : r.odometry) {
    if (m.is_log && m.name == "fr079" && m.measured && o.ref_sigma_m == 0) {
      rest_noise_from(m, &o.ref_sigma_m, &o.ref_sigma_deg);
    }
  }
  r.ref_sigma_m = o.ref_sigma_m;
  r.ref_sigma_deg = o.ref_sigma_deg;
  if (opt.simulated) run_simulated(o, &r);
  add_verdicts(&r);
  return r;
}

void add_json(const GroundReport& r, BenchJson* json) {
  json->add_bool("ground_data_present", r.data_present);
  json->add_bool("ground_odometry_profiles_linked", r.profiles_available);
  json->add_bool("ground_sensor_profiles_linked", r.sensor_profiles_available);
  json->add("ground_ref_sigma_m", r.ref_sigma_m);
  json->add("ground_ref_sigma_deg", r.ref_sigma_deg);
  if (!r.data_present) json->add_string("ground_note", "SKIP real logs: no data in " + r.data_dir);
  for (const OdometryMeasure& m : r.odometry) {
    if (!m.measured) continue;
    const std::string k = "ground_" + std::string(m.is_log ? "" : "profile_") + key_name(m.name) + "_";
    const OdometryErrorSummary& l = m.long_w;
    json->add_int(k + "windows", static_cast<long long>(l.windows));
    json->add(k + "trans_err_per_m_p50", l.trans_p50);
    json->add(k + "trans_err_per_m_p95", l.trans_p95);
    json->add(k + "head_err_deg_per_m_p50", l.head_deg_per_m_p50);
    json->add(k + "head_err_deg_per_m_p95", l.head_deg_per_m_p95);
    json->add(k + "head_err_per_rad_p50", l.head_per_rad_p50);
    json->add(k + "head_err_per_rad_p95", l.head_per_rad_p95);
    json->add(k + "dist_scale_median", l.dist_scale_median);
    json->add(k + "turn_scale_median", l.turn_scale_median);
    const OdometryErrorSummary& s = m.short_w;
    json->add_int(k + "1m_windows", static_cast<long long>(s.windows));
    json->add(k + "1m_trans_err_per_m_p50", s.trans_p50);
    json->add(k + "1m_trans_err_per_m_p95", s.trans_p95);
    json->add(k + "1m_head_err_deg_per_m_p50", s.head_deg_per_m_p50);
    json->add(k + "1m_head_err_deg_per_m_p95", s.head_deg_per_m_p95);
    json->add(k + "1m_head_err_per_rad_p50", s.head_per_rad_p50);
    json->add(k + "1m_head_err_per_rad_p95", s.head_per_rad_p95);
    if (m.is_log) {
      json->add(k + "ref_rest_m_p95", m.rest_m_p95);
      json->add(k + "ref_rest_deg_p95", m.rest_deg_p95);
    }
    if (m.through_ref) {
      json->add(k + "through_ref_trans_err_per_m_p50", m.long_w_ref.trans_p50);
      json->add(k + "through_ref_trans_err_per_m_p95", m.long_w_ref.trans_p95);
      json->add(k + "through_ref_head_err_deg_per_m_p50", m.long_w_ref.head_deg_per_m_p50);
      json->add(k + "through_ref_head_err_deg_per_m_p95", m.long_w_ref.head_deg_per_m_p95);
    }
  }
  for (const ResidualMeasure& m : r.residuals) {
    if (!m.measured) continue;
    const std::string k = "ground_" + std::string(m.is_log ? "" : "sensor_") + key_name(m.name) + "_residual_";
    json->add_int(k + "points", static_cast<long long>(m.s.points));
    json->add(k + "m_p50", m.s.p50);
    json->add(k + "m_p90", m.s.p90);
    json->add(k + "m_p99", m.s.p99);
    json->add(k + "beyond_0_3m", m.s.beyond);
  }
  for (const Verdict& v : r.verdicts) {
    std::string list;
    for (const std::string& l : v.resembles) list += (list.empty() ? "" : ",") + l;
    const std::string k = "ground_" + std::string(v.is_odometry ? "profile_" : "sensor_") + key_name(v.profile);
    json->add_string(k + "_resembles", list.empty() ? "none" : list);
    if (!v.through_ref) continue;
    std::string list2;
    for (const std::string& l : v.resembles_through_ref) list2 += (list2.empty() ? "" : ",") + l;
    json->add_string(k + "_resembles_through_ref", list2.empty() ? "none" : list2);
  }
  int unspanned = 0, logs = 0;
  for (const OdometryMeasure& l : r.odometry) {
    if (!l.is_log || !l.measured) continue;
    ++logs;
    std::string by;
    for (const Verdict& v : r.verdicts) {
      for (const std::string& x : v.resembles) {
        if (v.is_odometry && x == l.name) by += (by.empty() ? "" : ",") + v.profile;
      }
    }
    if (by.empty()) ++unspanned;
    json->add_string("ground_" + key_name(l.name) + "_resembled_by", by.empty() ? "none" : by);
  }
  json->add_int("ground_logs_measured", logs);
  json->add_int("ground_logs_no_profile_resembles", unspanned);
}

}  // namespace sim::ground
