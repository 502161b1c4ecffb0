#include "sim/eval/pransam_eval/pransam_eval_lib.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "firmware/map/map_image.h"
#include "firmware/pransam/relation_table_io.h"
#include "sim/common/stopwatch.h"
#include "sim/eval/pransam_scenes.h"
#include "sim/io/carmen_log.h"
#include "sim/io/datasets.h"
#include "sim/map/global_maps.h"
#include "sim/map/map_image_writer.h"

namespace sim::pransam_eval {

namespace {
double wrap(double a) {
  while (a > M_PI) a -= 2 * M_PI;
  while (a <= -M_PI) a += 2 * M_PI;
  return a;
}
}  // namespace

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const std::size_t i = static_cast<std::size_t>(std::floor(pos));
  const std::size_t j = std::min(i + 1, v.size() - 1);
  return v[i] + (v[j] - v[i]) * (pos - static_cast<double>(i));
}

double ScanMapRun::p50() const { return percentile(ms, 0.5); }
double ScanMapRun::p99() const { return percentile(ms, 0.99); }
double ScanMapRun::mean_iterations() const {
  double s = 0;
  for (double v : iterations) s += v;
  return iterations.empty() ? 0 : s / static_cast<double>(iterations.size());
}
double ScanMapRun::total_ms() const {
  double s = 0;
  for (double v : ms) s += v;
  return s;
}
double ThreeDRun::p50() const { return percentile(ms, 0.5); }

bool load_real_case(const std::string& dataset, const CaseOptions& options, RealCase* out, std::string* error) {
  out->dataset = dataset;
  const Dataset* ds = find_dataset(dataset);
  if (ds == nullptr || ds->corrected_log.empty()) {
    *error = "pransam eval: unknown dataset or no corrected log: '" + dataset + "'";
    return false;
  }
  RosMap ros;
  if (!ensure_global_map(dataset, -1.0, map_cache_dir(), &ros, error)) return false;
  if (!read_file_bytes(global_map_image_path(dataset), &out->image, error)) return false;
  out->map_arena = std::make_unique<fw::StartupArena>();
  const std::size_t map_bytes = fw::map_image_arena_bytes(out->image.data(), out->image.size());
  fw::Status s = out->map_arena->init_mapped(map_bytes + (std::size_t(4) << 20), false, "eval map");
  if (s.is_ok()) s = fw::load_map_image(out->image.data(), out->image.size(), *out->map_arena, &out->map,
                                        global_map_image_path(dataset).c_str());
  if (!s.is_ok()) {
    *error = s.message();
    return false;
  }
  CarmenLog log;
  CarmenReadOptions ro;
  if (!read_carmen_log(data_path(ds->corrected_log), ro, &log, error)) return false;
  out->queries.clear();
  for (std::size_t i = 0; i < log.scans.size(); i += options.every) {
    const CarmenScan& sc = log.scans[i];
    ScanQuery q;
    q.index = sc.index;
    q.x = sc.pose.x;
    q.y = sc.pose.y;
    q.theta = sc.pose.theta;
    for (std::size_t b = 0; b < sc.ranges.size(); ++b) {
      const float r = sc.ranges[b];
      if (!std::isfinite(r) || r < options.min_range || r > options.max_range || r >= sc.max_range) continue;
      const float a = sc.angle_min + sc.angle_increment * static_cast<float>(b);
      q.points.push_back(P2(r * std::cos(a), r * std::sin(a)));
    }
    out->queries.push_back(std::move(q));
    if (options.max_queries && out->queries.size() >= options.max_queries) break;
  }
  return true;
}

