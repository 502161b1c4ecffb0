// The Markdown table of the grounding measurement (build/bench/ground.md).
#include <cmath>
#include <cstdio>
#include <sstream>

#include "sim/eval/grounding/grounding.h"

namespace sim::ground {

namespace {

std::string fmt(const char* f, double v) {
  if (!std::isfinite(v)) return "–";
  char buf[64];
  std::snprintf(buf, sizeof(buf), f, v);
  return buf;
}

std::string pair(const char* f, double p50, double p95) { return fmt(f, p50) + " (" + fmt(f, p95) + ")"; }

void odometry_table(const GroundReport& r, bool long_windows, std::ostringstream& o) {
  o << "| source | windows | path (m) | trans. error %/m p50 (p95) | heading error °/m p50 (p95) | "
       "heading error per rad turned p50 (p95) | distance scale (median, signed) | turn scale (median, signed) |\n"
       "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const OdometryMeasure& m : r.odometry) {
    if (!m.measured) continue;
    const OdometryErrorSummary& s = long_windows ? m.long_w : m.short_w;
    o << "| " << (m.is_log ? "log **" + m.name + "**" : "profile " + m.name) << " | " << s.windows << " | "
      << fmt("%.0f", m.path_m) << " | " << pair("%.2f", 100 * s.trans_p50, 100 * s.trans_p95) << " | "
      << pair("%.2f", s.head_deg_per_m_p50, s.head_deg_per_m_p95) << " | "
      << pair("%.3f", s.head_per_rad_p50, s.head_per_rad_p95) << " | " << fmt("%+.2f %%", 100 * s.dist_scale_median)
      << " | " << fmt("%+.2f %%", 100 * s.turn_scale_median) << " |\n";
  }
}

void residual_table(const GroundReport& r, std::ostringstream& o) {
  o << "| source | scans | end-points | p50 (m) | p90 (m) | p99 (m) | beyond 0.3 m | histogram "
       "0/.05/.1/.15/.2/.3/.5/1 m (%) |\n| --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |\n";
  for (const ResidualMeasure& m : r.residuals) {
    if (!m.measured) continue;
    std::string h;
    for (const double x : m.s.histogram) h += (h.empty() ? "" : " / ") + fmt("%.0f", 100 * x);
    o << "| " << (m.is_log ? "log **" + m.name + "**" : "sensor " + m.name) << " | " << m.s.scans << " | "
      << m.s.points << " | " << fmt("%.3f", m.s.p50) << " | " << fmt("%.3f", m.s.p90) << " | "
      << fmt("%.2f", m.s.p99) << " | " << fmt("%.1f %%", 100 * m.s.beyond) << " | " << h << " |\n";
  }
}

void verdicts(const GroundReport& r, std::ostringstream& o) {
  o << "\n## Verdicts\n\n";
  for (const Verdict& v : r.verdicts) {
    o << "- " << (v.is_odometry ? "odometry profile **" : "sensor profile **") << v.profile << "**: ";
    if (v.resembles.empty()) {
      o << "**no real log resembles it**\n";
      continue;
    }
    o << "resembles";
    for (std::size_t i = 0; i < v.resembles.size(); ++i) o << (i ? ", " : " ") << v.resembles[i];
    o << "\n";
  }
  for (const Verdict& v : r.verdicts) {
    if (!v.through_ref) continue;
    o << "- odometry profile **" << v.profile << "** seen through the fr079-like reference: ";
    if (v.resembles_through_ref.empty()) {
      o << "no real log resembles it\n";
      continue;
    }
    o << "resembles";
    for (std::size_t i = 0; i < v.resembles_through_ref.size(); ++i) o << (i ? ", " : " ") << v.resembles_through_ref[i];
    o << "\n";
  }
  for (const OdometryMeasure& l : r.odometry) {
    if (!l.is_log || !l.measured) continue;
    std::string by;
    for (const Verdict& v : r.verdicts) {
      for (const std::string& x : v.resembles) {
        if (v.is_odometry && x == l.name) by += (by.empty() ? "" : ", ") + v.profile;
      }
    }
    o << "- real log **" << l.name << "** (odometry): " << (by.empty() ? "**no profile spans it**" : "resembled by " + by)
      << "\n";
  }
  for (const ResidualMeasure& l : r.residuals) {
    if (!l.is_log || !l.measured) continue;
    std::string by;
    for (const Verdict& v : r.verdicts) {
      for (const std::string& x : v.resembles) {
        if (!v.is_odometry && x == l.name) by += (by.empty() ? "" : ", ") + v.profile;
      }
    }
    o << "- real log **" << l.name << "** (residuals): " << (by.empty() ? "**no sensor profile spans it**" : "resembled by " + by)
      << "\n";
  }
}

}  // namespace

