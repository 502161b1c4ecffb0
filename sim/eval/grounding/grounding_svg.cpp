// The picture of the grounding measurement (build/bench/ground.svg): two log-scale scatter panels.
// Left: odometry, translation error per metre vs heading error per metre (5 m windows), p50 with
// whiskers to p95. Right: scan-to-map residuals, p50 (whisker to p90) vs the fraction beyond 0.3 m.
// Real logs are blue squares, profiles orange discs; each point is labelled.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include "sim/eval/grounding/grounding.h"

namespace sim::ground {

namespace {

struct Axis {
  double lo, hi;  // data range (log10 scale)
  double p0, p1;  // pixels
  double at(double v) const {
    const double l = std::log10(std::clamp(v, lo, hi));
    return p0 + (l - std::log10(lo)) / (std::log10(hi) - std::log10(lo)) * (p1 - p0);
  }
};

struct Panel {
  Axis x, y;
  std::string title, xlabel, ylabel;
};

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof(b), "%.1f", v);
  return b;
}

std::string esc(const std::string& t) {
  std::string o;
  for (const char c : t) {
    if (c == '<') o += "&lt;";
    else if (c == '>') o += "&gt;";
    else if (c == '&') o += "&amp;";
    else if (c == '\'') o += "&apos;";
    else o += c;
  }
  return o;
}

std::string tick_label(double v) {
  char b[32];
  std::snprintf(b, sizeof(b), "%g", v);
  return b;
}

void frame(const Panel& p, std::ostringstream& o) {
  o << "<rect x='" << num(p.x.p0) << "' y='" << num(p.y.p1) << "' width='" << num(p.x.p1 - p.x.p0) << "' height='"
    << num(p.y.p0 - p.y.p1) << "' fill='white' stroke='#444'/>\n";
  for (double d = std::pow(10.0, std::floor(std::log10(p.x.lo))); d <= p.x.hi * 1.0001; d *= 10) {
    if (d < p.x.lo * 0.9999) continue;
    o << "<line x1='" << num(p.x.at(d)) << "' y1='" << num(p.y.p0) << "' x2='" << num(p.x.at(d)) << "' y2='"
      << num(p.y.p1) << "' stroke='#ddd'/><text x='" << num(p.x.at(d)) << "' y='" << num(p.y.p0 + 16)
      << "' font-size='11' text-anchor='middle'>" << tick_label(d) << "</text>\n";
  }
  for (double d = std::pow(10.0, std::floor(std::log10(p.y.lo))); d <= p.y.hi * 1.0001; d *= 10) {
    if (d < p.y.lo * 0.9999) continue;
    o << "<line x1='" << num(p.x.p0) << "' y1='" << num(p.y.at(d)) << "' x2='" << num(p.x.p1) << "' y2='"
      << num(p.y.at(d)) << "' stroke='#ddd'/><text x='" << num(p.x.p0 - 6) << "' y='" << num(p.y.at(d) + 4)
      << "' font-size='11' text-anchor='end'>" << tick_label(d) << "</text>\n";
  }
  o << "<text x='" << num((p.x.p0 + p.x.p1) / 2) << "' y='" << num(p.y.p1 - 10)
    << "' font-size='14' text-anchor='middle' font-weight='bold'>" << esc(p.title) << "</text>\n";
  o << "<text x='" << num((p.x.p0 + p.x.p1) / 2) << "' y='" << num(p.y.p0 + 34) << "' font-size='12' text-anchor='middle'>"
    << esc(p.xlabel) << "</text>\n";
  o << "<text transform='translate(" << num(p.x.p0 - 44) << "," << num((p.y.p0 + p.y.p1) / 2)
    << ") rotate(-90)' font-size='12' text-anchor='middle'>" << esc(p.ylabel) << "</text>\n";
}

