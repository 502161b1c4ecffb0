// mml-pransam-eval: pRANSAM experiments (dissertation Sec. 4.5) on real data and a synthetic 3-D scene.
//   mml-pransam-eval scan-map [--dataset intel] [--mode precomp|online] [--threads 2] [--T 2] [--every 10]
//                             [--iters 100000] [--thres 0.8] [--hard] [--seed 1] [--max-range 12]
//                             [--triples 2000000] [--extent 10] [--max-queries 0] [--verbose]
//   mml-pransam-eval theorem1 [--dataset intel] [--queries 20]
//   mml-pransam-eval 3d [--cloud office1|car6|milk|bunny|all|room] [--draws 100] [--threads 2] [--iters 200000]
//                       [--thres 0.55] [--stop 1] [--extent-voxels 24] [--refine 10] [--refine-min 0.35]
//                       [--seed 1] [--voxel V] [--no-ambiguity] [--amb-z 3] [--amb-cell 0] [--amb-margin] [--no-retry] [--smaller-first] [--verbose]   (real clouds of ../shared/data/pcl3d, issue 17;
//                       --cloud room: the synthetic textured room with --trials 10)
//   mml-pransam-eval build-table [--dataset intel] [--triples 2000000] [--extent 10] --out FILE.mmap
#include <cstdio>
#include <cmath>
#include <cstdlib>
#include <map>
#include <string>

#include "sim/eval/pransam_eval/pransam3d_real.h"
#include "sim/eval/pransam_eval/cli_args.h"
#include "sim/eval/pransam_eval/pransam_eval_lib.h"
#include "sim/map/map_image_writer.h"
#include "sim/common/cli_main.h"

using namespace sim::pransam_eval;

namespace {
int usage() {
  std::fprintf(stderr, "usage: mml-pransam-eval scan-map|theorem1|3d|build-table [options] (see source header)\n");
  return 2;
}
Pransam3dConfig config_3d(const std::map<std::string, std::string>& a) {
  Pransam3dConfig c;
  c.max_iterations = static_cast<std::uint32_t>(std::stoul(get(a, "iters", std::to_string(c.max_iterations))));
  c.omega_thres = std::stof(get(a, "thres", std::to_string(c.omega_thres)));
  c.omega_stop = std::stof(get(a, "stop", std::to_string(c.omega_stop)));
  c.extent_voxels = std::stof(get(a, "extent-voxels", std::to_string(c.extent_voxels)));
  c.eps_hard_voxels = std::stof(get(a, "eps-hard", std::to_string(c.eps_hard_voxels)));
  c.eps_soft_voxels = std::stof(get(a, "eps-soft", std::to_string(c.eps_soft_voxels)));
  c.field_voxels = std::stof(get(a, "field-voxels", std::to_string(c.field_voxels)));
  c.refine_iterations = static_cast<std::uint32_t>(std::stoul(get(a, "refine", std::to_string(c.refine_iterations))));
  c.refine_min_quality = std::stof(get(a, "refine-min", std::to_string(c.refine_min_quality)));
  c.seed = std::stoull(get(a, "seed", "1"));
  c.free_space = a.count("free-space") != 0;
  c.free_space_min_quality = std::stof(get(a, "fs-min", std::to_string(c.free_space_min_quality)));
  c.free_space_block_voxels = std::stof(get(a, "fs-block", std::to_string(c.free_space_block_voxels)));
  c.free_space_margin_voxels = std::stof(get(a, "fs-margin", std::to_string(c.free_space_margin_voxels)));
  c.max_blocked = std::stof(get(a, "max-blocked", std::to_string(c.max_blocked)));
  c.ambiguity = a.count("no-ambiguity") == 0;
  c.smaller_as_scene = a.count("smaller-first") != 0;  // --smaller-first: A = the cloud of fewer points (Pransam3dConfig)
  c.retry_other_way = a.count("no-retry") == 0;  // --no-retry: one direction only
  c.ambiguity_options.z = std::stod(get(a, "amb-z", std::to_string(c.ambiguity_options.z)));
  c.ambiguity_options.paired = a.count("amb-margin") == 0;
  c.ambiguity_options.cell_voxels = std::stod(get(a, "amb-cell", std::to_string(c.ambiguity_options.cell_voxels)));  // --amb-margin: the unpaired margin rule (ambiguity3d.h)
  return c;
}

// Issue 17: pRANSAM 3-D on the real clouds (office1, car6, milk: 100 draws each; bun0 ↔ bun4).
int run_real_3d(const std::map<std::string, std::string>& a) {
  const std::string which = get(a, "cloud", "all");
  const int threads = std::stoi(get(a, "threads", "2"));
  const bool verbose = a.count("verbose") != 0;
  const Pransam3dConfig c = config_3d(a);
  std::string err;
  for (const std::string cloud : {"office1", "car6", "milk"}) {
    if (which != "all" && which != cloud) continue;
    DrawOptions o;
    o.draws = std::stoul(get(a, "draws", "100"));
    o.voxel = std::stof(get(a, "voxel", std::to_string(default_voxel(cloud))));
    std::vector<CloudDraw> draws;
    if (!load_draws(cloud, o, &draws, &err)) { std::fprintf(stderr, "%s\n", err.c_str()); return 1; }
    MethodRun r;
    if (!run_pransam3d(draws, c, threads, &r, &err, verbose)) { std::fprintf(stderr, "%s\n", err.c_str()); return 1; }
    std::printf("%s\n", summary_line(cloud + " pransam (" + std::to_string(threads) + " threads)", r).c_str());
    std::vector<double> vms;
    for (const auto& oc : r.outcomes)
      if (oc.verdict_ms > 0) vms.push_back(oc.verdict_ms);  // draws that had an answer to judge
    std::printf("%s ambiguity verdict: p50 %.1f ms p99 %.1f ms (included in the times above)\n", cloud.c_str(),
                percentile(vms, 0.5), percentile(vms, 0.99));
  }
  if (which == "all" || which == "bunny") {
    CloudDraw bunny;
    if (!load_bunny(&bunny, &err)) { std::fprintf(stderr, "%s\n", err.c_str()); return 1; }
    std::vector<CloudDraw> runs;
    for (std::size_t k = 0; k < 10; ++k) {
      runs.push_back(bunny);
      runs.back().index = k;
    }
    MethodRun r;
    if (!run_pransam3d(runs, c, threads, &r, &err, verbose)) { std::fprintf(stderr, "%s\n", err.c_str()); return 1; }
    std::vector<double> rms;
    for (const auto& oc : r.outcomes) rms.push_back(oc.inlier_rms);
    std::printf("bunny pransam: %zu/10 reported, %zu ambiguous, inlier RMS p50 %.5f m, runs agreeing %.0f %%, p50 %.1f ms\n",
                r.n() - r.nothing() - r.ambiguous(), r.ambiguous(), percentile(rms, 0.5),
                100.0 * agreement(bunny, r.outcomes), r.ms_p50());
  }
  return 0;
}
}  // namespace

