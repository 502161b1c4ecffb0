// mml-pransam-pcl: the PCL peers of pRANSAM 3-D (issue 17) on the draws of cloud_draws.h.
//   mml-pransam-pcl [--cloud office1|car6|milk|bunny|all] [--method fpfh|k4pcs|both] [--draws 100] [--first 0]
//                   [--threads 2] [--max-seconds 0] [--seed 1] [--k4pcs-samples 0] [--verbose]
// Reproducible per --seed: FPFH + prerejective always; K-4PCS with --threads 1 and --max-seconds 0
// (pcl_peers.cpp: PCL seeds rand() from time(), which is wrapped in this tool).
// bench_pransam_pcl OUT.json (same source, MMLFW_PCL_BENCH): reads the figures bench_pransam wrote to
// OUT.json, runs both peers on the first N draws of each cloud (the same draws pRANSAM had; N =
// MMLFW_PCL_DRAWS, default 3: one FPFH + prerejective run takes 15–30 s on these clouds, so 300 draws
// would take hours), FPFH on 2 OpenMP threads (and the first office draw on one thread), K-4PCS on
// one thread without a time bound (the only reproducible setting, pcl_peers.cpp), runs pRANSAM again
// on exactly those draws, and writes OUT.json back with the pcl_* figures and the comparison added.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "sim/common/bench_json.h"
#include "sim/common/cli_main.h"
#include "sim/common/flat_json_read.h"
#include "sim/eval/pransam_eval/pcl/pcl_peers.h"
#include "sim/eval/pransam_eval/pransam3d_real.h"
#include "sim/eval/pransam_eval/cli_args.h"
#include "sim/eval/pransam_eval/pransam_eval_lib.h"

using namespace sim::pransam_eval;

namespace {

int fail(const std::string& e) {
  std::fprintf(stderr, "mml-pransam-pcl: %s\n", e.c_str());
  return 1;
}

// The draws of one cloud, or the bunny pair repeated `runs` times (independent seeds / runs).
bool draws_of(const std::string& cloud, std::size_t n, std::vector<CloudDraw>* out, std::string* err) {
  if (cloud == "bunny") {
    CloudDraw b;
    if (!load_bunny(&b, err)) return false;
    out->assign(n, b);
    for (std::size_t k = 0; k < n; ++k) (*out)[k].index = k;
    return true;
  }
  DrawOptions o;
  o.draws = n;
  o.voxel = default_voxel(cloud);
  return load_draws(cloud, o, out, err);
}

#ifdef MMLFW_PCL_BENCH

int bench(const std::string& path) {
  sim::BenchJson json;
  // Keep what bench_pransam wrote (flat "key": value lines), in order.
  {
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line)) {
      const std::size_t q0 = line.find('"'), q1 = line.find("\":", q0 + 1);
      if (q0 == std::string::npos || q1 == std::string::npos) continue;
      const std::string key = line.substr(q0 + 1, q1 - q0 - 1);
      std::string v = line.substr(q1 + 2);
      while (!v.empty() && (v.back() == ',' || v.back() == ' ')) v.pop_back();
      while (!v.empty() && v.front() == ' ') v.erase(v.begin());
      json.add_raw(key, v);
    }
  }
  std::string err;
  const char* env = std::getenv("MMLFW_PCL_DRAWS");
  const std::size_t n = env != nullptr && std::atoi(env) > 0 ? static_cast<std::size_t>(std::atoi(env)) : 3;
  json.add_int("pcl_draws_per_cloud", static_cast<long long>(n));
  // K-4PCS source sample bound (pcl_peers.cpp): MMLFW_K4PCS_SAMPLES, default 1000.
  const char* ks = std::getenv("MMLFW_K4PCS_SAMPLES");
  const int k4pcs_samples = ks != nullptr && std::atoi(ks) >= 0 ? std::atoi(ks) : 1000;
  json.add_int("pcl_k4pcs_source_samples", k4pcs_samples);
  std::map<std::string, std::vector<CloudDraw>> draws;
  for (const char* c : {"office1", "car6", "milk"}) {
    if (!draws_of(c, n, &draws[c], &err)) return fail(err);
  }
  // pRANSAM on exactly these draws (its 100-draw figures are bench_pransam's).
  double pr_p50 = NAN;
  {
    const Pransam3dConfig c3;
    MethodRun office, objects;
    if (!run_pransam3d(draws["office1"], c3, 2, &office, &err)) return fail(err);
    for (const char* c : {"car6", "milk"}) {
      MethodRun r;
      if (!run_pransam3d(draws[c], c3, 2, &r, &err)) return fail(err);
      objects.append(r);
    }
    std::printf("%s\n%s\n", summary_line("office1 pransam (PCL subset)", office).c_str(),
                summary_line("car6+milk pransam (PCL subset)", objects).c_str());
    json.add("pransam3d_office_success_pcl_subset", office.success());
    json.add("pransam3d_office_ms_p50_pcl_subset", office.ms_p50());
    pr_p50 = office.ms_p50();
    json.add("pransam3d_objects_success_pcl_subset", objects.success());
  }
  double best_success = -1, best_p50 = NAN;
  std::string best_name;
  for (PclMethod m : {PclMethod::kFpfhPrerejective, PclMethod::kK4pcs}) {
    const std::string name = pcl_method_name(m);
    MethodRun office, objects, office1t;
    const int threads = m == PclMethod::kK4pcs ? 1 : 2;  // K-4PCS: reproducible only on one thread
    if (!run_pcl(m, draws["office1"], threads, &office, &err, true, 0, 1, k4pcs_samples)) return fail(err);
    for (const char* c : {"car6", "milk"}) {
      MethodRun r;
      if (!run_pcl(m, draws[c], threads, &r, &err, true, 0, 1, k4pcs_samples)) return fail(err);
      std::printf("%s\n", summary_line(std::string(c) + " " + name, r).c_str());
      objects.append(r);
    }
    if (threads == 1) {
      office1t = office;
    } else {
      const std::vector<CloudDraw> first(draws["office1"].begin(), draws["office1"].begin() + 1);
      if (!run_pcl(m, first, 1, &office1t, &err, true)) return fail(err);
    }
    std::printf("%s\n%s\n%s\n", summary_line("office1 " + name + " (" + std::to_string(threads) + " threads)", office).c_str(),
                summary_line("car6+milk " + name, objects).c_str(),
                summary_line("office1 " + name + " (1 thread)", office1t).c_str());
    json.add_int(name + "_threads", threads);
    json.add(name + "_office_success", office.success());
    json.add_int(name + "_office_wrong", static_cast<long long>(office.wrong()));
    json.add(name + "_office_ms_p50", office.ms_p50());
    json.add(name + "_office_ms_p99", office.ms_p99());
    json.add(name + "_office_ms_p50_1t", office1t.ms_p50());
    json.add(name + "_objects_success", objects.success());
    json.add_int(name + "_objects_wrong", static_cast<long long>(objects.wrong()));
    json.add_int(name + "_objects_draws", static_cast<long long>(objects.n()));
    json.add(name + "_objects_ms_p50", objects.ms_p50());
    if (office.success() > best_success || (office.success() == best_success && office.ms_p50() < best_p50)) {
      best_success = office.success();
      best_p50 = office.ms_p50();
      best_name = name;
    }
  }
  // The better PCL method on the office, and how much faster pRANSAM is (same draws, 2 threads).
  json.add_string("pcl_best_office_method", best_name);
  json.add("pransam3d_speedup_vs_best_pcl_office", best_p50 / pr_p50);
  return json.write(path) ? 0 : 1;
}
#endif

}  // namespace

