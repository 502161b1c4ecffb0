#include "sim/eval/rbsm/rbsm_eval_lib.h"

#include <png.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>

#include "firmware/base/rng.h"
#include "firmware/rbsm/increment_smoother.h"
#include "sim/io/datasets.h"

namespace sim {

const char* matcher_name(MatcherKind kind) {
  switch (kind) {
    case MatcherKind::kRbsm: return "rbsm";
    case MatcherKind::kIcp: return "trimmed-icp";
    case MatcherKind::kPlIcp: return "pl-icp";
  }
  return "?";
}

std::vector<MatcherKind> icp_baselines() { return {MatcherKind::kPlIcp, MatcherKind::kIcp}; }

MatcherConfig default_matcher_config() {
  MatcherConfig c;
  c.rbsm.grid.resolution = 0.05f;
  c.rbsm.grid.size_log2 = 10;
  c.rbsm.num_particles = 1000;
  c.rbsm.max_range = 15.0f;
  c.rbsm.min_iterations = 3;  // the firmware default, explicit here (see RbsmOptions)
  c.icp.grid = c.rbsm.grid;
  c.icp.max_range = 15.0f;
  c.plicp.max_range = 15.0f;
  c.front.scan.max_range = 15.0f;
  return c;
}

std::unique_ptr<MatcherInstance> MatcherInstance::create(MatcherKind kind, const MatcherConfig& config,
                                                         std::string* error) {
  std::unique_ptr<MatcherInstance> m(new MatcherInstance());
  const size_t bytes = (kind == MatcherKind::kRbsm  ? fw::Rbsm::required_arena_bytes(config.rbsm)
                        : kind == MatcherKind::kIcp ? fw::TrimmedIcp::required_arena_bytes(config.icp)
                                                    : 0) + 4096;
  m->block_.assign(bytes, 0);
  fw::Status st = m->arena_.init(m->block_.data(), m->block_.size(), matcher_name(kind));
  if (st.is_ok() && kind == MatcherKind::kRbsm) {
    if (config.workers > 1) {
      m->pool_ = std::make_unique<fw::WorkerPool>();
      fw::WorkerPoolOptions po;
      po.num_workers = config.workers;
      po.pin = false;
      st = m->pool_->start(po);
    }
    if (st.is_ok()) {
      m->rbsm_ = std::make_unique<fw::Rbsm>();
      st = m->rbsm_->init(config.rbsm, m->arena_, m->pool_.get());
      m->matcher_ = m->rbsm_.get();
    }
  } else if (st.is_ok() && kind == MatcherKind::kPlIcp) {
    m->plicp_ = std::make_unique<fw::PlIcp>();
    st = m->plicp_->init(config.plicp);
    m->matcher_ = m->plicp_.get();
  } else if (st.is_ok()) {
    m->icp_ = std::make_unique<fw::TrimmedIcp>();
    st = m->icp_->init(config.icp, m->arena_);
    m->matcher_ = m->icp_.get();
  }
  if (!st.is_ok()) {
    *error = std::string(matcher_name(kind)) + ": " + st.message();
    return nullptr;
  }
  m->arena_.seal();
  return m;
}

MatcherInstance::~MatcherInstance() {
  if (pool_) pool_->stop();
}

namespace {

// Times match() by wrapping the matcher (the front end calls it once per scan).
class TimedMatcher final : public fw::ScanMatcher {
 public:
  TimedMatcher(fw::ScanMatcher* inner, std::vector<double>* ms, std::vector<double>* cpu_ms)
      : inner_(inner), ms_(ms), cpu_ms_(cpu_ms) {}
  const char* name() const override { return inner_->name(); }
  void reset() override { inner_->reset(); }
  fw::Status match(const fw::Point2f* p, std::size_t n, const fw::Se2f& g, fw::ScanMatchResult* out) override {
    const double c0 = thread_cpu_ms();
    const auto t0 = std::chrono::steady_clock::now();
    fw::Status st = inner_->match(p, n, g, out);
    const auto t1 = std::chrono::steady_clock::now();
    const double c1 = thread_cpu_ms();
    if (st.is_ok() && !out->map_was_empty) {
      ms_->push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
      cpu_ms_->push_back(c1 - c0);
    }
    return st;
  }
  fw::Status integrate(const fw::Point2f* p, std::size_t n, const fw::Se2f& pose, fw::Point2f* nc, std::size_t cap,
                       std::size_t* nn) override {
    return inner_->integrate(p, n, pose, nc, cap, nn);
  }

