#include "sim/world/route.h"

#include <algorithm>
#include <cmath>

namespace sim {

std::string RouteOptions::validate() const {
  if (!(length_m >= 0 && std::isfinite(length_m))) return "route length must be ≥ 0";
  if (!(speed > 0 && speed < 10)) return "route speed must be in (0, 10) m/s";
  if (!(turn_rate_deg > 0 && turn_rate_deg <= 720)) return "route turn rate must be in (0, 720] deg/s";
  if (!(straight_weight > 0 && unvisited_weight > 0 && room_weight > 0)) return "route choice weights must be > 0";
  const bool no_leg_speeds = speed_min == 0 && speed_max == 0;
  if (!no_leg_speeds && !(speed_min > 0 && speed_min <= speed_max && speed_max < 10)) {
    return "route speed_min, speed_max must both be 0 or 0 < speed_min <= speed_max < 10 m/s";
  }
  if (!(stop_probability >= 0 && stop_probability <= 1)) return "route stop_probability must be in [0, 1]";
  if (!(stop_min_s >= 0 && stop_min_s <= stop_max_s && stop_max_s <= 600)) {
    return "route stop_min_s, stop_max_s must be 0 <= stop_min_s <= stop_max_s <= 600 s";
  }
  return {};
}

double default_route_length(const World& world) {
  const Vec2 size = world.bounds.max - world.bounds.min;
  // About one and a half times the building's long side plus its short side: enough corridor
  // to resolve the ambiguity of the large office (the dissertation needed ~300 steps).
  return std::max(30.0, 1.5 * (size.x() + size.y()));
}

void RouteTrajectory::start_at(const fw::Se2d& pose) {
  pieces_.clear();
  end_ = pose;
  length_ = 0;
}

void RouteTrajectory::add_turn(double target_heading, double turn_rate) {
  const double d = fw::wrap_angle(target_heading - end_.theta);
  if (std::fabs(d) < 1e-9) return;
  const double t0 = duration();
  const double dur = std::fabs(d) / turn_rate;
  pieces_.push_back({t0, t0 + dur, end_, 0.0, d > 0 ? turn_rate : -turn_rate});
  end_ = fw::Se2d(end_.x, end_.y, fw::wrap_angle(target_heading));
}

void RouteTrajectory::add_drive(const Vec2& to, double speed) {
  const Vec2 from(end_.x, end_.y);
  const double len = (to - from).norm();
  if (len < 1e-9) return;
  const double t0 = duration();
  pieces_.push_back({t0, t0 + len / speed, end_, speed, 0.0});
  end_ = fw::Se2d(to.x(), to.y(), end_.theta);
  length_ += len;
}

void RouteTrajectory::add_stop(double duration_s) {
  if (!(duration_s > 0)) return;
  const double t0 = duration();
  pieces_.push_back({t0, t0 + duration_s, end_, 0.0, 0.0});
}

fw::Se2d RouteTrajectory::pose_at(double t) const {
  if (pieces_.empty()) return end_;
  if (t <= 0) return pieces_.front().start;
  if (t >= duration()) return end_;
  // Binary search for the piece containing t.
  const auto it = std::upper_bound(pieces_.begin(), pieces_.end(), t, [](double v, const Piece& p) { return v < p.t1; });
  const Piece& p = it == pieces_.end() ? pieces_.back() : *it;
  const double dt = t - p.t0;
  if (p.omega == 0.0 && p.v == 0.0) return p.start;  // a stop
  if (p.omega != 0.0) return fw::Se2d(p.start.x, p.start.y, fw::wrap_angle(p.start.theta + p.omega * dt));
  return fw::Se2d(p.start.x + std::cos(p.start.theta) * p.v * dt, p.start.y + std::sin(p.start.theta) * p.v * dt,
                  p.start.theta);
}

namespace {
bool in_unknown(const World& w, const Vec2& p) {
  for (const Box& b : w.unknown_areas) {
    if (b.contains(p)) return true;
  }
  return false;
}

// Dijkstra from `start` to the nearest node inside an unknown area; *path = the nodes to drive
// through to it, in order, `start` excluded. False when no unknown area is reachable.
bool path_to_unknown(const World& world, int start, std::vector<int>* path) {
  const RouteGraph& g = world.route;
  const size_t n = g.nodes.size();
  std::vector<double> dist(n, 1e300);
  std::vector<int> from(n, -1);
  std::vector<bool> done(n, false);
  dist[start] = 0;
  int target = -1;
  for (;;) {
    int u = -1;
    for (size_t i = 0; i < n; ++i) {
      if (!done[i] && dist[i] < 1e299 && (u < 0 || dist[i] < dist[u])) u = static_cast<int>(i);
    }
    if (u < 0) break;
    done[u] = true;
    if (in_unknown(world, g.nodes[u])) {
      target = u;
      break;
    }
    for (int v : g.adjacent[u]) {
      const double d = dist[u] + (g.nodes[v] - g.nodes[u]).norm();
      if (d < dist[v]) {
        dist[v] = d;
        from[v] = u;
      }
    }
  }
  if (target < 0) return false;
  path->clear();
  for (int v = target; v != start; v = from[v]) path->push_back(v);
  std::reverse(path->begin(), path->end());
  return true;
}

// Issue 55: the speed of each leg and a stop on arriving at a node (RouteOptions::varied_motion).
// Its stream is seeded from a copy of the route's, which it does not advance: the path (start node,
// heading, choices) is the same with or without these, and a default route draws nothing here.
class LegMotion {
 public:
  LegMotion(const RouteOptions& opt, const fw::RandomStream& route_rng) : opt_(opt) {
    if (!opt.varied_motion()) return;
    fw::RandomStream copy = route_rng;
    const std::uint64_t hi = copy.next_u32();
    const std::uint64_t lo = copy.next_u32();
    rng_.reseed((hi << 32) | lo, 0x524f555445ULL);
  }
  double speed() {
    if (!(opt_.speed_max > 0)) return opt_.speed;
    return opt_.speed_min + (opt_.speed_max - opt_.speed_min) * rng_.uniform01();
  }
  // The robot reached a node; `length` is the route's length (no stop once it is driven).
  void arrive(RouteTrajectory* out, double length) {
    if (!(opt_.stop_probability > 0)) return;
    if (!(rng_.uniform01() < opt_.stop_probability)) return;
    const double duration = opt_.stop_min_s + (opt_.stop_max_s - opt_.stop_min_s) * rng_.uniform01();
    if (out->length() < length) out->add_stop(duration);
  }