static int run_main(int argc, char** argv) {
#ifdef MMLFW_PCL_BENCH
  if (argc < 2) return fail("usage: bench_pransam_pcl OUT.json");
  return bench(argv[1]);
#else
  const auto a = parse(argc, argv, 1);
  const std::string which = get(a, "cloud", "all"), method = get(a, "method", "both");
  const int threads = std::stoi(get(a, "threads", "2"));
  const int max_seconds = std::stoi(get(a, "max-seconds", "0"));
  const std::size_t n = std::stoul(get(a, "draws", "100"));
  const std::uint64_t seed = std::stoull(get(a, "seed", "1"));
  const int k4pcs_samples = std::stoi(get(a, "k4pcs-samples", "0"));
  const std::size_t first = std::stoul(get(a, "first", "0"));  // skip draws 0 … first − 1 (resume a long run)
  std::string err;
  for (const char* c : {"office1", "car6", "milk", "bunny"}) {
    if (which != "all" && which != c) continue;
    std::vector<CloudDraw> draws;
    const bool bunny = std::string(c) == "bunny";
    if (!draws_of(c, bunny ? 10 : first + n, &draws, &err)) return fail(err);
    if (!bunny) draws.erase(draws.begin(), draws.begin() + static_cast<std::ptrdiff_t>(first));
    for (PclMethod m : {PclMethod::kFpfhPrerejective, PclMethod::kK4pcs}) {
      if (method != "both" && method != (m == PclMethod::kK4pcs ? "k4pcs" : "fpfh")) continue;
      MethodRun r;
      if (!run_pcl(m, draws, threads, &r, &err, a.count("verbose") != 0, max_seconds, seed, k4pcs_samples)) return fail(err);
      if (std::string(c) == "bunny") {
        std::vector<double> rms;
        for (const auto& oc : r.outcomes) rms.push_back(oc.inlier_rms);
        std::printf("bunny %s: %zu/%zu reported, inlier RMS p50 %.5f m, runs agreeing %.0f %%, p50 %.1f ms\n",
                    pcl_method_name(m), r.n() - r.nothing(), r.n(), percentile(rms, 0.5),
                    100.0 * agreement(draws[0], r.outcomes), r.ms_p50());
      } else {
        std::printf("%s\n", summary_line(std::string(c) + " " + pcl_method_name(m) + " (" + std::to_string(threads) +
                                             " threads)", r).c_str());
      }
    }
  }
  return 0;
#endif
}

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress lines appear while the long runs go on
  return sim::guarded_main("mml-pransam-pcl", [&] { return run_main(argc, argv); });
}
