// LaMa's Loc2D (iris_lama fd60e55, ../shared/peers, BSD 3-clause) driven as its ROS node drives it.
// Read: iris-ua/iris_lama_ros src/loc2d_ros.cpp (ROS 2 branch, commit 0b97c4c9):
//  - InitLoc2DFromOccupancyGridMsg: Loc2D::Options with the node's parameter defaults d_thresh 0.01,
//    a_thresh 0.2, l2_max 0.5, strategy "gn", patch_size 32, resolution = the map's; Init(); then
//    every cell 0 → occupancy_map->setFree, 100 → setOccupied + distance_map->addObstacle(w2m),
//    world coordinates origin + i·resolution (the cell's corner, as the node does); distance_map->update().
//  - onInitialPose: setPose(x, y, yaw).
//  - onLaserScan: odom = base_link in odom; only when loc2d->enoughMotion(odom) the scan becomes a
//    point cloud (beam_step 1, finite ranges strictly between range_min and range_max, sensor origin
//    = the laser's pose on the base, here the origin) and loc2d->update(cloud, odom, stamp); the
//    published tf map→odom is the pose after that update composed with the inverse odometry, and is
//    republished unchanged between updates (so the pose at any scan = that tf ∘ the scan's odometry).
// Loc2D's own defaults (loc2d.cpp Options::Options) supply the rest: max_iter 100, gloc_particles
// 3000, gloc_iters 10, gloc_thresh 0.15, cov_blend 0; the robust cost is Cauchy(0.15) (Init()).
#include <cmath>

#include "lama/loc2d.h"
#include "lama/random.h"
#include "sim/eval/peers/peer_drivers.h"

namespace sim::peers {

struct LamaDriver::Impl {
  lama::Loc2D loc;
  lama::Pose2D pose_at_update;  // Loc2D's pose after the last update …
  lama::Pose2D odom_at_update;  // … and the odometry it was taken at (the node's tf map→odom)
  bool have_tf = false;
};

LamaDriver::LamaDriver(const GridView& map, const Options& opt, unsigned seed) : impl_(new Impl) {
  lama::random::setSeed(seed);
  lama::Loc2D::Options o;
  o.trans_thresh = opt.d_thresh;
  o.rot_thresh = opt.a_thresh;
  o.l2_max = opt.l2_max;
  o.strategy = "gn";
  o.patch_size = opt.patch_size;
  o.resolution = map.resolution;
  impl_->loc.Init(o);
  for (std::uint32_t j = 0; j < map.height; ++j) {
    for (std::uint32_t i = 0; i < map.width; ++i) {
      Eigen::Vector3d coords(map.origin_x + i * map.resolution, map.origin_y + j * map.resolution, 0.0);
      const std::uint8_t v = map.cells[static_cast<std::size_t>(j) * map.width + i];
      if (v == 0) {
        impl_->loc.occupancy_map->setFree(coords);
      } else if (v == 100) {
        impl_->loc.occupancy_map->setOccupied(coords);
        impl_->loc.distance_map->addObstacle(impl_->loc.distance_map->w2m(coords));
      }
    }
  }
  impl_->loc.distance_map->update();
}

LamaDriver::~LamaDriver() {
  // Loc2D::Init allocates its two maps with new and its destructor does not free them.
  delete impl_->loc.occupancy_map;
  delete impl_->loc.distance_map;
}

void LamaDriver::set_pose(const Pose& p) {
  impl_->loc.setPose(lama::Pose2D(p.x, p.y, p.theta));
  impl_->have_tf = false;
}

void LamaDriver::trigger_global_localization() { impl_->loc.triggerGlobalLocalization(); }

StepOut LamaDriver::step(const ScanView& scan, const Pose& odom_in) {
  Impl& m = *impl_;
  const lama::Pose2D odom(odom_in.x, odom_in.y, odom_in.theta);
  StepOut out;
  if (m.loc.enoughMotion(odom)) {
    lama::PointCloudXYZ::Ptr cloud(new lama::PointCloudXYZ);
    cloud->sensor_origin_ = Eigen::Vector3d::Zero();
    cloud->sensor_orientation_ = Eigen::Quaterniond::Identity();
    cloud->points.reserve(scan.count);
    for (std::size_t i = 0; i < scan.count; ++i) {
      const double r = scan.ranges[i];
      if (!std::isfinite(r) || r >= scan.range_max || r <= scan.range_min) continue;
      const double a = scan.angle_min + static_cast<double>(i) * scan.angle_increment;
      cloud->points.emplace_back(r * std::cos(a), r * std::sin(a), 0.0);
    }
    m.loc.update(cloud, odom, 0.0);
    m.pose_at_update = m.loc.getPose();
    m.odom_at_update = odom;
    m.have_tf = true;
    out.updated = true;
  }
  // The node's tf (map→odom of the last update) applied to this scan's odometry.
  const lama::Pose2D p = m.have_tf ? m.pose_at_update + (m.odom_at_update - odom) : m.loc.getPose();
  out.pose = {p.x(), p.y(), p.rotation()};
  return out;
}

}  // namespace sim::peers
