#include "sim/io/reference_trajectory.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <cstdio>
#include <string_view>

#include "sim/common/units.h"
#include "sim/io/text_fields.h"

namespace sim {
namespace {

// A billion scans is 150 days of a 75 Hz laser; a larger index is a corrupt file, not a log.
constexpr unsigned long long kMaxFlaserIndex = 1000000000ull;

fw::Se2d chain(const fw::Se2d& c, const fw::Se2d& o_anchor, const fw::Se2d& o_i) {
  return c.compose(o_anchor.between(o_i));
}

fw::Se2d blend(const fw::Se2d& a, const fw::Se2d& b, double w) {
  return fw::Se2d((1 - w) * a.x + w * b.x, (1 - w) * a.y + w * b.y,
                  fw::wrap_angle(a.theta + w * fw::wrap_angle(b.theta - a.theta)));
}

// Corrected poses usable with this log, with the position of their scan in raw.scans (equal to
// flaser_index unless skip_bad_lines dropped scan lines), in index order. Poses whose scan is not in
// the log (beyond its end, or dropped as malformed) are left out.
struct Anchor {
  size_t pos;
  const CorrectedPose* c;
};
std::vector<Anchor> usable(const CarmenLog& raw, const std::vector<CorrectedPose>& corrected) {
  std::vector<const CorrectedPose*> sorted;
  for (const auto& c : corrected) sorted.push_back(&c);
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const CorrectedPose* a, const CorrectedPose* b) { return a->flaser_index < b->flaser_index; });
  std::vector<Anchor> u;
  for (const CorrectedPose* c : sorted) {
    size_t pos = c->flaser_index;
    if (pos >= raw.scans.size() || raw.scans[pos].index != c->flaser_index) {
      auto it = std::lower_bound(raw.scans.begin(), raw.scans.end(), c->flaser_index,
                                 [](const CarmenScan& s, size_t v) { return s.index < v; });
      if (it == raw.scans.end() || it->index != c->flaser_index) continue;
      pos = static_cast<size_t>(it - raw.scans.begin());
    }
    u.push_back({pos, c});
  }
  return u;
}

}  // namespace

bool read_corrected_poses(const std::string& path, std::vector<CorrectedPose>* out, std::string* error) {
  out->clear();
  std::string data;
  if (!read_file_maybe_gz(path, &data, error)) return false;
  FieldLines lines(data);
  std::vector<std::string_view> tok;
  while (lines.next(6, &tok)) {
    const std::string where = path + ":" + std::to_string(lines.line_no()) + ": ";
    if (tok.size() != 6) {
      *error = where + "expected 6 fields (flaser_index ipc_timestamp logger_timestamp x y theta), found " +
               (tok.size() > 6 ? std::string("more") : std::to_string(tok.size()));
      return false;
    }
    CorrectedPose c;
    unsigned long long idx = 0;
    auto r = std::from_chars(tok[0].data(), tok[0].data() + tok[0].size(), idx);
    if (r.ec != std::errc() || r.ptr != tok[0].data() + tok[0].size()) {
      *error = where + "flaser_index is not a non-negative integer: '" + std::string(tok[0].substr(0, 40)) + "'";
      return false;
    }
    if (idx > kMaxFlaserIndex) {
      *error = where + "flaser_index " + std::to_string(idx) + " is not a plausible scan index (at most " +
               std::to_string(kMaxFlaserIndex) + ")";
      return false;
    }
    c.flaser_index = static_cast<size_t>(idx);
    double v[5];
    static const char* kNames[5] = {"ipc_timestamp", "logger_timestamp", "x", "y", "theta"};
    for (int i = 0; i < 5; ++i) {
      if (!parse_finite_double(tok[static_cast<size_t>(i) + 1], &v[i])) {
        *error = where + kNames[i] + " is not a finite number: '" +
                 std::string(tok[static_cast<size_t>(i) + 1].substr(0, 40)) + "'";
        return false;
      }
      const double limit = i < 2 ? kMaxAbsTimestampS : i < 4 ? kMaxAbsPositionM : kMaxAbsAngleRad;
      if (!(std::fabs(v[i]) <= limit)) {
        char lim[32];
        std::snprintf(lim, sizeof(lim), "%g", limit);
        *error = where + kNames[i] + " is " + std::string(tok[static_cast<size_t>(i) + 1].substr(0, 40)) +
                 ", outside the plausible ±" + lim + (i < 2 ? " s" : i < 4 ? " m" : " rad");
        return false;
      }
    }
    if (!out->empty() && c.flaser_index <= out->back().flaser_index) {
      *error = where + "flaser_index " + std::to_string(c.flaser_index) + " does not increase (previous " +
               std::to_string(out->back().flaser_index) + ")";
      return false;
    }
    c.ipc_timestamp = v[0];
    c.logger_timestamp = v[1];
    c.pose = fw::Se2d(v[2], v[3], v[4]);
    out->push_back(c);
  }
  return true;
}