namespace {
fw::pransam::MatcherOptions options_for(const fw::GlobalMap& map, int T, bool allocate_model_table,
                                        float eps_hard = 0.10f, float eps_soft = 0.20f) {
  fw::pransam::MatcherOptions o;
  o.num_workers = T;
  o.max_scene_points = 2048;
  o.max_model_points = std::max<std::uint32_t>(map.num_points, 3);
  o.field.resolution = map.geometry.resolution;
  o.field.eps_hard = eps_hard;
  o.field.eps_soft = eps_soft;
  const double cells_w = map.geometry.width + 2.0 * (0.2 / map.geometry.resolution + 4);
  const double cells_h = map.geometry.height + 2.0 * (0.2 / map.geometry.resolution + 4);
  o.field.max_cells = static_cast<std::size_t>(cells_w * cells_h) + 1024;
  o.field.max_axis = static_cast<std::uint32_t>(std::max(cells_w, cells_h)) + 16;
  o.allocate_model_table = allocate_model_table;
  o.collect_capacity = 8192;
  return o;
}
std::size_t arena_bytes(const fw::pransam::MatcherOptions& o) {
  return (o.allocate_model_table ? 2 : 1) * fw::pransam::kNumSlots * 12 +
         fw::pransam::ContactField<2>::arena_bytes(o.field) +
         static_cast<std::size_t>(o.max_model_points) * 8 + o.num_workers * (std::size_t(1) << 20) +
         o.collect_capacity * 64 + (std::size_t(8) << 20);
}
}  // namespace

bool build_table_section(RealCase* c, const TableBuild& build, double* seconds, std::string* error) {
  fw::pransam::MatcherOptions o = options_for(c->map, 2, true);
  fw::StartupArena arena;
  fw::Status s = arena.init_mapped(arena_bytes(o), false, "table build");
  fw::pransam::Matcher<2> m;
  if (s.is_ok()) s = m.init(o, arena, nullptr);
  if (s.is_ok()) s = m.set_model(c->map.points, c->map.num_points, c->dataset.c_str());
  const double t0 = now_ms();
  if (s.is_ok()) s = m.fill_model_table(build.seed, build.triples, build.extent, build.min_height_ratio);
  *seconds = (now_ms() - t0) / 1000.0;
  if (!s.is_ok()) {
    *error = s.message();
    return false;
  }
  std::vector<std::uint8_t> section(fw::pransam::relation_table_section_bytes());
  s = fw::pransam::write_relation_table_section(m.model_table(), 2, build.min_height_ratio,
                                                reinterpret_cast<const float*>(c->map.points), c->map.num_points,
                                                build.triples, section.data(), section.size());
  if (!s.is_ok()) {
    *error = s.message();
    return false;
  }
  RosMap ros;
  if (!read_ros_map(global_map_yaml_path(c->dataset), &ros, error)) return false;
  MapImageWriter w;
  if (!w.set_map(ros, error)) return false;
  if (!w.add_section(fw::MapSectionType::kRelationTable2D, std::move(section), fw::pransam::kRelationTableSectionVersion,
                     error)) {
    return false;
  }
  std::vector<std::uint8_t> image = w.bytes();
  // The points of the rebuilt image must be the ones the table indexes.
  fw::StartupArena check_arena;
  fw::GlobalMap check;
  s = check_arena.init_mapped(fw::map_image_arena_bytes(image.data(), image.size()) + (std::size_t(4) << 20), false,
                              "table check");
  if (s.is_ok()) s = fw::load_map_image(image.data(), image.size(), check_arena, &check, "image with table");
  if (!s.is_ok()) {
    *error = s.message();
    return false;
  }
  if (check.num_points != c->map.num_points ||
      std::memcmp(check.points, c->map.points, sizeof(fw::Point2f) * check.num_points) != 0) {
    *error = "pransam eval: rebuilt map image has different points than the cached one";
    return false;
  }
  c->image = std::move(image);
  return true;
}

