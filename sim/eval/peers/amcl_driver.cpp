// AMCL's core (ROS navigation amcl/ at 9ad6441, ../shared/peers, LGPL) driven as amcl_node does.
// Read: that archive's src/amcl_node.cpp:
//  - parameter defaults (AmclNode::AmclNode): min/max_particles 100/5000, kld_err 0.01, kld_z 0.99,
//    odom_model_type diff, odom_alpha1..4 0.2, laser_model_type likelihood_field, laser_max_beams 30,
//    laser_z_hit 0.95, laser_z_rand 0.05, laser_sigma_hit 0.2, laser_likelihood_max_dist 2.0,
//    update_min_d 0.2, update_min_a π/6, resample_interval 2, recovery_alpha_slow/fast 0.001/0.1,
//    selective_resampling off, laser_min/max_range -1 (the scan's own); initial_cov_xx/yy 0.25,
//    initial_cov_aa (π/12)² (updatePoseFromServer).
//  - handleMapMessage + convertMap: map cells 0 → free (-1), 100 → occupied (+1), else unknown (0);
//    origin at the map's centre; pf_alloc(…, uniformPoseGenerator, map); pf_init(mean, cov);
//    AMCLOdom::SetModel; AMCLLaser(max_beams, map) + SetModelLikelihoodField.
//  - uniformPoseGenerator (NEW_UNIFORM_SAMPLING 1): a uniformly drawn free cell, heading uniform;
//    globalLocalizationCallback: pf_init_model(pf, uniformPoseGenerator, map).
//  - laserReceived: the laser pose on the base (here the origin); the odometry change since the last
//    filter update; update when |dx| > d or |dy| > d or |dθ| > a; the first scan only initialises;
//    UpdateAction with the odometry delta, UpdateSensor with every range (≤ range_min → range_max,
//    > range_max → DBL_MAX), resample every resample_interval-th update; after a resample (or the
//    first scan) the highest-weight cluster's mean is published and becomes the tf map→odom, which
//    stays until the next publication (so the pose at any scan = that tf ∘ the scan's odometry).
// pf_alloc seeds drand48 from time() and pf_init from a process-wide counter (pf_pdf.c); we reseed
// it with the run's seed after each, so that a run repeats exactly whatever ran before it.
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <utility>
#include <vector>

#include "amcl/map/map.h"
#include "amcl/pf/pf.h"
#include "amcl/sensors/amcl_laser.h"
#include "amcl/sensors/amcl_odom.h"
#include "sim/eval/peers/peer_drivers.h"