static int run_main(int argc, char** argv) {
  if (argc < 2) return usage();
  const std::string cmd = argv[1];
  const auto a = parse(argc, argv, 2);
  std::string err;
  if (cmd == "3d" && get(a, "cloud", "all") != "room") return run_real_3d(a);
  if (cmd == "3d") {
    const ThreeDRun r = run_3d(std::stoul(get(a, "trials", "10")), std::stoi(get(a, "threads", "2")),
                               static_cast<std::uint32_t>(std::stoul(get(a, "iters", "200000"))), &err,
                               static_cast<std::uint32_t>(std::stoul(get(a, "refine", "0"))),
                               std::stof(get(a, "refine-min", "0.45")));
    if (!err.empty()) { std::fprintf(stderr, "%s\n", err.c_str()); return 1; }
    for (std::size_t i = 0; i < r.trials; ++i)
      std::printf("trial %zu: %.1f ms  trans err %.3f m  rot err %.2f deg\n", i, r.ms[i], r.trans_err[i], r.rot_err_deg[i]);
    std::printf("3d: success %zu/%zu  p50 %.1f ms\n", r.success, r.trials, r.p50());
    return 0;
  }
  CaseOptions co;
  co.every = std::stoul(get(a, "every", "10"));
  co.max_range = std::stof(get(a, "max-range", "12"));
  co.max_queries = std::stoul(get(a, "max-queries", "0"));
  RealCase c;
  if (!load_real_case(get(a, "dataset", "intel"), co, &c, &err)) { std::fprintf(stderr, "%s\n", err.c_str()); return 1; }
  c.eps_hard = std::stof(get(a, "eps-hard", "0.1"));
  c.eps_soft = std::stof(get(a, "eps-soft", "0.2"));
  std::printf("%s: map %u points (%ux%u @ %.3f m), %zu queries\n", c.dataset.c_str(), c.map.num_points,
              c.map.geometry.width, c.map.geometry.height, c.map.geometry.resolution, c.queries.size());
  TableBuild tb;
  tb.triples = std::stoull(get(a, "triples", "2000000"));
  tb.extent = std::stof(get(a, "extent", "10"));
  if (cmd == "build-table") {
    double sec = 0;
    if (!build_table_section(&c, tb, &sec, &err)) { std::fprintf(stderr, "%s\n", err.c_str()); return 1; }
    const std::string out = get(a, "out", "");
    if (out.empty()) return usage();
    if (!sim::write_file_bytes(out, c.image, &err)) { std::fprintf(stderr, "%s\n", err.c_str()); return 1; }
    std::printf("relation table (%llu triples, extent %.1f m) built in %.2f s; image %zu bytes -> %s\n",
                static_cast<unsigned long long>(tb.triples), tb.extent, sec, c.image.size(), out.c_str());
    return 0;
  }
  if (cmd == "theorem1") {
    const auto rows = theorem1(c, 4, {2000, 5000, 10000, 20000, 40000}, std::stoul(get(a, "queries", "20")), 1, &err);
    if (rows.empty()) { std::fprintf(stderr, "%s\n", err.c_str()); return 1; }
    std::printf("T=4 tau I_max  mean_best_Ω  mean_collisions  mean_ms  success\n");
    for (const auto& r : rows)
      std::printf("     %d  %6u  %.3f  %10.1f  %7.2f  %.2f\n", r.tau, r.max_iterations, r.mean_best_quality,
                  r.mean_collisions, r.mean_ms, r.success);
    return 0;
  }
  if (cmd == "diag") {
    MatcherHandle m;
    if (!make_matcher(c, 2, 2, false, &m, &err)) { std::fprintf(stderr, "%s\n", err.c_str()); return 1; }
    double sum = 0;
    std::vector<double> qs;
    for (const auto& q : c.queries) {
      fw::pransam::Hypothesis<2> h;
      const float cs = std::cos(static_cast<float>(q.theta)), sn = std::sin(static_cast<float>(q.theta));
      h.rotation << cs, -sn, sn, cs;
      h.translation = P2(static_cast<float>(q.x), static_cast<float>(q.y));
      double f = 0, hd = 0;
      for (const auto& pt : q.points) {
        const int v = m.matcher->field().contact(h.apply(pt));
        f += v == 255 ? 1.0 : v / 255.0;
        hd += v == 255 ? 1.0 : 0.0;
      }
      f /= q.points.size();
      hd /= q.points.size();
      qs.push_back(f);
      sum += f;
      if (a.count("verbose")) std::printf("scan %zu: true-pose Ω fuzzy %.3f hard %.3f (%zu pts)\n", q.index, f, hd, q.points.size());
    }
    std::printf("true-pose fuzzy Ω: mean %.3f p10 %.3f p50 %.3f\n", sum / qs.size(), percentile(qs, 0.1), percentile(qs, 0.5));
    return 0;
  }
  if (cmd != "scan-map") return usage();
  // (--thres 1 runs I_max; then "found" means nothing, so judge the best hypothesis.)
  const bool precomp = get(a, "mode", "precomp") == "precomp";
  if (precomp) {
    double sec = 0;
    if (!build_table_section(&c, tb, &sec, &err)) { std::fprintf(stderr, "%s\n", err.c_str()); return 1; }
    std::printf("offline table: %.2f s\n", sec);
  }
  MatcherHandle m;
  if (!make_matcher(c, std::stoi(get(a, "threads", "2")), std::stoi(get(a, "T", "2")), precomp, &m, &err)) {
    std::fprintf(stderr, "%s\n", err.c_str());
    return 1;
  }
  fw::pransam::MatchParams p;
  p.seed = std::stoull(get(a, "seed", "1"));
  p.max_iterations = static_cast<std::uint32_t>(std::stoul(get(a, "iters", "100000")));
  p.omega_thres = std::stof(get(a, "thres", "0.8"));
  p.fuzzy = a.count("hard") == 0;
  p.max_extent = tb.extent;
  p.refine_iterations = static_cast<std::uint32_t>(std::stoul(get(a, "refine", "0")));
  p.refine_min_quality = std::stof(get(a, "refine-min", "0.6"));
  p.scene_origin_is_sensor = a.count("free-space") != 0;
  p.free_space_margin = std::stof(get(a, "free-margin", "0.3"));
  p.first_batch = static_cast<std::uint32_t>(std::stoul(get(a, "first-batch", "256")));
  p.max_blocked_fraction = std::stof(get(a, "max-blocked", "0.1"));
  const ScanMapRun r = run_scan_map(c, m, p, Criterion(), a.count("verbose") != 0);
  std::printf("%s %s T=%s threads=%s %s: correct %zu wrong %zu nothing %zu of %zu (%.1f %%; %zu returned below "
              "Ω_thres, %zu of them correct)  p50 %.2f ms  p99 %.2f ms  mean iterations %.0f\n",
              c.dataset.c_str(), precomp ? "precomp" : "online", get(a, "T", "2").c_str(), get(a, "threads", "2").c_str(),
              p.fuzzy ? "fuzzy" : "hard", r.correct, r.wrong, r.nothing, r.n, 100.0 * r.success(), r.below_thres,
              r.correct_below_thres, r.p50(), r.p99(), r.mean_iterations());
  return 0;
}

int main(int argc, char** argv) {
  return sim::guarded_main("mml-pransam-eval", [&] { return run_main(argc, argv); });
}