std::vector<ReferencePose> reference_with_bounds(const CarmenLog& raw, const std::vector<CorrectedPose>& corrected) {
  const auto u = usable(raw, corrected);
  std::vector<ReferencePose> out;
  if (u.empty()) return out;
  const size_t n = raw.scans.size();
  out.resize(n);
  const double inf = std::numeric_limits<double>::infinity();
  auto odo = [&](size_t i) -> const fw::Se2d& { return raw.scans[i].odom; };
  // Before the first corrected pose: backward chain only.
  for (size_t i = 0; i < u.front().pos; ++i) {
    out[i].pose = chain(u.front().c->pose, odo(u.front().pos), odo(i));
    out[i].bound = out[i].bound_theta = inf;
  }
  for (size_t k = 0; k < u.size(); ++k) {
    const size_t a = u[k].pos;
    out[a].pose = u[k].c->pose;
    out[a].exact = true;
    if (k + 1 == u.size()) {
      for (size_t i = a + 1; i < n; ++i) {
        out[i].pose = chain(u[k].c->pose, odo(a), odo(i));
        out[i].bound = out[i].bound_theta = inf;
      }
      break;
    }
    const size_t b = u[k + 1].pos;
    const fw::Se2d closure = chain(u[k].c->pose, odo(a), odo(b)).between(u[k + 1].c->pose);
    const double r = std::hypot(closure.x, closure.y);
    const double dd = static_cast<double>(b - a);
    for (size_t i = a + 1; i < b; ++i) {
      const double w = static_cast<double>(i - a) / dd;
      const fw::Se2d f = chain(u[k].c->pose, odo(a), odo(i));
      const fw::Se2d bb = chain(u[k + 1].c->pose, odo(b), odo(i));
      out[i].pose = blend(f, bb, w);
      out[i].bound = ((1.0 - w) * std::sqrt(w) + w * std::sqrt(1.0 - w)) * r;
      out[i].bound_theta = ((1.0 - w) * std::sqrt(w) + w * std::sqrt(1.0 - w)) * std::fabs(closure.theta);
    }
  }
  return out;
}

std::vector<fw::Se2d> reference_at_every_scan(const CarmenLog& raw, const std::vector<CorrectedPose>& corrected) {
  std::vector<fw::Se2d> out;
  for (const auto& r : reference_with_bounds(raw, corrected)) out.push_back(r.pose);
  return out;
}

ReferenceGapStats reference_gap_stats(const CarmenLog& raw, const std::vector<CorrectedPose>& corrected) {
  const auto u = usable(raw, corrected);
  ReferenceGapStats s;
  for (size_t k = 0; k + 1 < u.size(); ++k) {
    const size_t a = u[k].pos, b = u[k + 1].pos;
    const fw::Se2d closure = chain(u[k].c->pose, raw.scans[a].odom, raw.scans[b].odom).between(u[k + 1].c->pose);
    const double r = std::hypot(closure.x, closure.y);
    const double rd = std::abs(closure.theta) * kRadToDeg;
    ++s.gaps;
    s.mean_gap_scans += static_cast<double>(b - a);
    s.max_gap_scans = std::max(s.max_gap_scans, static_cast<double>(b - a));
    s.mean_closure_m += r;
    s.max_closure_m = std::max(s.max_closure_m, r);
    s.mean_closure_deg += rd;
    s.max_closure_deg = std::max(s.max_closure_deg, rd);
  }
  if (s.gaps > 0) {
    s.mean_gap_scans /= static_cast<double>(s.gaps);
    s.mean_closure_m /= static_cast<double>(s.gaps);
    s.mean_closure_deg /= static_cast<double>(s.gaps);
  }
  return s;
}