 private:
  const RouteOptions& opt_;
  fw::RandomStream rng_;
};
}  // namespace

bool generate_route(const World& world, const RouteOptions& opt, fw::RandomStream* rng, RouteTrajectory* out,
                    std::vector<int>* visited_nodes, std::string* err, const Vec2* exclude_near,
                    double exclude_radius) {
  const std::string bad = opt.validate();
  if (!bad.empty()) {
    if (err) *err = bad;
    return false;
  }
  LegMotion legs(opt, *rng);
  const RouteGraph& g = world.route;
  std::vector<int> allowed;
  for (size_t i = 0; i < g.nodes.size(); ++i) {
    const bool blocked = (opt.avoid_unknown || opt.via_unknown) && in_unknown(world, g.nodes[i]);
    const bool too_near = exclude_near != nullptr && (g.nodes[i] - *exclude_near).norm() <= exclude_radius;
    if (!blocked && !too_near && !g.adjacent[i].empty()) allowed.push_back(static_cast<int>(i));
  }
  if (allowed.empty()) {
    if (err) *err = "world '" + world.name + "' has no route graph to drive on";
    return false;
  }
  int cur;
  if (opt.start_node >= 0) {
    if (opt.start_node >= static_cast<int>(g.nodes.size()) || g.adjacent[opt.start_node].empty()) {
      if (err) *err = "route start node " + std::to_string(opt.start_node) + " is not a connected node of world '" +
                      world.name + "' (" + std::to_string(g.nodes.size()) + " nodes)";
      return false;
    }
    cur = opt.start_node;
  } else {
    cur = allowed[rng->uniform_index(static_cast<std::uint32_t>(allowed.size()))];
  }
  const double length = opt.length_m > 0 ? opt.length_m : default_route_length(world);
  const double turn_rate = opt.turn_rate_deg * M_PI / 180.0;
  const double heading0 = (rng->uniform01() * 2.0 - 1.0) * M_PI;  // unknown start heading too
  out->start_at(fw::Se2d(g.nodes[cur].x(), g.nodes[cur].y(), heading0));
  if (visited_nodes) visited_nodes->assign(1, cur);
  int prev = -1;
  std::vector<bool> visited(g.nodes.size(), false);
  visited[cur] = true;
  bool avoid_unknown = opt.avoid_unknown;
  if (opt.via_unknown) {
    std::vector<int> path;
    if (!path_to_unknown(world, cur, &path)) {
      if (err) *err = "world '" + world.name + "' has no unknown area reachable by the route graph";
      return false;
    }
    for (auto it = path.begin(); it != path.end() && out->length() < length; ++it) {
      const Vec2 d = g.nodes[*it] - g.nodes[cur];
      out->add_turn(std::atan2(d.y(), d.x()), turn_rate);
      const double remaining = length - out->length();
      const Vec2 to = d.norm() > remaining ? Vec2(g.nodes[cur] + d.normalized() * remaining) : g.nodes[*it];
      out->add_drive(to, legs.speed());
      prev = cur;
      cur = *it;
      visited[cur] = true;
      if (visited_nodes) visited_nodes->push_back(cur);
      legs.arrive(out, length);
    }
    avoid_unknown = false;
  }
  for (int guard = 0; out->length() < length && guard < 100000; ++guard) {
    std::vector<int> cand;
    std::vector<double> weight;
    for (int n : g.adjacent[cur]) {
      if (avoid_unknown && in_unknown(world, g.nodes[n])) continue;
      if (n == prev && g.adjacent[cur].size() > 1) continue;
      cand.push_back(n);
      double wgt = 1.0;
      if (prev >= 0) {
        const Vec2 d_in = (g.nodes[cur] - g.nodes[prev]).normalized();
        const Vec2 d_out = (g.nodes[n] - g.nodes[cur]).normalized();
        if (d_in.dot(d_out) > 0.95) wgt *= opt.straight_weight;
      }
      if (!visited[n]) wgt *= opt.unvisited_weight;
      if (g.kinds[cur] == RouteGraph::kCorridor && g.kinds[n] == RouteGraph::kDoorway) wgt *= opt.room_weight;
      weight.push_back(wgt);
    }
    if (cand.empty()) {  // dead end that is only reachable back through prev
      if (prev < 0) break;
      cand.push_back(prev);
      weight.push_back(1.0);
    }
    double total = 0;
    for (double w : weight) total += w;
    double r = rng->uniform01() * total;
    size_t pick = 0;
    while (pick + 1 < cand.size() && r >= weight[pick]) r -= weight[pick++];
    const int next = cand[pick];
    const Vec2 d = g.nodes[next] - g.nodes[cur];
    out->add_turn(std::atan2(d.y(), d.x()), turn_rate);
    // Stop exactly at the requested length.
    const double remaining = length - out->length();
    const Vec2 to = d.norm() > remaining ? Vec2(g.nodes[cur] + d.normalized() * remaining) : g.nodes[next];
    out->add_drive(to, legs.speed());
    prev = cur;
    cur = next;
    visited[cur] = true;
    if (visited_nodes) visited_nodes->push_back(cur);
    legs.arrive(out, length);
  }
  return true;
}

}  // namespace sim
