#include "sim/slam/slam_pipeline.h"

#include <chrono>
#include <cmath>
#include <memory>

#include "sim/common/stopwatch.h"
#include "sim/io/reference_trajectory.h"
#include "sim/io/ros_map.h"
#include "sim/map/occupancy_builder.h"
#include "sim/viz/picture.h"

namespace sim {

namespace {
// A trajectory (one pose per scan) as a line of the picture.
Polyline trajectory_line(const std::vector<fw::Se2d>& poses, Rgb color, double width_px, const char* label) {
  Polyline l;
  l.color = color;
  l.width_px = width_px;
  l.label = label;
  for (const auto& p : poses) l.points.push_back({p.x, p.y});
  return l;
}

class SteadyClock final : public hal::Clock {
 public:
  std::uint64_t now_ns() const override {
    return static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
            .count());
  }
};

}  // namespace

bool run_slam_backend(const CarmenLog& log, const std::vector<fw::Se2d>& frontend, const SlamConfig& config,
                      SlamRun* out, std::string* error) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t n = frontend.size();
  if (n == 0 || n > log.scans.size()) {
    *error = log.path + ": no scans to map";
    return false;
  }
  fw::antslam::AntSlamOptions o = config.slam;
  // The final refinement is run below by hand, after Alg. 3's poses are read (SlamRun::alg3_poses).
  const bool refine = o.final_refinement;
  o.final_refinement = false;
  if (o.max_scans < n) o.max_scans = static_cast<std::uint32_t>(n);
  // Enough fragments for the distance the front end travelled (a long log must not run out).
  double travelled = 0;
  for (std::size_t i = 1; i < n; ++i) travelled += std::hypot(frontend[i].x - frontend[i - 1].x, frontend[i].y - frontend[i - 1].y);
  const double need = travelled / o.fragment_length_m + 16;
  if (need > o.max_fragments) o.max_fragments = static_cast<std::uint32_t>(need);
  // Host arena: one block (the firmware would carve it from its start-up arena).
  std::vector<unsigned char> block(fw::antslam::AntSlam::required_arena_bytes(o));
  fw::StartupArena arena;
  fw::Status st = arena.init(block.data(), block.size(), "antslam");
  std::unique_ptr<fw::WorkerPool> pool;
  if (st.is_ok() && config.workers > 1) {
    pool = std::make_unique<fw::WorkerPool>();
    fw::WorkerPoolOptions po;
    po.num_workers = config.workers;
    po.pin = false;
    st = pool->start(po);
  }
  SteadyClock clock;
  auto slam = std::make_unique<fw::antslam::AntSlam>();
  if (st.is_ok()) st = slam->init(o, arena, pool.get(), &clock);
  if (!st.is_ok()) {
    *error = std::string("antslam: ") + st.message();
    if (pool) pool->stop();
    return false;
  }
  arena.seal();
  fw::ScanPointsOptions spo = config.front.front.scan;
  std::vector<fw::Point2f> buf(hal::LaserScan::kMaxBeams);
  auto scan = std::make_unique<hal::LaserScan>();
  for (std::size_t i = 0; i < n && st.is_ok(); ++i) {
    *scan = to_laser_scan(log.scans[i], 0);
    fw::ScanPointsResult pr;
    const bool have_points = fw::scan_to_points(*scan, spo, buf.data(), buf.size(), &pr).is_ok();
    st = slam->add_scan(frontend[i], buf.data(), have_points ? pr.count : 0);
    if (config.progress && (i % 500 == 0)) config.progress(i, n, "antslam");
  }
  if (st.is_ok()) st = slam->finish();
  out->alg3_poses.clear();
  if (st.is_ok() && refine) {
    out->alg3_poses.resize(n);
    for (std::size_t i = 0; i < n; ++i) out->alg3_poses[i] = slam->scan_pose(static_cast<std::uint32_t>(i));
    st = slam->refine_whole_graph();
  }
  if (pool) pool->stop();
  if (!st.is_ok()) {
    *error = log.path + ": antslam: " + st.message();
    return false;
  }
  out->frontend = frontend;
  out->poses.resize(n);
  for (std::size_t i = 0; i < n; ++i) out->poses[i] = slam->scan_pose(static_cast<std::uint32_t>(i));
  out->fragments.clear();
  for (std::uint32_t f = 0; f < slam->num_fragments(); ++f) {
    SlamFragmentInfo fi;
    fi.pose = slam->fragment_pose(f);
    std::uint32_t np = 0;
    const fw::Point2f* p = slam->fragment_points(f, &np);
    fi.points.assign(p, p + np);
    std::uint32_t nb = 0, nh = 0;
    const fw::antslam::Border* b = slam->fragment_borders(f, &nb);
    fi.borders.assign(b, b + nb);
    const fw::Point2f* h = slam->fragment_hull(f, &nh);
    fi.hull.assign(h, h + nh);
    out->fragments.push_back(std::move(fi));
  }
  out->edges.clear();
  for (std::uint32_t e = 0; e < slam->num_edges(); ++e) {
    const auto& ed = slam->edge(e);
    out->edges.push_back({ed.from, ed.to, ed.closure, ed.frozen});
  }
  out->closures.clear();
  for (std::uint32_t c = 0; c < slam->num_closures(); ++c) out->closures.push_back(slam->closure(c));
  out->stats = slam->stats();
  out->optimizer_ms = static_cast<double>(out->stats.optimizer_ns) * 1e-6;
  out->matcher_ms = static_cast<double>(out->stats.matcher_ns) * 1e-6;
  out->backend_s = seconds_since(t0);
  return true;
}