bool corrected_poses_from_relations(const CarmenLog& raw, const std::vector<Relation>& relations,
                                    std::vector<CorrectedPose>* out, std::string* error) {
  out->clear();
  // Timestamp → scan index.
  std::vector<size_t> order(raw.scans.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return raw.scans[a].ipc_timestamp < raw.scans[b].ipc_timestamp; });
  auto lookup = [&](double t, size_t* idx) {
    auto it = std::lower_bound(order.begin(), order.end(), t,
                               [&](size_t i, double v) { return raw.scans[i].ipc_timestamp < v; });
    double best = 1e-4;
    bool found = false;
    for (auto jt : {it, it == order.begin() ? it : it - 1}) {
      if (jt == order.end()) continue;
      const double d = std::abs(raw.scans[*jt].ipc_timestamp - t);
      if (d <= best) {
        best = d;
        *idx = *jt;
        found = true;
      }
    }
    return found;
  };
  std::map<size_t, std::vector<std::pair<size_t, size_t>>> adj;  // scan → (relation, other scan)
  for (size_t r = 0; r < relations.size(); ++r) {
    size_t a = 0, b = 0;
    for (double t : {relations[r].t1, relations[r].t2}) {
      size_t dummy;
      if (!lookup(t, &dummy)) {
        char buf[64];
        std::snprintf(buf, sizeof(buf), "%.6f", t);
        *error = std::string("relation ") + std::to_string(r + 1) + ": timestamp " + buf + " is not a scan of " + raw.path;
        return false;
      }
    }
    lookup(relations[r].t1, &a);
    lookup(relations[r].t2, &b);
    adj[a].push_back({r, b});
    adj[b].push_back({r, a});
  }
  std::map<size_t, fw::Se2d> placed;
  for (const auto& [start, unused] : adj) {  // scan order
    if (placed.count(start)) continue;
    if (placed.empty()) {
      placed[start] = fw::Se2d();
    } else {
      auto it = placed.lower_bound(start);  // nearest placed scan (before, else after)
      const size_t p = it == placed.begin() ? it->first : std::prev(it)->first;
      placed[start] = placed[p].compose(raw.scans[p].odom.between(raw.scans[start].odom));
    }
    std::vector<size_t> queue{start};
    for (size_t q = 0; q < queue.size(); ++q) {
      const size_t u = queue[q];
      for (const auto& [r, v] : adj[u]) {
        if (placed.count(v)) continue;
        const Relation& rel = relations[r];
        size_t a = 0;
        lookup(rel.t1, &a);
        placed[v] = a == u ? placed[u].compose(rel.delta) : placed[u].compose(rel.delta.inverse());
        queue.push_back(v);
      }
    }
  }
  for (const auto& [idx, pose] : placed) {
    out->push_back({raw.scans[idx].index, raw.scans[idx].ipc_timestamp, raw.scans[idx].logger_timestamp, pose});
  }
  return true;
}

Trajectory odometry_trajectory(const CarmenLog& raw) {
  Trajectory t;
  t.reserve(raw.scans.size());
  for (const auto& s : raw.scans) t.push_back({s.ipc_timestamp, s.odom});
  return t;
}

Trajectory make_trajectory(const CarmenLog& raw, const std::vector<fw::Se2d>& poses) {
  Trajectory t;
  const size_t n = std::min(raw.scans.size(), poses.size());
  t.reserve(n);
  for (size_t i = 0; i < n; ++i) t.push_back({raw.scans[i].ipc_timestamp, poses[i]});
  return t;
}

}  // namespace sim