 private:
  static double thread_cpu_ms() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
  }
  fw::ScanMatcher* inner_;
  std::vector<double>* ms_;
  std::vector<double>* cpu_ms_;
};

double thread_cpu_now_ms() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

uint64_t stamp_ns(const CarmenScan& s) {
  return static_cast<uint64_t>(std::llround(std::max(0.0, s.logger_timestamp) * 1e9));
}

}  // namespace

bool run_scan_matching_odometry(const CarmenLog& log, MatcherKind kind, const MatcherConfig& config, size_t max_scans,
                                OdometryRun* out, std::string* error,
                                const std::function<void(size_t, size_t)>& progress) {
  *out = OdometryRun{};
  auto inst = MatcherInstance::create(kind, config, error);
  if (!inst) return false;
  TimedMatcher timed(inst->matcher(), &out->match_ms, &out->match_cpu_ms);
  auto front = std::make_unique<fw::ScanMatchingOdometry>();
  fw::Status st = front->init(config.front, &timed, nullptr);
  if (!st.is_ok()) {
    *error = st.message();
    return false;
  }
  const size_t n = max_scans == 0 ? log.scans.size() : std::min(max_scans, log.scans.size());
  out->poses.reserve(n);
  auto scan = std::make_unique<hal::LaserScan>();
  for (size_t i = 0; i < n; ++i) {
    if (progress && i % 500 == 0) progress(i, n);
    const CarmenScan& cs = log.scans[i];
    *scan = to_laser_scan(cs, stamp_ns(cs));
    hal::Odometry odom;
    odom.timestamp_ns = scan->timestamp_ns;
    odom.x = static_cast<float>(cs.odom.x);
    odom.y = static_cast<float>(cs.odom.y);
    odom.theta = static_cast<float>(cs.odom.theta);
    fw::Se2f pose;
    fw::ScanMatchResult res;
    const double c0 = thread_cpu_now_ms();
    st = front->step(*scan, odom, &pose, &res);
    out->scan_cpu_ms.push_back(thread_cpu_now_ms() - c0);
    if (st.is_ok() && res.iterations > 0) {
      out->iterations.push_back(res.iterations);
      if (!res.converged) ++out->not_converged;
    }
    if (!st.is_ok()) {
      ++out->failures;
      if (out->failure_messages.size() < 5) out->failure_messages.push_back(log.path + ": " + st.message());
    }
    out->poses.push_back(pose.cast<double>());
  }
  return true;
}

bool fuse_increments(const std::vector<fw::Se2d>& absolute, const std::vector<fw::Se2d>& relative,
                     const fw::IncrementFusionOptions& options, bool smooth, std::vector<fw::Se2d>* out,
                     uint32_t* gated, std::string* error) {
  if (absolute.size() != relative.size()) {
    *error = "fuse_increments: " + std::to_string(absolute.size()) + " RBSM poses but " +
             std::to_string(relative.size()) + " PL-ICP poses";
    return false;
  }
  fw::IncrementFusion fusion;
  const fw::Status init = fusion.init(options);
  if (!init.is_ok()) {
    *error = std::string("fuse_increments: ") + init.message();
    return false;
  }
  std::vector<fw::FusionStep> steps;
  steps.reserve(absolute.size());
  for (size_t i = 0; i < absolute.size(); ++i) {
    const fw::Se2d u = i == 0 ? fw::Se2d() : relative[i - 1].between(relative[i]);
    const fw::Status st = fusion.update(absolute[i], i > 0, u);
    if (!st.is_ok()) {
      *error = "fuse_increments: scan " + std::to_string(i) + ": " + st.message();
      return false;
    }
    steps.push_back(fusion.step());
  }
  *gated = fusion.gated_updates();
  if (smooth) {
    const fw::Status st = fw::smooth_fusion_steps(steps.data(), steps.size());
    if (!st.is_ok()) {
      *error = std::string("fuse_increments: ") + st.message();
      return false;
    }
  }
  out->clear();
  for (const fw::FusionStep& s : steps) out->push_back(s.pose);
  return true;
}

