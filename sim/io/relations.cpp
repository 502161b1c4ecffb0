#include "sim/io/relations.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <string_view>

#include "sim/common/units.h"
#include "sim/io/carmen_log.h"
#include "sim/io/text_fields.h"

namespace sim {
namespace {

std::string format_limit(double v) {
  char b[32];
  std::snprintf(b, sizeof(b), "%g", v);
  return b;
}

// Sorted index of the trajectory for nearest-timestamp lookup.
class TimeIndex {
 public:
  explicit TimeIndex(const Trajectory& t) : traj_(t), order_(t.size()) {
    std::iota(order_.begin(), order_.end(), size_t{0});
    std::stable_sort(order_.begin(), order_.end(), [&](size_t a, size_t b) { return t[a].t < t[b].t; });
  }
  const TimedPose* find(double t, double tol) const {
    auto it = std::lower_bound(order_.begin(), order_.end(), t, [&](size_t i, double v) { return traj_[i].t < v; });
    const TimedPose* best = nullptr;
    double best_d = std::numeric_limits<double>::infinity();
    if (it != order_.end()) {
      best = &traj_[*it];
      best_d = std::abs(best->t - t);
    }
    if (it != order_.begin()) {
      // first among equal timestamps before `it`
      auto jt = std::lower_bound(order_.begin(), it, traj_[*(it - 1)].t,
                                 [&](size_t i, double v) { return traj_[i].t < v; });
      const double d = std::abs(traj_[*jt].t - t);
      if (d < best_d) {
        best = &traj_[*jt];
        best_d = d;
      }
    }
    return best && best_d <= tol ? best : nullptr;
  }

 private:
  const Trajectory& traj_;
  std::vector<size_t> order_;
};

void mean_std(const std::vector<double>& v, double* mean, double* sd) {
  if (v.empty()) {
    *mean = *sd = 0.0;
    return;
  }
  double s = 0;
  for (double x : v) s += x;
  *mean = s / static_cast<double>(v.size());
  double q = 0;
  for (double x : v) q += (x - *mean) * (x - *mean);
  *sd = std::sqrt(q / static_cast<double>(v.size()));
}

}  // namespace

bool read_relations(const std::string& path, std::vector<Relation>* out, std::string* error) {
  out->clear();
  std::string data;
  if (!read_file_maybe_gz(path, &data, error)) return false;
  FieldLines lines(data);
  std::vector<std::string_view> tok;
  while (lines.next(8, &tok)) {
    const std::string where = path + ":" + std::to_string(lines.line_no()) + ": ";
    if (tok.size() != 8) {
      *error = where + "expected 8 fields (t1 t2 x y z roll pitch yaw), found " +
               (tok.size() > 8 ? std::string("more") : std::to_string(tok.size()));
      return false;
    }
    double v[8];
    static const char* kNames[8] = {"t1", "t2", "x", "y", "z", "roll", "pitch", "yaw"};
    for (int i = 0; i < 8; ++i) {
      if (!parse_finite_double(tok[static_cast<size_t>(i)], &v[i])) {
        *error = where + "field " + kNames[i] + " is not a finite number: '" +
                 std::string(tok[static_cast<size_t>(i)].substr(0, 40)) + "'";
        return false;
      }
    }
    if (v[4] != 0.0 || v[5] != 0.0 || v[6] != 0.0) {
      *error = where + "z, roll and pitch must be 0 for a 2D relation";
      return false;
    }
    const double limits[8] = {kMaxAbsTimestampS, kMaxAbsTimestampS, kMaxAbsPositionM, kMaxAbsPositionM, 0, 0, 0,
                              kMaxAbsAngleRad};
    for (int i : {0, 1, 2, 3, 7}) {
      if (!(std::fabs(v[i]) <= limits[i])) {
        *error = where + "field " + kNames[i] + " is " + std::string(tok[static_cast<size_t>(i)].substr(0, 40)) +
                 ", outside the plausible ±" + format_limit(limits[i]) + (i < 2 ? " s" : i < 4 ? " m" : " rad");
        return false;
      }
    }
    Relation r;
    r.t1 = v[0];
    r.t2 = v[1];
    r.delta = fw::Se2d(v[2], v[3], v[7]);
    out->push_back(r);
  }
  return true;
}

bool write_relations(const std::string& path, const std::vector<Relation>& rel, std::string* error) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    *error = path + ": cannot open for writing";
    return false;
  }
  for (const auto& r : rel) {
    char a[64], b[64], c[64];
    *std::to_chars(a, a + 63, r.delta.x).ptr = 0;
    *std::to_chars(b, b + 63, r.delta.y).ptr = 0;
    *std::to_chars(c, c + 63, r.delta.theta).ptr = 0;
    std::fprintf(f, "%.6f %.6f %s %s 0 0 0 %s\n", r.t1, r.t2, a, b, c);
  }
  if (std::fclose(f) != 0) {
    *error = path + ": write error";
    return false;
  }
  return true;
}

std::vector<RelationError> relation_errors(const std::vector<Relation>& relations, const Trajectory& trajectory,
                                           double time_tolerance) {
  TimeIndex index(trajectory);
  std::vector<RelationError> out;
  out.reserve(relations.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const auto& r : relations) {
    const TimedPose* a = index.find(r.t1, time_tolerance);
    const TimedPose* b = index.find(r.t2, time_tolerance);
    if (!a || !b) {
      out.push_back({nan, nan});
      continue;
    }
    const fw::Se2d est = a->pose.between(b->pose);
    const fw::Se2d e = r.delta.between(est);
    out.push_back({std::hypot(e.x, e.y), fw::wrap_angle(est.theta - r.delta.theta)});
  }
  return out;
}

