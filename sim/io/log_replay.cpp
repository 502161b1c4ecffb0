#include "sim/io/log_replay.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sim {

std::vector<ReplayEvent> make_replay_events(const CarmenLog& log, const ReplayOptions& options) {
  struct Item {
    double t;
    size_t line;
    ReplayEvent e;
  };
  std::vector<Item> items;
  items.reserve(log.scans.size() * 2 + log.odom.size());
  const bool odom_records = !log.odom.empty();
  if (options.include_odometry && odom_records) {
    for (size_t i = 0; i < log.odom.size(); ++i) {
      ReplayEvent e;
      e.kind = ReplayEvent::Kind::kOdometry;
      e.index = i;
      items.push_back({log.odom[i].ipc_timestamp, log.odom[i].line, e});
    }
  }
  for (size_t i = 0; i < log.scans.size(); ++i) {
    if (options.include_odometry && !odom_records) {
      ReplayEvent o;
      o.kind = ReplayEvent::Kind::kOdometry;
      o.odom_from_scan = true;
      o.index = i;
      items.push_back({log.scans[i].ipc_timestamp, log.scans[i].line, o});
    }
    ReplayEvent e;
    e.kind = ReplayEvent::Kind::kScan;
    e.index = i;
    items.push_back({log.scans[i].ipc_timestamp, log.scans[i].line, e});
  }
  // File order (line, then odometry before scan for scan-borne odometry).
  std::stable_sort(items.begin(), items.end(), [](const Item& a, const Item& b) { return a.line < b.line; });
  double t0 = std::numeric_limits<double>::infinity();
  for (const auto& it : items) t0 = std::min(t0, it.t);
  if (options.order == ReplayOptions::Order::kSortByTime) {
    std::stable_sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
      if (a.t != b.t) return a.t < b.t;
      return a.e.kind == ReplayEvent::Kind::kOdometry && b.e.kind == ReplayEvent::Kind::kScan;
    });
  }
  std::vector<ReplayEvent> out;
  out.reserve(items.size());
  std::uint64_t prev = 0;
  for (const auto& it : items) {
    ReplayEvent e = it.e;
    e.t_ns = std::max(prev, seconds_to_ns(it.t - t0));
    prev = e.t_ns;
    out.push_back(e);
  }
  return out;
}

std::uint64_t seconds_to_ns(double seconds) {
  if (!(seconds > 0.0)) return 0;
  if (seconds >= 9.0e9) return 9000000000000000000ull;
  return static_cast<std::uint64_t>(std::llround(seconds * 1e9));
}

hal::Odometry odometry_message(const fw::Se2d& pose, double v, double omega, std::uint64_t timestamp_ns) {
  hal::Odometry m;
  m.timestamp_ns = timestamp_ns;
  m.x = static_cast<float>(pose.x);
  m.y = static_cast<float>(pose.y);
  m.theta = static_cast<float>(pose.theta);
  m.v = static_cast<float>(v);
  m.omega = static_cast<float>(omega);
  return m;
}

hal::Odometry to_odometry(const CarmenOdom& odom, std::uint64_t timestamp_ns) {
  return odometry_message(odom.pose, odom.tv, odom.rv, timestamp_ns);
}

// A scan's own odometry triple carries no velocities.
hal::Odometry to_odometry(const CarmenScan& scan, std::uint64_t timestamp_ns) {
  return odometry_message(scan.odom, 0.0, 0.0, timestamp_ns);
}

hal::LaserScan event_scan(const CarmenLog& log, const ReplayEvent& e) { return to_laser_scan(log.scans[e.index], e.t_ns); }

hal::Odometry event_odometry(const CarmenLog& log, const ReplayEvent& e) {
  return e.odom_from_scan ? to_odometry(log.scans[e.index], e.t_ns) : to_odometry(log.odom[e.index], e.t_ns);
}

}  // namespace sim