bool make_matcher(const RealCase& c, int pool_threads, int T, bool precomputed, MatcherHandle* out,
                  std::string* error) {
  fw::pransam::MatcherOptions o = options_for(c.map, T, !precomputed, c.eps_hard, c.eps_soft);
  // Online matching runs two barriers per round (draw/rate, then apply inserts): larger rounds.
  // Precomputed matching stops early, and a large last round would be wasted work.
  o.max_batch = precomputed ? 1024 : 4096;
  out->arena = std::make_unique<fw::StartupArena>();
  fw::Status s = out->arena->init_mapped(arena_bytes(o), false, "pransam eval");
  if (!s.is_ok()) {
    *error = s.message();
    return false;
  }
  out->pool.reset();
  if (pool_threads > 0) {
    out->pool = std::make_unique<fw::WorkerPool>();
    fw::WorkerPoolOptions po;
    po.num_workers = pool_threads;
    s = out->pool->start(po);
    if (!s.is_ok()) {
      *error = s.message();
      return false;
    }
  }
  out->matcher = std::make_unique<fw::pransam::Matcher<2>>();
  s = out->matcher->init(o, *out->arena, out->pool.get());
  if (s.is_ok()) s = out->matcher->set_model(c.map.points, c.map.num_points, c.dataset.c_str());
  if (s.is_ok() && precomputed) {
    std::size_t len = 0;
    const std::uint8_t* sec = fw::find_section(c.image.data(), c.image.size(), fw::MapSectionType::kRelationTable2D, &len);
    if (sec == nullptr) {
      *error = "pransam eval: map image of '" + c.dataset + "' has no relation table section (build_table_section)";
      return false;
    }
    fw::pransam::RelationTableSection view;
    s = fw::pransam::parse_relation_table_section(sec, len, 2, reinterpret_cast<const float*>(c.map.points),
                                                  c.map.num_points, &view);
    if (s.is_ok()) s = out->matcher->use_precomputed_table(view.slots, view.extent);
  }
  if (!s.is_ok()) {
    *error = s.message();
    return false;
  }
  return true;
}

ScanMapRun run_scan_map(const RealCase& c, MatcherHandle& m, const fw::pransam::MatchParams& params,
                        const Criterion& crit, bool verbose) {
  ScanMapRun run;
  for (std::size_t qi = 0; qi < c.queries.size(); ++qi) {
    const ScanQuery& q = c.queries[qi];
    fw::pransam::MatchParams p = params;
    p.seed = params.seed * 7919ull + q.index;
    fw::pransam::MatchResult<2> r;
    const double t0 = now_ms();
    const fw::Status s = m.matcher->match(q.points.data(), q.points.size(), p, &r);
    const double dt = now_ms() - t0;
    ++run.n;
    run.ms.push_back(dt);
    run.iterations.push_back(static_cast<double>(r.stats.iterations));
    run.collisions.push_back(static_cast<double>(r.stats.collisions));
    run.best_quality.push_back(r.best_valid ? r.best.quality : 0.0);
    double et = NAN, er = NAN;
    if (s.is_ok() && r.best_valid) {
      const fw::Se2f e = fw::pransam::to_se2(r.best);
      et = std::hypot(e.x - q.x, e.y - q.y);
      er = std::fabs(wrap(e.theta - q.theta)) * 180.0 / M_PI;
    }
    run.trans_err.push_back(et);
    run.rot_err_deg.push_back(er);
    const char* verdict;
    if (!s.is_ok() || !r.best_valid) {
      ++run.nothing;
      verdict = "nothing";
    } else if (et < crit.max_trans && er < crit.max_rot_deg) {
      ++run.correct;
      verdict = r.found ? "correct" : "correct (below Ω_thres)";
      if (!r.found) ++run.correct_below_thres;
    } else {
      ++run.wrong;
      verdict = r.found ? "WRONG" : "WRONG (below Ω_thres)";
    }
    if (s.is_ok() && r.best_valid && !r.found) ++run.below_thres;
    if (verbose) {
      std::printf("  scan %5zu pts %3zu  %7.2f ms  it %6llu coll %6llu  Ω %.3f  err %.2f m %.1f°  %s%s%s\n", q.index,
                  q.points.size(), dt, static_cast<unsigned long long>(r.stats.iterations),
                  static_cast<unsigned long long>(r.stats.collisions), r.best_valid ? r.best.quality : 0.0f, et, er,
                  verdict, s.is_ok() ? "" : " status: ", s.is_ok() ? "" : s.message());
    }
  }
  return run;
}