// A point at (x, y) with whiskers to (x_hi, y) and (x, y_hi) (a whisker ≤ the point is not drawn).
// Label positions already used (pixels), so that close points get their labels stacked, not overlaid.
struct Labels {
  std::vector<std::pair<double, double>> at;
  double place(double x, double y) {
    for (bool moved = true; moved;) {
      moved = false;
      for (const auto& [lx, ly] : at) {
        if (std::fabs(lx - x) < 70 && std::fabs(ly - y) < 12) {
          y = ly + 12;
          moved = true;
        }
      }
    }
    at.emplace_back(x, y);
    return y;
  }
};

void point(const Panel& p, double x, double y, double x_hi, double y_hi, bool log, const std::string& label,
           Labels* labels, std::ostringstream& o) {
  if (!std::isfinite(x) || !std::isfinite(y)) return;
  const std::string c = log ? "#1f5fbf" : "#e07b00";
  const double px = p.x.at(x), py = p.y.at(y);
  if (std::isfinite(x_hi) && x_hi > x) {
    o << "<line x1='" << num(px) << "' y1='" << num(py) << "' x2='" << num(p.x.at(x_hi)) << "' y2='" << num(py)
      << "' stroke='" << c << "' stroke-width='1.5'/>\n";
  }
  if (std::isfinite(y_hi) && y_hi > y) {
    o << "<line x1='" << num(px) << "' y1='" << num(py) << "' x2='" << num(px) << "' y2='" << num(p.y.at(y_hi))
      << "' stroke='" << c << "' stroke-width='1.5'/>\n";
  }
  if (log) {
    o << "<rect x='" << num(px - 5) << "' y='" << num(py - 5) << "' width='10' height='10' fill='" << c << "'/>\n";
  } else {
    o << "<circle cx='" << num(px) << "' cy='" << num(py) << "' r='5.5' fill='" << c << "'/>\n";
  }
  const double ly = labels->place(px + 8, py - 6);
  o << "<text x='" << num(px + 8) << "' y='" << num(ly) << "' font-size='11' fill='" << c << "'>" << esc(label)
    << "</text>\n";
}

}  // namespace

bool write_svg(const GroundReport& r, const std::string& path, std::string* err) {
  const double w = 1180, h = 560;
  std::ostringstream o;
  o << "<svg xmlns='http://www.w3.org/2000/svg' width='" << w << "' height='" << h << "' font-family='sans-serif'>\n"
    << "<rect width='100%' height='100%' fill='#fafafa'/>\n";
  o << "<text x='20' y='24' font-size='15' font-weight='bold'>Real logs (blue squares) and generated profiles (orange "
       "discs): p50, whiskers to p95 (odometry) / p90 (residuals)</text>\n";
  const Panel odo{{0.1, 100, 90, 560}, {0.01, 100, 490, 70}, "Odometry error over 5 m windows",
                  "translation error (% of distance driven)", "heading error (deg per m)"};
  const Panel res{{0.001, 5, 690, 1150}, {0.001, 1, 490, 70}, "Scan-to-map residuals (beams ≤ 30 m)",
                  "residual p50 (m), whisker to p90", "fraction of end-points beyond 0.3 m"};
  frame(odo, o);
  frame(res, o);
  Labels labels;
  for (const OdometryMeasure& m : r.odometry) {
    if (!m.measured) continue;
    const OdometryErrorSummary& s = m.long_w;
    point(odo, 100 * s.trans_p50, s.head_deg_per_m_p50, 100 * s.trans_p95, s.head_deg_per_m_p95, m.is_log, m.name,
          &labels, o);
  }
  for (const ResidualMeasure& m : r.residuals) {
    if (!m.measured) continue;
    point(res, m.s.p50, std::max(m.s.beyond, 0.001), m.s.p90, -1, m.is_log, m.name, &labels, o);
  }
  if (!r.data_present) {
    o << "<text x='20' y='545' font-size='13' fill='#b00'>SKIP real logs: no data in " << esc(r.data_dir) << "</text>\n";
  }
  o << "</svg>\n";
  std::ofstream f(path);
  f << o.str();
  if (!f) {
    if (err != nullptr) *err = "cannot write " + path;
    return false;
  }
  return true;
}

}  // namespace sim::ground
