// mml-carmen: command-line access to the sim/io readers and writers.
//   mml-carmen info LOG [--skip-bad-lines]            record counts, time span, bad lines
//   mml-carmen convert IN OUT [--skip-bad-lines] [--max-scans N]   re-write as FLASER/ODOM (.gz ok)
//   mml-carmen trajectory LOG OUT [--reference CORRECTED_POSES | --reference-relations RELATIONS]
//                                                    "t x y theta" at every scan (raw odometry or reference)
//   mml-carmen eval RELATIONS TRAJECTORY [--tolerance S]           Kümmerle et al. 2009 metric, overall
//                                                    (first line, as before) and split by relation length
//                                                    (all / short ≤ 10 s / long > 10 s)
//   mml-carmen dataset NAME                          metric of raw odometry and reference (../shared/data)
//   --max-log-mib N   (any command reading a log) refuse logs larger than N MiB, plain or inflated
//                     (default 512: a gzip bomb is stopped there with a message, not inflated)
// Exit status 0 on success, 1 on bad input (message names the file and line), 2 on usage errors.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "sim/io/carmen_log.h"
#include "sim/io/datasets.h"
#include "sim/io/reference_trajectory.h"
#include "sim/io/relations.h"
#include "sim/common/cli_main.h"

namespace {

int usage() {
  std::fprintf(stderr,
               "usage: mml-carmen info LOG [--skip-bad-lines]\n"
               "       mml-carmen convert IN OUT [--skip-bad-lines] [--max-scans N]\n"
               "       mml-carmen trajectory LOG OUT [--reference CORRECTED_POSES | --reference-relations RELATIONS]\n"
               "       mml-carmen eval RELATIONS TRAJECTORY [--tolerance SECONDS]\n"
               "       mml-carmen dataset NAME   (intel, fr079, aces, fr-clinic, mit-killian)\n"
               "options for every command reading a log: --max-log-mib N (default 512)\n");
  return 2;
}

int fail(const std::string& msg) {
  std::fprintf(stderr, "mml-carmen: %s\n", msg.c_str());
  return 1;
}

struct Args {
  std::vector<std::string> pos;
  bool skip = false;
  size_t max_scans = 0;
  double tolerance = 1e-4;
  std::string reference;
  std::string reference_relations;
  std::uint64_t max_log_bytes = sim::kDefaultMaxLogBytes;
  bool ok = true;
};

Args parse_args(int argc, char** argv) {
  Args a;
  for (int i = 2; i < argc; ++i) {
    const std::string s = argv[i];
    auto value = [&](const char* name) -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "mml-carmen: %s needs a value\n", name);
        a.ok = false;
        return "";
      }
      return argv[++i];
    };
    if (s == "--skip-bad-lines") {
      a.skip = true;
    } else if (s == "--max-scans") {
      char* end = nullptr;
      const char* v = value("--max-scans");
      a.max_scans = std::strtoul(v, &end, 10);
      if (!a.ok || *v == 0 || *end != 0) a.ok = false;
    } else if (s == "--tolerance") {
      char* end = nullptr;
      const char* v = value("--tolerance");
      a.tolerance = std::strtod(v, &end);
      if (!a.ok || *v == 0 || *end != 0 || !(a.tolerance >= 0)) a.ok = false;
    } else if (s == "--max-log-mib") {
      char* end = nullptr;
      const char* v = value("--max-log-mib");
      const unsigned long long mib = std::strtoull(v, &end, 10);
      if (!a.ok || *v == 0 || *v == '-' || *end != 0 || mib == 0 || mib > (1ull << 20)) {
        std::fprintf(stderr, "mml-carmen: --max-log-mib '%s' is not a size in MiB (1 .. 1048576)\n", v);
        a.ok = false;
      } else {
        a.max_log_bytes = static_cast<std::uint64_t>(mib) << 20;
      }
    } else if (s == "--reference") {
      a.reference = value("--reference");
    } else if (s == "--reference-relations") {
      a.reference_relations = value("--reference-relations");
    } else if (s.size() > 1 && s[0] == '-') {
      std::fprintf(stderr, "mml-carmen: unknown option %s\n", s.c_str());
      a.ok = false;
    } else {
      a.pos.push_back(s);
    }
  }
  return a;
}