std::vector<Theorem1Row> theorem1(const RealCase& c, int T, const std::vector<std::uint32_t>& imax,
                                  std::size_t queries, std::uint64_t seed, std::string* error) {
  std::vector<Theorem1Row> rows;
  MatcherHandle m;
  if (!make_matcher(c, 2, T, false, &m, error)) return rows;
  for (int tau = 1; tau < T; ++tau) {
    for (std::uint32_t im : imax) {
      Theorem1Row row;
      row.tau = tau;
      row.max_iterations = im;
      std::size_t n = 0, ok = 0;
      for (std::size_t qi = 0; qi < c.queries.size() && n < queries; ++qi, ++n) {
        const ScanQuery& q = c.queries[qi];
        fw::pransam::MatchParams p;
        p.seed = seed * 31 + q.index;
        p.tau = tau;
        p.max_iterations = im;
        p.omega_thres = 1.0f;  // never stop early: the figure is quality after I_max
        fw::pransam::MatchResult<2> r;
        const double t0 = now_ms();
        const fw::Status s = m.matcher->match(q.points.data(), q.points.size(), p, &r);
        row.mean_ms += now_ms() - t0;
        if (!s.is_ok()) continue;
        row.mean_best_quality += r.best_valid ? r.best.quality : 0.0;
        row.mean_collisions += static_cast<double>(r.stats.collisions);
        if (r.best_valid) {
          const fw::Se2f e = fw::pransam::to_se2(r.best);
          if (std::hypot(e.x - q.x, e.y - q.y) < 0.3 && std::fabs(wrap(e.theta - q.theta)) < 5.0 * M_PI / 180.0) ++ok;
        }
      }
      if (n) {
        row.mean_best_quality /= static_cast<double>(n);
        row.mean_collisions /= static_cast<double>(n);
        row.mean_ms /= static_cast<double>(n);
        row.success = static_cast<double>(ok) / static_cast<double>(n);
      }
      rows.push_back(row);
    }
  }
  return rows;
}

ThreeDRun run_3d(std::size_t trials, int pool_threads, std::uint32_t max_iterations, std::string* error,
                 std::uint32_t refine_iterations, float refine_min_quality) {
  ThreeDRun run;
  fw::pransam::MatcherOptions o;
  o.num_workers = 2;
  o.max_scene_points = 8192;
  o.max_model_points = 65536;
  o.field.resolution = 0.05f;
  o.field.eps_hard = 0.10f;
  o.field.eps_soft = 0.20f;
  o.field.max_cells = std::size_t(4) << 20;
  o.field.max_axis = 512;
  fw::StartupArena arena;
  fw::Status s = arena.init_mapped(arena_bytes(o) + (std::size_t(24) << 20), false, "3d eval");
  fw::WorkerPool pool;
  if (s.is_ok() && pool_threads > 0) {
    fw::WorkerPoolOptions po;
    po.num_workers = pool_threads;
    s = pool.start(po);
  }
  fw::pransam::Matcher<3> m;
  if (s.is_ok()) s = m.init(o, arena, pool_threads > 0 ? &pool : nullptr);
  fw::RandomStream rb(2012, 1);
  const std::vector<P3> b = pransam_scenes::crop(pransam_scenes::textured_room(60.0f, rb), P3(-1, -1, -1),
                                                 P3(6.5f, 7, 4));
  if (s.is_ok()) s = m.set_model(b.data(), b.size(), "3d room crop B");
  if (!s.is_ok()) {
    *error = s.message();
    return run;
  }
  for (std::size_t k = 0; k < trials; ++k) {
    fw::RandomStream ra(2012, 100 + k), rt(2012, 1000 + k);
    const std::vector<P3> aw = pransam_scenes::crop(pransam_scenes::textured_room(15.0f, ra), P3(1.5f, -1, -1),
                                                    P3(9, 7, 4));
    const float yaw = rt.uniform(-3.1f, 3.1f), pitch = rt.uniform(-0.2f, 0.2f), roll = rt.uniform(-0.2f, 0.2f);
    const Eigen::Matrix3f r = (Eigen::AngleAxisf(yaw, Eigen::Vector3f::UnitZ()) *
                               Eigen::AngleAxisf(pitch, Eigen::Vector3f::UnitY()) *
                               Eigen::AngleAxisf(roll, Eigen::Vector3f::UnitX())).toRotationMatrix();
    // One draw per declarator, last coordinate first (as x86-64 GCC evaluated the constructor's
    // arguments when the figures were measured; the order of arguments is unspecified).
    const float tz = rt.uniform(-0.5f, 0.5f), ty = rt.uniform(-2, 2), tx = rt.uniform(-2, 2);
    const P3 t(tx, ty, tz);
    std::vector<P3> a;
    for (const P3& p : aw) {
      const P3 noisy = p + pransam_scenes::gaussian3f(rt, 0.005f);
      a.push_back(r.transpose() * (noisy - t));
    }
    fw::pransam::MatchParams p;
    p.seed = 77 + k;
    p.max_iterations = max_iterations;
    p.omega_thres = 1.0f;  // run I_max, keep the best (the room is nearly 180°-symmetric)
    p.refine_iterations = refine_iterations;
    p.refine_min_quality = refine_min_quality;
    fw::pransam::MatchResult<3> res;
    const double t0 = now_ms();
    s = m.match(a.data(), a.size(), p, &res);
    run.ms.push_back(now_ms() - t0);
    ++run.trials;
    if (!s.is_ok() || !res.best_valid) {
      run.trans_err.push_back(NAN);
      run.rot_err_deg.push_back(NAN);
      continue;
    }
    const double et = (res.best.translation - t).norm();
    const Eigen::Vector3f e = fw::pransam::rpy(res.best.rotation), g = fw::pransam::rpy(r);
    double er = 0;
    for (int i = 0; i < 3; ++i) er = std::max(er, std::fabs(wrap(e(i) - g(i))) * 180.0 / M_PI);
    run.trans_err.push_back(et);
    run.rot_err_deg.push_back(er);
    if (et < 0.25 && er < 3.0) ++run.success;
  }
  return run;
}