RelationsMetric evaluate_relations(const std::vector<Relation>& relations, const Trajectory& trajectory,
                                   double time_tolerance) {
  RelationsMetric m;
  std::vector<double> t, t2, r, r2;
  for (const auto& e : relation_errors(relations, trajectory, time_tolerance)) {
    if (std::isnan(e.trans)) {
      ++m.missing;
      continue;
    }
    const double rd = std::abs(e.rot) * kRadToDeg;
    t.push_back(e.trans);
    t2.push_back(e.trans * e.trans);
    r.push_back(rd);
    r2.push_back(rd * rd);
    m.trans_max = std::max(m.trans_max, e.trans);
    m.rot_max_deg = std::max(m.rot_max_deg, rd);
  }
  m.used = t.size();
  mean_std(t, &m.trans_mean, &m.trans_std);
  mean_std(t2, &m.trans2_mean, &m.trans2_std);
  mean_std(r, &m.rot_mean_deg, &m.rot_std_deg);
  mean_std(r2, &m.rot2_mean, &m.rot2_std);
  return m;
}

RelationsMetricSplit evaluate_relations_split(const std::vector<Relation>& relations, const Trajectory& trajectory,
                                              double split_s, double time_tolerance) {
  RelationsMetricSplit m;
  m.split_s = split_s;
  std::vector<Relation> short_rel, long_rel;
  for (const auto& r : relations) (std::fabs(r.t2 - r.t1) <= split_s ? short_rel : long_rel).push_back(r);
  m.all = evaluate_relations(relations, trajectory, time_tolerance);
  m.short_rel = evaluate_relations(short_rel, trajectory, time_tolerance);
  m.long_rel = evaluate_relations(long_rel, trajectory, time_tolerance);
  return m;
}

bool read_trajectory(const std::string& path, Trajectory* out, std::string* error) {
  out->clear();
  std::string data;
  if (!read_file_maybe_gz(path, &data, error)) return false;
  FieldLines lines(data, /*commas=*/true);
  std::vector<std::string_view> tok;
  while (lines.next(4, &tok)) {
    const std::string where = path + ":" + std::to_string(lines.line_no()) + ": ";
    if (tok.size() != 4) {
      *error = where + "expected 4 fields (t x y theta), found " +
               (tok.size() > 4 ? std::string("more") : std::to_string(tok.size()));
      return false;
    }
    double v[4];
    static const char* kNames[4] = {"t", "x", "y", "theta"};
    for (int i = 0; i < 4; ++i) {
      if (!parse_finite_double(tok[static_cast<size_t>(i)], &v[i])) {
        *error = where + kNames[i] + " is not a finite number: '" + std::string(tok[static_cast<size_t>(i)].substr(0, 40)) + "'";
        return false;
      }
      const double limit = i == 0 ? kMaxAbsTimestampS : i < 3 ? kMaxAbsPositionM : kMaxAbsAngleRad;
      if (!(std::fabs(v[i]) <= limit)) {
        *error = where + kNames[i] + " is " + std::string(tok[static_cast<size_t>(i)].substr(0, 40)) +
                 ", outside the plausible ±" + format_limit(limit) + (i == 0 ? " s" : i < 3 ? " m" : " rad");
        return false;
      }
    }
    out->push_back({v[0], fw::Se2d(v[1], v[2], v[3])});
  }
  return true;
}

bool write_trajectory(const std::string& path, const Trajectory& traj, std::string* error) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    *error = path + ": cannot open for writing";
    return false;
  }
  std::fprintf(f, "# t x y theta\n");
  for (const auto& tp : traj) {
    char a[64], b[64], c[64];
    *std::to_chars(a, a + 63, tp.pose.x).ptr = 0;
    *std::to_chars(b, b + 63, tp.pose.y).ptr = 0;
    *std::to_chars(c, c + 63, tp.pose.theta).ptr = 0;
    std::fprintf(f, "%.6f %s %s %s\n", tp.t, a, b, c);
  }
  if (std::fclose(f) != 0) {
    *error = path + ": write error";
    return false;
  }
  return true;
}

std::string to_string(const RelationsMetric& m) {
  char buf[400];
  std::snprintf(buf, sizeof(buf),
                "used %zu missing %zu | trans %.4f ± %.4f m, trans² %.5f ± %.5f m² (max %.3f m) | rot %.3f ± %.3f deg, "
                "rot² %.3f ± %.3f deg² (max %.2f deg)",
                m.used, m.missing, m.trans_mean, m.trans_std, m.trans2_mean, m.trans2_std, m.trans_max,
                m.rot_mean_deg, m.rot_std_deg, m.rot2_mean, m.rot2_std, m.rot_max_deg);
  return buf;
}

std::string to_string(const RelationsMetricSplit& m) {
  char head[96];
  std::string out = "all: " + to_string(m.all) + "\n";
  std::snprintf(head, sizeof(head), "short (<= %g s): ", m.split_s);
  out += head + to_string(m.short_rel) + "\n";
  std::snprintf(head, sizeof(head), "long (> %g s): ", m.split_s);
  out += head + to_string(m.long_rel);
  return out;
}

}  // namespace sim