bool load(const std::string& path, const Args& a, sim::CarmenLog* log, std::string* err) {
  sim::CarmenReadOptions o;
  o.skip_bad_lines = a.skip;
  o.max_scans = a.max_scans;
  o.max_bytes = a.max_log_bytes;
  const bool ok = sim::read_carmen_log(path, o, log, err);
  if (ok && log->bad_lines > 0) {
    std::fprintf(stderr, "mml-carmen: %s: skipped %zu bad lines\n", path.c_str(), log->bad_lines);
    for (const auto& m : log->bad_line_messages) std::fprintf(stderr, "  %s\n", m.c_str());
    if (log->bad_line_messages.size() < log->bad_lines) std::fprintf(stderr, "  …\n");
  }
  return ok;
}

int cmd_info(const Args& a) {
  if (a.pos.size() != 1) return usage();
  sim::CarmenLog log;
  std::string err;
  const auto t0 = std::chrono::steady_clock::now();
  if (!load(a.pos[0], a, &log, &err)) return fail(err);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::map<std::string, size_t> types;
  std::map<size_t, size_t> beams;
  for (const auto& sc : log.scans) {
    ++types[sc.type];
    ++beams[sc.ranges.size()];
  }
  std::printf("%s: %zu lines read in %.3f s\n", log.path.c_str(), log.lines, s);
  for (const auto& [t, n] : types) std::printf("  %-12s %zu\n", t.c_str(), n);
  std::printf("  %-12s %zu\n  %-12s %zu\n  %-12s %zu\n  %-12s %zu\n  %-12s %zu\n  %-12s %zu\n", "ODOM", log.odom.size(),
              "PARAM", log.params.size(), "NEFF", log.neff_records, "#", log.comment_lines, "other", log.other_records,
              "bad lines", log.bad_lines);
  for (const auto& [n, c] : beams) std::printf("  beams %zu: %zu scans\n", n, c);
  if (!log.scans.empty()) {
    std::printf("  scans: ipc %.6f .. %.6f, logger %.6f .. %.6f, max_range %.2f m\n", log.scans.front().ipc_timestamp,
                log.scans.back().ipc_timestamp, log.scans.front().logger_timestamp, log.scans.back().logger_timestamp,
                log.scans.front().max_range);
  }
  return 0;
}

int cmd_convert(const Args& a) {
  if (a.pos.size() != 2) return usage();
  sim::CarmenLog log;
  std::string err;
  if (!load(a.pos[0], a, &log, &err)) return fail(err);
  if (!sim::write_carmen_log(a.pos[1], log, {}, &err)) return fail(err);
  std::printf("%s: %zu scans, %zu odometry records written\n", a.pos[1].c_str(), log.scans.size(), log.odom.size());
  return 0;
}

int cmd_trajectory(const Args& a) {
  if (a.pos.size() != 2) return usage();
  sim::CarmenLog log;
  std::string err;
  if (!load(a.pos[0], a, &log, &err)) return fail(err);
  sim::Trajectory traj;
  if (a.reference.empty() && a.reference_relations.empty()) {
    traj = sim::odometry_trajectory(log);
  } else {
    std::vector<sim::CorrectedPose> cp;
    if (!a.reference.empty()) {
      if (!sim::read_corrected_poses(a.reference, &cp, &err)) return fail(err);
    } else {
      std::vector<sim::Relation> rel;
      if (!sim::read_relations(a.reference_relations, &rel, &err)) return fail(err);
      if (!sim::corrected_poses_from_relations(log, rel, &cp, &err)) return fail(a.reference_relations + ": " + err);
    }
    const auto ref = sim::reference_at_every_scan(log, cp);
    if (ref.empty()) return fail(a.reference + ": no corrected pose indexes a scan of " + a.pos[0]);
    traj = sim::make_trajectory(log, ref);
  }
  if (!sim::write_trajectory(a.pos[1], traj, &err)) return fail(err);
  std::printf("%s: %zu poses\n", a.pos[1].c_str(), traj.size());
  return 0;
}