bool determinism_check(const RealCase& c, bool precomputed, std::string* detail) {
  std::vector<std::vector<fw::pransam::Hypothesis<2>>> runs;
  for (int threads : {1, 2, 2}) {
    MatcherHandle m;
    std::string err;
    if (!make_matcher(c, threads, 2, precomputed, &m, &err)) {
      *detail = err;
      return false;
    }
    fw::pransam::MatchParams p;
    p.seed = 4242;
    p.collect_all = true;
    p.max_iterations = 20000;
    p.omega_thres = 0.5f;
    std::vector<fw::pransam::Hypothesis<2>> all;
    for (std::size_t qi = 0; qi < c.queries.size() && qi < 5; ++qi) {
      fw::pransam::MatchResult<2> r;
      if (!m.matcher->match(c.queries[qi].points.data(), c.queries[qi].points.size(), p, &r).is_ok()) continue;
      all.insert(all.end(), r.hypotheses, r.hypotheses + r.num_hypotheses);
    }
    runs.push_back(std::move(all));
  }
  for (std::size_t k = 1; k < runs.size(); ++k) {
    if (runs[k].size() != runs[0].size()) {
      *detail = "hypothesis counts differ: " + std::to_string(runs[0].size()) + " vs " + std::to_string(runs[k].size());
      return false;
    }
    for (std::size_t i = 0; i < runs[0].size(); ++i) {
      const auto& x = runs[k][i];
      const auto& y = runs[0][i];
      if (std::memcmp(x.rotation.data(), y.rotation.data(), sizeof(float) * 4) != 0 ||
          std::memcmp(x.translation.data(), y.translation.data(), sizeof(float) * 2) != 0 ||
          std::memcmp(&x.quality, &y.quality, sizeof(float)) != 0 || x.iteration != y.iteration ||
          x.worker != y.worker) {
        *detail = "hypothesis " + std::to_string(i) + " differs";
        return false;
      }
    }
  }
  *detail = std::to_string(runs[0].size()) + " hypotheses identical over 3 runs (1, 2, 2 pool threads)";
  return !runs[0].empty();
}

}  // namespace sim::pransam_eval
