#include "sim/world/synthetic_run.h"

#include <algorithm>
#include <cmath>

namespace sim {

std::string SyntheticRunOptions::validate() const {
  std::string e = route.validate();
  if (e.empty()) e = laser.validate();
  if (e.empty()) e = odometry.validate();
  if (!e.empty()) return e;
  if (!(scan_period_s >= 0.01 && scan_period_s <= 10)) return "scan period must be in [0.01, 10] s";
  if (odometry_per_scan < 1 || odometry_per_scan > 100) return "odometry samples per scan must be in [1, 100]";
  if (!(odometry_phase >= 0 && odometry_phase < 1)) return "odometry phase must be in [0, 1)";
  if (people < -1 || people > 200) return "people count must be in [0, 200]";
  if (!(people_speed > 0 && people_speed < 5)) return "people speed must be in (0, 5) m/s";
  return {};
}

void add_people(World* world, int count, double speed, fw::RandomStream* rng) {
  const RouteGraph& g = world->route;
  if (g.nodes.size() < 2) return;
  for (int i = 0; i < count; ++i) {
    // A straight run of 2–5 edges from a random node: corridor walkers, sometimes into a room.
    int a = static_cast<int>(rng->uniform_index(static_cast<std::uint32_t>(g.nodes.size())));
    if (g.adjacent[a].empty()) continue;
    int b = g.adjacent[a][rng->uniform_index(static_cast<std::uint32_t>(g.adjacent[a].size()))];
    Person p;
    p.path = {g.nodes[a], g.nodes[b]};
    const Vec2 dir = (g.nodes[b] - g.nodes[a]).normalized();
    const int hops = 1 + static_cast<int>(rng->uniform_index(4));
    for (int h = 0; h < hops; ++h) {
      int next = -1;
      for (int c : g.adjacent[b]) {
        if ((g.nodes[c] - g.nodes[b]).normalized().dot(dir) > 0.99) next = c;
      }
      if (next < 0) break;
      p.path.push_back(g.nodes[next]);
      b = next;
    }
    // Walk 0.5 m beside the centre line (people keep to one side; the robot drives the middle).
    const Vec2 side(-dir.y(), dir.x());
    const double offset = rng->uniform01() < 0.5 ? -0.5 : 0.5;
    for (Vec2& q : p.path) q += side * offset;
    p.speed = speed * (0.7 + 0.6 * rng->uniform01());
    p.phase_s = rng->uniform01() * 100.0;
    p.radius = 0.2 + 0.1 * rng->uniform01();
    world->people.push_back(p);
  }
}

fw::Se2d SyntheticRun::truth_at(double t) const {
  if (kidnap_t_ >= 0 && t >= kidnap_t_) return after_kidnap_.pose_at(t - kidnap_t_);
  return trajectory_.pose_at(t);
}

std::uint64_t SyntheticRun::time_ns(double t) const {
  return opt_.start_time_ns + static_cast<std::uint64_t>(std::llround(t * 1e9));
}

bool SyntheticRun::init(const World& world, const SyntheticRunOptions& opt, std::string* err) {
  const std::string bad = opt.validate();
  if (!bad.empty()) {
    if (err) *err = bad;
    return false;
  }
  world_ = world;
  opt_ = opt;
  fw::RandomStream route_rng(opt.seed, 1), people_rng(opt.seed, 4);
  if (!generate_route(world_, opt.route, &route_rng, &trajectory_, &route_nodes_, err)) return false;
  kidnap_t_ = -1;
  odom_teleported_ = false;
  if (opt.kidnap_at_scan > 0) {
    kidnap_t_ = static_cast<double>(opt.kidnap_at_scan) * opt.scan_period_s;
    if (kidnap_t_ >= trajectory_.duration()) {
      if (err) *err = "kidnap at scan " + std::to_string(opt.kidnap_at_scan) + " is after the end of the route";
      return false;
    }
    const fw::Se2d at = trajectory_.pose_at(kidnap_t_);
    const Vec2 here(at.x, at.y);
    RouteOptions ro = opt.route;
    ro.start_node = -1;
    ro.via_unknown = false;
    fw::RandomStream kidnap_rng(opt.seed, 5);
    if (!generate_route(world_, ro, &kidnap_rng, &after_kidnap_, nullptr, err, &here, 10.0)) return false;
  }
  int people = opt.people;
  if (people < 0) {
    const Vec2 size = world_.bounds.max - world_.bounds.min;
    people = std::min(12, static_cast<int>(size.x() * size.y() / 150.0));
  }
  add_people(&world_, people, opt.people_speed, &people_rng);
  index_ = WorldIndex(world_);
  const double duration = kidnap_t_ >= 0 ? kidnap_t_ + after_kidnap_.duration() : trajectory_.duration();
  num_scans_ = static_cast<std::size_t>(std::floor(duration / opt.scan_period_s)) + 1;
  if (opt.max_scans > 0) num_scans_ = std::min(num_scans_, opt.max_scans);
  next_scan_ = 0;
  next_odom_ = 0;
  last_odom_t_ = 0;
  travelled_ = 0;
  laser_rng_.reseed(opt.seed, 3);
  laser_extra_rng_.reseed(opt.seed, 7);
  odom_sim_ = OdometrySimulator(opt.odometry, opt.seed);
  last_truth_ = trajectory_.pose_at(0);
  return true;
}

bool SyntheticRun::next(SyntheticFrame* out) {
  if (next_scan_ >= num_scans_) return false;
  const double t = static_cast<double>(next_scan_) * opt_.scan_period_s;
  const double odom_period = opt_.scan_period_s / opt_.odometry_per_scan;
  out->index = static_cast<std::uint32_t>(next_scan_);
  out->t = t;
  out->truth = truth_at(t);
  const double prev_t = t - opt_.scan_period_s;
  out->kidnapped = kidnap_t_ >= 0 && prev_t < kidnap_t_ && t >= kidnap_t_ && next_scan_ > 0;
  if (out->kidnapped) {
    // Only the driving before the jump and after the new start counts.
    const fw::Se2d before = trajectory_.pose_at(kidnap_t_), after = after_kidnap_.pose_at(0);
    travelled_ += std::hypot(before.x - last_truth_.x, before.y - last_truth_.y) +
                  std::hypot(out->truth.x - after.x, out->truth.y - after.y);
  } else {
    travelled_ += std::hypot(out->truth.x - last_truth_.x, out->truth.y - last_truth_.y);
  }
  last_truth_ = out->truth;
  out->travelled_m = travelled_;
  out->odometry.clear();
  // Odometry sample j is at (j − 1 + phase)·period for j ≥ 1, sample 0 at t = 0 (power-on); emit
  // samples up to and including the first at or after the scan time, so the scan is bracketed.
  while (next_odom_ == 0 || last_odom_t_ < t) {
    const double tau = next_odom_ == 0 ? 0.0 : (static_cast<double>(next_odom_ - 1) + opt_.odometry_phase) * odom_period;
    if (kidnap_t_ >= 0 && tau >= kidnap_t_ && !odom_teleported_) {
      // The odometry delta is taken from the pre-jump pose to the kidnap point, then the reference
      // jumps: the wheels never see the carry.
      odom_teleported_ = true;
      if (last_odom_t_ < kidnap_t_) {
        odom_sim_.next(trajectory_.pose_at(kidnap_t_), time_ns(kidnap_t_), 0.0);
      }
      odom_sim_.teleport(after_kidnap_.pose_at(0));
    }
    const fw::Se2d truth = truth_at(tau);
    if (next_odom_ == 0) {
      out->odometry.push_back(odom_sim_.start(truth, time_ns(tau)));
    } else {
      out->odometry.push_back(odom_sim_.next(truth, time_ns(tau), (tau - last_odom_t_) / opt_.scan_period_s));
    }
    last_odom_t_ = tau;
    ++next_odom_;
  }
  out->scan.timestamp_ns = time_ns(t);
  out->scan.scan_id = static_cast<std::uint32_t>(next_scan_);
  simulate_scan(world_, out->truth, t, opt_.laser, &laser_rng_, &out->scan, &laser_extra_rng_, &index_);
  ++next_scan_;
  return true;
}

}  // namespace sim