int cmd_eval(const Args& a) {
  if (a.pos.size() != 2) return usage();
  std::vector<sim::Relation> rel;
  sim::Trajectory traj;
  std::string err;
  if (!sim::read_relations(a.pos[0], &rel, &err)) return fail(err);
  if (!sim::read_trajectory(a.pos[1], &traj, &err)) return fail(err);
  // Overall, then split by relation length (≤ 10 s: single-alignment precision; > 10 s: drift).
  const sim::RelationsMetricSplit ms = sim::evaluate_relations_split(rel, traj, 10.0, a.tolerance);
  const sim::RelationsMetric& m = ms.all;
  std::printf("%s\n%s\n", sim::to_string(m).c_str(), sim::to_string(ms).c_str());
  return m.used > 0 ? 0 : fail("no relation could be evaluated (timestamps not in the trajectory)");
}

int cmd_dataset(const Args& a) {
  if (a.pos.size() != 1) return usage();
  const sim::Dataset* d = sim::find_dataset(a.pos[0]);
  if (!d || d->raw_log.empty()) return fail("unknown dataset or no raw log: " + a.pos[0]);
  sim::CarmenLog log;
  std::string err;
  if (!load(sim::data_path(d->raw_log), a, &log, &err)) return fail(err);
  std::printf("%s: %zu scans (expected %zu)\n", d->name.c_str(), log.scans.size(), d->expected_scans);
  std::vector<sim::Relation> rel;
  if (!d->relations.empty() && d->relations_match_log) {
    if (!sim::read_relations(sim::data_path(d->relations), &rel, &err)) return fail(err);
    std::printf("raw odometry: %s\n", sim::to_string(sim::evaluate_relations(rel, sim::odometry_trajectory(log))).c_str());
  }
  if (!d->corrected_poses.empty() || !rel.empty()) {
    std::vector<sim::CorrectedPose> cp;
    if (!d->corrected_poses.empty()) {
      if (!sim::read_corrected_poses(sim::data_path(d->corrected_poses), &cp, &err)) return fail(err);
    } else {
      std::printf("(no corrected log: reference poses from the relations' spanning tree)\n");
      if (!sim::corrected_poses_from_relations(log, rel, &cp, &err)) return fail(err);
    }
    const auto g = sim::reference_gap_stats(log, cp);
    std::printf("reference: %zu corrected poses, gaps mean %.1f max %.0f scans, closure residual mean %.3f m max %.3f m\n",
                cp.size(), g.mean_gap_scans, g.max_gap_scans, g.mean_closure_m, g.max_closure_m);
    if (!rel.empty()) {
      const auto traj = sim::make_trajectory(log, sim::reference_at_every_scan(log, cp));
      std::printf("reference:    %s\n", sim::to_string(sim::evaluate_relations(rel, traj)).c_str());
    }
  }
  return 0;
}

}  // namespace

static int run_main(int argc, char** argv) {
  if (argc < 2) return usage();
  const std::string cmd = argv[1];
  const Args a = parse_args(argc, argv);
  if (!a.ok) return usage();
  if (cmd == "info") return cmd_info(a);
  if (cmd == "convert") return cmd_convert(a);
  if (cmd == "trajectory") return cmd_trajectory(a);
  if (cmd == "eval") return cmd_eval(a);
  if (cmd == "dataset") return cmd_dataset(a);
  return usage();
}

int main(int argc, char** argv) {
  return sim::guarded_main("mml-carmen", [&] { return run_main(argc, argv); });
}