namespace sim::peers {

namespace {

// amcl_node.cpp's angle_diff (normalize(a) - normalize(b), the short way round).
double angle_diff(double a, double b) {
  a = std::atan2(std::sin(a), std::cos(a));
  b = std::atan2(std::sin(b), std::cos(b));
  double d1 = a - b;
  double d2 = 2 * M_PI - std::fabs(d1);
  if (d1 > 0) d2 *= -1.0;
  return std::fabs(d1) < std::fabs(d2) ? d1 : d2;
}

struct FreeCells {
  map_t* map = nullptr;
  std::vector<std::pair<int, int>> cells;
};

// amcl_node.cpp's uniformPoseGenerator with NEW_UNIFORM_SAMPLING.
pf_vector_t uniform_pose(void* arg) {
  const FreeCells* f = static_cast<const FreeCells*>(arg);
  const unsigned int k = static_cast<unsigned int>(drand48() * f->cells.size());
  const std::pair<int, int> c = f->cells[k];
  pf_vector_t p;
  p.v[0] = MAP_WXGX(f->map, c.first);
  p.v[1] = MAP_WYGY(f->map, c.second);
  p.v[2] = drand48() * 2 * M_PI - M_PI;
  return p;
}

}  // namespace

struct AmclDriver::Impl {
  Options opt;
  long seed = 1;
  map_t* map = nullptr;
  FreeCells free;
  pf_t* pf = nullptr;
  amcl::AMCLOdom odom;
  amcl::AMCLLaser* laser = nullptr;
  bool pf_init = false;
  pf_vector_t pf_odom_pose{};
  int resample_count = 0;
  Pose tf_pose, tf_odom;  // published pose and the odometry it was published at (map→odom)
  bool have_tf = false;
  ~Impl() {
    delete laser;
    if (pf) pf_free(pf);
    if (map) map_free(map);
  }
};

AmclDriver::AmclDriver(const GridView& g, const Options& opt, long seed) : impl_(new Impl) {
  Impl& m = *impl_;
  m.opt = opt;
  m.seed = seed;
  m.map = map_alloc();
  m.map->size_x = static_cast<int>(g.width);
  m.map->size_y = static_cast<int>(g.height);
  m.map->scale = g.resolution;
  m.map->origin_x = g.origin_x + (m.map->size_x / 2) * m.map->scale;
  m.map->origin_y = g.origin_y + (m.map->size_y / 2) * m.map->scale;
  m.map->cells = static_cast<map_cell_t*>(std::malloc(sizeof(map_cell_t) * m.map->size_x * m.map->size_y));
  for (int i = 0; i < m.map->size_x * m.map->size_y; ++i) {
    const std::uint8_t v = g.cells[i];
    m.map->cells[i].occ_state = v == 0 ? -1 : (v == 100 ? +1 : 0);
  }
  m.free.map = m.map;
  for (int i = 0; i < m.map->size_x; ++i)
    for (int j = 0; j < m.map->size_y; ++j)
      if (m.map->cells[MAP_INDEX(m.map, i, j)].occ_state == -1) m.free.cells.emplace_back(i, j);
  m.pf = pf_alloc(opt.min_particles, opt.max_particles, opt.alpha_slow, opt.alpha_fast, uniform_pose, &m.free);
  pf_set_selective_resampling(m.pf, 0);
  m.pf->pop_err = opt.kld_err;
  m.pf->pop_z = opt.kld_z;
  srand48(seed);
  m.odom.SetModel(amcl::ODOM_MODEL_DIFF, opt.odom_alpha[0], opt.odom_alpha[1], opt.odom_alpha[2], opt.odom_alpha[3],
                  0.2);
  m.laser = new amcl::AMCLLaser(static_cast<size_t>(opt.max_beams), m.map);
  m.laser->SetModelLikelihoodField(opt.z_hit, opt.z_rand, opt.sigma_hit, opt.likelihood_max_dist);
  pf_vector_t lp = pf_vector_zero();
  m.laser->SetLaserPose(lp);
}

AmclDriver::~AmclDriver() = default;

void AmclDriver::set_pose(const Pose& p) {
  Impl& m = *impl_;
  pf_vector_t mean = pf_vector_zero();
  mean.v[0] = p.x;
  mean.v[1] = p.y;
  mean.v[2] = p.theta;
  pf_matrix_t cov = pf_matrix_zero();
  for (int k = 0; k < 3; ++k) cov.m[k][k] = m.opt.init_cov[k];
  pf_init(m.pf, mean, cov);
  srand48(m.seed);  // pf_init reseeded drand48 from a process-wide counter: make each run its own
  m.pf_init = false;
  m.have_tf = false;
}

void AmclDriver::global_localization() {
  Impl& m = *impl_;
  srand48(m.seed);
  pf_init_model(m.pf, uniform_pose, &m.free);
  m.pf_init = false;
  m.have_tf = false;
}

int AmclDriver::particles() const { return impl_->pf->sets[impl_->pf->current_set].sample_count; }

StepOut AmclDriver::step(const ScanView& scan, const Pose& odom) {
  Impl& m = *impl_;
  StepOut out;
  pf_vector_t pose;
  pose.v[0] = odom.x;
  pose.v[1] = odom.y;
  pose.v[2] = odom.theta;
  pf_vector_t delta = pf_vector_zero();
  bool update = false, force_publication = false;
  if (m.pf_init) {
    delta.v[0] = pose.v[0] - m.pf_odom_pose.v[0];
    delta.v[1] = pose.v[1] - m.pf_odom_pose.v[1];
    delta.v[2] = angle_diff(pose.v[2], m.pf_odom_pose.v[2]);
    update = std::fabs(delta.v[0]) > m.opt.update_min_d || std::fabs(delta.v[1]) > m.opt.update_min_d ||
             std::fabs(delta.v[2]) > m.opt.update_min_a;
  } else {
    m.pf_odom_pose = pose;
    m.pf_init = true;
    update = true;
    force_publication = true;
    m.resample_count = 0;
  }
  if (update && !force_publication) {
    amcl::AMCLOdomData odata;
    odata.pose = pose;
    odata.delta = delta;
    m.odom.UpdateAction(m.pf, &odata);
  }
  bool resampled = false;
  if (update) {
    amcl::AMCLLaserData ldata;
    ldata.sensor = m.laser;
    ldata.range_count = static_cast<int>(scan.count);
    ldata.range_max = scan.range_max;
    ldata.ranges = new double[scan.count][2];
    for (std::size_t i = 0; i < scan.count; ++i) {
      const double r = scan.ranges[i];
      if (r <= scan.range_min)
        ldata.ranges[i][0] = ldata.range_max;
      else if (r > ldata.range_max)
        ldata.ranges[i][0] = DBL_MAX;
      else
        ldata.ranges[i][0] = r;
      ldata.ranges[i][1] = scan.angle_min + static_cast<double>(i) * scan.angle_increment;
    }
    m.laser->UpdateSensor(m.pf, &ldata);
    m.pf_odom_pose = pose;
    if (!(++m.resample_count % m.opt.resample_interval)) {
      pf_update_resample(m.pf);
      resampled = true;
    }
    out.updated = true;
  }
  if (resampled || force_publication) {
    double max_weight = 0.0;
    pf_vector_t best = pf_vector_zero();
    for (int h = 0; h < m.pf->sets[m.pf->current_set].cluster_count; ++h) {
      double w;
      pf_vector_t mean;
      pf_matrix_t cov;
      if (!pf_get_cluster_stats(m.pf, h, &w, &mean, &cov)) break;
      if (w > max_weight) {
        max_weight = w;
        best = mean;
      }
    }
    if (max_weight > 0.0) {
      m.tf_pose = {best.v[0], best.v[1], best.v[2]};
      m.tf_odom = odom;
      m.have_tf = true;
    }
  }
  if (m.have_tf) {
    // tf map→odom ∘ this scan's odometry: the published pose moved by the odometry since.
    const double c0 = std::cos(m.tf_odom.theta), s0 = std::sin(m.tf_odom.theta);
    const double dx = c0 * (odom.x - m.tf_odom.x) + s0 * (odom.y - m.tf_odom.y);
    const double dy = -s0 * (odom.x - m.tf_odom.x) + c0 * (odom.y - m.tf_odom.y);
    const double c = std::cos(m.tf_pose.theta), s = std::sin(m.tf_pose.theta);
    out.pose = {m.tf_pose.x + c * dx - s * dy, m.tf_pose.y + s * dx + c * dy,
                std::atan2(std::sin(m.tf_pose.theta + odom.theta - m.tf_odom.theta),
                           std::cos(m.tf_pose.theta + odom.theta - m.tf_odom.theta))};
  } else {
    out.pose = {std::nan(""), std::nan(""), std::nan("")};
  }
  return out;
}

}  // namespace sim::peers