double cpu_ms_per_scan(const OdometryRun& run) {
  if (run.scan_cpu_ms.empty()) return std::nan("");
  double s = 0;
  for (double v : run.scan_cpu_ms) s += v;
  return s / static_cast<double>(run.scan_cpu_ms.size());
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? NAN : s / v.size();
}
double stddev(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return v.empty() ? NAN : std::sqrt(s / v.size());
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double idx = p / 100.0 * static_cast<double>(v.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(idx)), hi = static_cast<size_t>(std::ceil(idx));
  return v[lo] + (v[hi] - v[lo]) * (idx - static_cast<double>(lo));
}

ErrorSummary summarize(std::vector<double> v) {
  ErrorSummary s;
  s.n = v.size();
  if (v.empty()) return s;
  double sum = 0;
  for (double x : v) sum += x;
  s.mean = sum / static_cast<double>(v.size());
  s.p95 = percentile(v, 95);
  s.max = *std::max_element(v.begin(), v.end());
  return s;
}

bool run_pairwise(const CarmenLog& log, const std::vector<CorrectedPose>& reference, MatcherKind kind,
                  const MatcherConfig& config, size_t max_pairs, std::uint64_t seed, double sigma_xy,
                  double sigma_theta_deg, PairwiseResult* out, std::string* error) {
  *out = PairwiseResult{};
  auto inst = MatcherInstance::create(kind, config, error);
  if (!inst) return false;
  std::vector<size_t> usable;
  for (size_t k = 0; k + 1 < reference.size(); ++k) {
    if (reference[k + 1].flaser_index < log.scans.size()) usable.push_back(k);
  }
  if (usable.empty()) {
    *error = log.path + ": no consecutive reference poses inside the log";
    return false;
  }
  const size_t stride = max_pairs == 0 || usable.size() <= max_pairs ? 1 : usable.size() / max_pairs;
  fw::RandomStream noise(seed, 1000);
  std::vector<fw::Point2f> a(hal::LaserScan::kMaxBeams), b(hal::LaserScan::kMaxBeams);
  auto scan = std::make_unique<hal::LaserScan>();
  fw::ScanPointsOptions spo = config.front.scan;
  for (size_t u = 0; u < usable.size() && (max_pairs == 0 || out->ms.size() + out->failures < max_pairs); u += stride) {
    const CorrectedPose& ra = reference[usable[u]];
    const CorrectedPose& rb = reference[usable[u] + 1];
    fw::ScanPointsResult pa, pb;
    *scan = to_laser_scan(log.scans[ra.flaser_index], 0);
    fw::Status st = fw::scan_to_points(*scan, spo, a.data(), a.size(), &pa);
    *scan = to_laser_scan(log.scans[rb.flaser_index], 0);
    if (st.is_ok()) st = fw::scan_to_points(*scan, spo, b.data(), b.size(), &pb);
    if (!st.is_ok()) {
      ++out->failures;
      continue;
    }
    const fw::Se2d truth = ra.pose.between(rb.pose);
    // One draw per declarator (a constructor's argument order is unspecified): θ, y, x — the
    // order x86-64 GCC used when the figures were measured.
    const double gt = noise.gaussian(), gy = noise.gaussian(), gx = noise.gaussian();
    const fw::Se2d guess(truth.x + sigma_xy * gx, truth.y + sigma_xy * gy,
                         fw::wrap_angle(truth.theta + sigma_theta_deg * M_PI / 180.0 * gt));
    fw::ScanMatcher* m = inst->matcher();
    m->reset();
    if (inst->rbsm()) inst->rbsm()->forget_tracking();
    st = m->integrate(a.data(), pa.count, fw::Se2f());
    fw::ScanMatchResult r;
    const auto t0 = std::chrono::steady_clock::now();
    if (st.is_ok()) st = m->match(b.data(), pb.count, guess.cast<float>(), &r);
    const auto t1 = std::chrono::steady_clock::now();
    if (!st.is_ok()) {
      ++out->failures;
      continue;
    }
    const fw::Se2d e = truth.between(r.pose.cast<double>());
    out->trans_err_m.push_back(std::hypot(e.x, e.y));
    out->rot_err_deg.push_back(std::fabs(fw::wrap_angle(e.theta)) * 180.0 / M_PI);
    out->ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  return true;
}

bool write_map_png(const std::string& path, const CarmenLog& log, const std::vector<fw::Se2d>& poses,
                   const std::vector<fw::Se2d>* second, double res, float max_range, size_t stride,
                   std::string* error) {
  if (poses.empty()) {
    *error = path + ": no poses to draw";
    return false;
  }
  // Pass 1: extent of the end points.
  std::vector<std::pair<double, double>> pts;
  auto scan = std::make_unique<hal::LaserScan>();
  std::vector<fw::Point2f> buf(hal::LaserScan::kMaxBeams);
  fw::ScanPointsOptions spo;
  spo.max_range = max_range;
  for (size_t i = 0; i < poses.size() && i < log.scans.size(); i += std::max<size_t>(1, stride)) {
    *scan = to_laser_scan(log.scans[i], 0);
    fw::ScanPointsResult pr;
    if (!fw::scan_to_points(*scan, spo, buf.data(), buf.size(), &pr).is_ok()) continue;
    const fw::Se2d& p = poses[i];
    const double c = std::cos(p.theta), s = std::sin(p.theta);
    for (size_t k = 0; k < pr.count; ++k) {
      pts.emplace_back(p.x + c * buf[k](0) - s * buf[k](1), p.y + s * buf[k](0) + c * buf[k](1));
    }
  }
  double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
  for (const auto& q : pts) {
    x0 = std::min(x0, q.first); x1 = std::max(x1, q.first);
    y0 = std::min(y0, q.second); y1 = std::max(y1, q.second);
  }
  for (const auto& p : poses) {
    x0 = std::min(x0, p.x); x1 = std::max(x1, p.x); y0 = std::min(y0, p.y); y1 = std::max(y1, p.y);
  }
  const int w = std::min(4000, static_cast<int>((x1 - x0) / res) + 3);
  const int h = std::min(4000, static_cast<int>((y1 - y0) / res) + 3);
  const double sc = std::max((x1 - x0) / (w - 3), (y1 - y0) / (h - 3));
  std::vector<uint16_t> hits(static_cast<size_t>(w) * h, 0);
  auto px = [&](double x, double y, int* u, int* v) {
    *u = static_cast<int>((x - x0) / sc) + 1;
    *v = h - 2 - static_cast<int>((y - y0) / sc);
    return *u >= 0 && *u < w && *v >= 0 && *v < h;
  };
  for (const auto& q : pts) {
    int u, v;
    if (px(q.first, q.second, &u, &v) && hits[static_cast<size_t>(v) * w + u] < 65535) ++hits[static_cast<size_t>(v) * w + u];
  }
  std::vector<uint8_t> rgb(static_cast<size_t>(w) * h * 3, 255);
  for (size_t i = 0; i < hits.size(); ++i) {
    if (hits[i] == 0) continue;
    const int g = hits[i] >= 3 ? 0 : (hits[i] == 2 ? 90 : 160);
    rgb[i * 3] = rgb[i * 3 + 1] = rgb[i * 3 + 2] = static_cast<uint8_t>(g);
  }
  auto draw_path = [&](const std::vector<fw::Se2d>& path_poses, uint8_t r, uint8_t g, uint8_t b) {
    for (const auto& p : path_poses) {
      int u, v;
      if (!px(p.x, p.y, &u, &v)) continue;
      uint8_t* d = &rgb[(static_cast<size_t>(v) * w + u) * 3];
      d[0] = r; d[1] = g; d[2] = b;
    }
  };
  if (second) draw_path(*second, 30, 60, 230);
  draw_path(poses, 220, 30, 30);
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) {
    *error = path + ": cannot open for writing";
    return false;
  }
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
    *error = path + ": libpng write error";
    return false;
  }
  png_init_io(png, f);
  png_set_IHDR(png, info, w, h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int v = 0; v < h; ++v) png_write_row(png, &rgb[static_cast<size_t>(v) * w * 3]);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  std::fclose(f);
  return true;
}

bool find_eval_dataset(const std::string& name, EvalDataset* out, std::string* error) {
  const Dataset* d = find_dataset(name);
  if (d == nullptr || d->raw_log.empty()) {
    *error = "unknown dataset or no raw log: '" + name + "'";
    return false;
  }
  out->name = name;
  out->raw_log = data_path(d->raw_log);
  out->relations = data_path(d->relations);
  out->corrected_poses = data_path(d->corrected_poses);
  return true;
}

}  // namespace sim