bool run_slam(const CarmenLog& log, const SlamConfig& config, SlamRun* out, std::string* error) {
  *out = SlamRun{};
  const auto t0 = std::chrono::steady_clock::now();
  MatcherConfig mc = config.front;
  mc.workers = config.workers;
  OdometryRun odo;
  std::function<void(size_t, size_t)> front_progress;
  if (config.progress) front_progress = [&config](size_t done, size_t total) { config.progress(done, total, "rbsm"); };
  if (!run_scan_matching_odometry(log, MatcherKind::kRbsm, mc, config.max_scans, &odo, error, front_progress)) {
    return false;
  }
  if (config.fuse_front) {
    if (config.progress) front_progress = [&config](size_t done, size_t total) { config.progress(done, total, "pl-icp"); };
    OdometryRun icp;
    if (!run_scan_matching_odometry(log, MatcherKind::kPlIcp, mc, config.max_scans, &icp, error, front_progress)) {
      return false;
    }
    std::vector<fw::Se2d> fused;
    std::uint32_t gated = 0;
    if (!fuse_increments(odo.poses, icp.poses, mc.fusion, mc.fusion_smooth, &fused, &gated, error)) return false;
    odo.poses = std::move(fused);
  }
  const double front_s = seconds_since(t0);
  if (!run_slam_backend(log, odo.poses, config, out, error)) return false;
  out->frontend_s = front_s;
  return true;
}

bool slam_dataset_relations(const CarmenLog& log, const EvalDataset& d, std::vector<Relation>* rel,
                            std::string* err) {
  if (d.name != "mit-killian") return read_relations(d.relations, rel, err);
  std::vector<CorrectedPose> ref;
  if (!read_corrected_poses(d.corrected_poses, &ref, err)) return false;
  rel->clear();
  for (std::size_t k = 0; k + 1 < ref.size(); ++k) {
    if (ref[k + 1].flaser_index >= log.scans.size()) break;
    Relation r;
    r.t1 = log.scans[ref[k].flaser_index].ipc_timestamp;
    r.t2 = log.scans[ref[k + 1].flaser_index].ipc_timestamp;
    r.delta = ref[k].pose.between(ref[k + 1].pose);
    rel->push_back(r);
  }
  if (rel->empty()) *err = d.corrected_poses + ": no corrected pose inside the log";
  return !rel->empty();
}