std::string markdown(const GroundReport& r) {
  std::ostringstream o;
  o << "# Grounding the generated profiles in the real logs (issue 55, item 6)\n\n";
  if (!r.data_present) o << "**SKIP (real logs)**: no data in `" << r.data_dir << "`; only the profiles are measured.\n\n";
  if (!r.profiles_available) {
    o << "Odometry profiles not linked in this build (sim/world/odometry_profiles.cpp absent): the simulated side is "
         "the current default white model only.\n\n";
  }
  if (!r.sensor_profiles_available) {
    o << "Sensor profiles not linked in this build (sim/world/sensor_profiles.cpp absent): the simulated side is the "
         "default laser model only.\n\n";
  }
  o << "One estimator for both sides (sim/eval/grounding/README.md): windows of driven distance between instants "
       "where the reference is measured (corrected poses, relation scans; exact truth in simulation); per window the "
       "odometry increment against the reference increment in the start frame. The reference has its own error "
       "(SLAM-corrected poses: a few cm and about 1 deg; see the rest table), which weighs 5x less per metre over "
       "5 m windows than over 1 m windows.\n\n";
  o << "## Odometry error, 5 m windows (verdicts use these)\n\n";
  odometry_table(r, true, o);
  if (r.ref_sigma_m > 0) {
    o << "\n### The profiles seen through a reference like fr079's (5 m windows)\n\nThe truth plus iid per-pose "
         "errors of " << fmt("%.3f", r.ref_sigma_m) << " m per axis and " << fmt("%.2f", r.ref_sigma_deg)
      << " deg, derived from fr079's reference at rest (p95 = 2.45 sigma sqrt 2 in the plane, 1.96 sigma sqrt 2 in "
         "heading): what the same estimator would report for the profile on a real log with such a reference.\n\n"
         "| profile | windows | trans. error %/m p50 (p95) | heading error deg/m p50 (p95) |\n| --- | ---: | ---: | ---: |\n";
    for (const OdometryMeasure& m : r.odometry) {
      if (!m.through_ref) continue;
      const OdometryErrorSummary& s = m.long_w_ref;
      o << "| " << m.name << " | " << s.windows << " | " << pair("%.2f", 100 * s.trans_p50, 100 * s.trans_p95) << " | "
        << pair("%.2f", s.head_deg_per_m_p50, s.head_deg_per_m_p95) << " |\n";
    }
  }
  o << "\n## Odometry error, 1 m windows (the reference's own error weighs more here)\n\n";
  odometry_table(r, false, o);
  o << "\n## The reference's own motion while the odometry stands still (p95 over consecutive reference poses)\n\n"
       "| log | pairs at rest | m p95 | deg p95 |\n| --- | ---: | ---: | ---: |\n";
  for (const OdometryMeasure& m : r.odometry) {
    if (m.is_log && m.measured) {
      o << "| " << m.name << " | " << m.rest_pairs << " | " << fmt("%.3f", m.rest_m_p95) << " | "
        << fmt("%.2f", m.rest_deg_p95) << " |\n";
    }
  }
  o << "\n## Scan-to-map residuals (end-point to nearest occupied cell, beams ≤ 30 m)\n\n";
  residual_table(r, o);
  o << "\n## Notes per source\n\n";
  for (const OdometryMeasure& m : r.odometry) {
    if (m.measured) o << "- odometry of " << m.name << ": " << m.note << "\n";
  }
  for (const ResidualMeasure& m : r.residuals) {
    if (m.measured) o << "- residuals of " << m.name << ": " << m.note << "\n";
  }
  o << "\n## Not measured\n\n";
  for (const OdometryMeasure& m : r.odometry) {
    if (!m.measured) o << "- odometry of " << m.name << ": " << m.note << "\n";
  }
  for (const ResidualMeasure& m : r.residuals) {
    if (!m.measured) o << "- residuals of " << m.name << ": " << m.note << "\n";
  }
  verdicts(r, o);
  return o.str();
}

}  // namespace sim::ground