bool write_slam_map(const CarmenLog& log, const std::vector<fw::Se2d>& poses, double resolution, double max_range,
                    const std::string& yaml_path, std::string* error) {
  std::vector<PosedScan> scans;
  for (std::size_t i = 0; i < poses.size() && i < log.scans.size(); ++i) {
    const CarmenScan& s = log.scans[i];
    scans.push_back({poses[i], s.angle_min, s.angle_increment, s.max_range, s.ranges.data(), s.ranges.size()});
  }
  OccupancyBuildOptions o;
  o.resolution = resolution;
  o.max_usable_range = max_range;
  OccupancyGrid grid;
  OccupancyBuildStats stats;
  if (!build_occupancy_grid(scans, o, &grid, &stats, error)) return false;
  std::string image = yaml_path;
  const std::size_t slash = image.find_last_of('/');
  std::string base = slash == std::string::npos ? image : image.substr(slash + 1);
  if (base.size() > 5 && base.substr(base.size() - 5) == ".yaml") base = base.substr(0, base.size() - 5);
  const RosMap map = grid_to_ros_map(grid, base + ".pgm");
  return write_ros_map(yaml_path, map, error);
}

bool write_slam_svg(const SlamRun& run, const std::string& title, const std::string& path, std::string* error) {
  Picture pic;
  pic.title = title;
  pic.notes.push_back(std::to_string(run.fragments.size()) + " fragments, " + std::to_string(run.stats.loops) +
                      " loops closed (" + std::to_string(run.stats.candidates) + " pRANSAM candidates)");
  PointSet pts;
  pts.color = Rgb{120, 120, 120};
  pts.radius_px = 0.6;
  pts.label = "fragment points (corrected)";
  for (const auto& f : run.fragments) {
    const double c = std::cos(f.pose.theta), s = std::sin(f.pose.theta);
    for (std::size_t k = 0; k < f.points.size(); k += 2) {
      const double x = f.points[k](0), y = f.points[k](1);
      pts.points.push_back({f.pose.x + c * x - s * y, f.pose.y + s * x + c * y});
    }
  }
  pic.point_sets.push_back(std::move(pts));
  pic.lines.push_back(trajectory_line(run.frontend, Rgb{230, 150, 40}, 1.0, "RBSM front end"));
  pic.lines.push_back(trajectory_line(run.poses, Rgb{30, 60, 220}, 1.2, "AntSLAM"));
  bool first_closure = true;
  for (const auto& e : run.edges) {
    if (!e.closure || e.from >= run.fragments.size() || e.to >= run.fragments.size()) continue;
    Polyline l;
    l.color = Rgb{220, 30, 30};
    l.width_px = 2.0;
    if (first_closure) l.label = "closed loops (pRANSAM edges)";
    first_closure = false;
    l.points = {{run.fragments[e.from].pose.x, run.fragments[e.from].pose.y},
                {run.fragments[e.to].pose.x, run.fragments[e.to].pose.y}};
    pic.lines.push_back(std::move(l));
  }
  // Borders (Sec. 3.4): one segment per border, drawn once (each is stored on both of its fragments).
  bool first_border = true;
  for (const auto& f : run.fragments) {
    const double c = std::cos(f.pose.theta), s = std::sin(f.pose.theta);
    for (const auto& b : f.borders) {
      Polyline l;
      l.color = Rgb{150, 40, 170};
      l.width_px = 1.2;
      if (first_border) l.label = "fragment borders (Eq. 3.6-3.8)";
      first_border = false;
      l.points = {{f.pose.x + c * b.x1 - s * b.y1, f.pose.y + s * b.x1 + c * b.y1},
                  {f.pose.x + c * b.x2 - s * b.y2, f.pose.y + s * b.x2 + c * b.y2}};
      pic.lines.push_back(std::move(l));
    }
  }
  PointSet frames;
  frames.color = Rgb{20, 160, 60};
  frames.radius_px = 3.0;
  frames.label = "fragment frames (adjacent edges join them)";
  for (const auto& f : run.fragments) frames.points.push_back({f.pose.x, f.pose.y});
  pic.point_sets.push_back(std::move(frames));
  if (path.size() > 4 && path.substr(path.size() - 4) == ".png") return write_png(pic, path, error);
  return write_svg(pic, path, error);
}

}  // namespace sim
