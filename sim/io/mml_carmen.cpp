// mml-carmen: command-line access to the sim/io readers and writers.
//   mml-carmen info LOG [--skip-bad-lines]            record counts, time span, bad lines
//   mml-carmen convert IN OUT [--skip-bad-lines] [--max-scans N]   re-write as FLASER/ODOM (.gz ok)
//   mml-carmen trajectory LOG OUT [--reference CORRECTED_POSES | --reference-relations RELATIONS]
//                                                    "t x y theta" at every scan (raw odometry or reference)
//   mml-carmen eval RELATIONS TRAJECTORY [--tolerance S]           Kümmerle et al. 2009 metric, overall
//                                                    (first line, as before) and split by relation length
//                                                    (all / short ≤ 10 s / long > 10 s)
//   mml-carmen dataset NAME                          metric of raw odometry and reference (../shared/data)
//   mml-carmen reference RAW CORRECTED OUT [--every-scan]   ground truth for the raw log's scans from a
//                                                    corrected log (the --reference file of mml-eval/mml-sim)
//   mml-carmen synth-odom CORRECTED OUT [--seed S]   a log with odometry synthesised from the corrected
//                                                    poses (sim/io/synthetic_odometry.h), for logs without
//   mml-carmen --help | COMMAND --help               raw odometry
//   --max-log-mib N   (any command reading a log) refuse logs larger than N MiB, plain or inflated
//                     (default 512: a gzip bomb is stopped there with a message, not inflated)
// Exit status 0 on success, 1 on bad input (message names the file and line), 2 on usage errors.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <unordered_map>
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
#include "sim/io/synthetic_odometry.h"
#include "sim/common/cli_main.h"

namespace {

const char kUsage[] =
    "usage: mml-carmen info LOG [--skip-bad-lines]\n"
    "       mml-carmen convert IN OUT [--skip-bad-lines] [--max-scans N]\n"
    "       mml-carmen trajectory LOG OUT [--reference CORRECTED_POSES | --reference-relations RELATIONS]\n"
    "       mml-carmen eval RELATIONS TRAJECTORY [--tolerance SECONDS]\n"
    "       mml-carmen dataset NAME   (intel, fr079, aces, fr-clinic, mit-killian)\n"
    "       mml-carmen reference RAW CORRECTED OUT [--every-scan]\n"
    "       mml-carmen synth-odom CORRECTED OUT [--seed S]\n"
    "       mml-carmen --help | COMMAND --help\n"
    "options for every command reading a log: --max-log-mib N (default 512)\n";

const char kReferenceHelp[] =
    "usage: mml-carmen reference RAW CORRECTED OUT [--every-scan]\n"
    "Ground truth for the scans of a raw log (laser + odometry) from a corrected log of the same run\n"
    "(e.g. GMapping's output): every scan of CORRECTED is associated, in order, with the\n"
    "scan of RAW whose range readings are identical (to 1 mm). OUT gets one row per associated scan,\n"
    "  flaser_index ipc_timestamp logger_timestamp x y theta\n"
    "(flaser_index: 0-based scan index in RAW; timestamps from RAW; pose from CORRECTED), the format of\n"
    "../shared/data/*/*.corrected-poses.txt. mml-eval --reference and mml-sim --reference read it and\n"
    "chain RAW's odometry between the rows to every scan (sim/io/reference_trajectory.h).\n"
    "  --every-scan   write that chained pose for every scan of RAW instead (one row per scan)\n"
    "Fails (exit 1) when no scan can be associated.\n";

const char kSynthHelp[] =
    "usage: mml-carmen synth-odom CORRECTED OUT [--seed S]\n"
    "For a log that has corrected poses only (no raw odometry): writes OUT, the same scans with wheel\n"
    "odometry synthesised from the corrected poses (FLASER pose and odometry triples; ODOM and NEFF\n"
    "records dropped). Noise model (sim/io/synthetic_odometry.h, as mml-eval --synthetic-odometry and\n"
    "the built-in fr101 / fr-campus runs): per scan step the corrected increment (Δs m, Δθ rad) gets\n"
    "Gaussian noise σ_t = 0.05·Δs + 0.01·|Δθ| m on x and y and σ_r = 0.05·|Δθ| + 0.01·Δs rad on θ;\n"
    "odometry starts at the first corrected pose; deterministic per --seed (default 1).\n"
    "Ground truth for OUT: 'mml-carmen reference OUT CORRECTED REF.txt' (every scan associates).\n";

int usage() {
  std::fputs(kUsage, stderr);
  return 2;
}

int usage_error(const std::string& msg) {
  std::fprintf(stderr, "mml-carmen: %s\n", msg.c_str());
  return usage();
}

int wrong_count(const char* cmd, const char* expected, size_t got) {
  return usage_error(std::string(cmd) + " needs " + expected + " (got " + std::to_string(got) + " file arguments)");
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
  std::uint64_t seed = 1;
  bool seed_given = false;
  bool every_scan = false;
  bool help = false;
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
    if (s == "--help" || s == "-h") {
      a.help = true;
    } else if (s == "--skip-bad-lines") {
      a.skip = true;
    } else if (s == "--every-scan") {
      a.every_scan = true;
    } else if (s == "--max-scans") {
      char* end = nullptr;
      const char* v = value("--max-scans");
      a.max_scans = std::strtoul(v, &end, 10);
      if (a.ok && (*v == 0 || *v == '-' || *end != 0)) {
        std::fprintf(stderr, "mml-carmen: --max-scans '%s' is not a non-negative integer\n", v);
        a.ok = false;
      }
    } else if (s == "--tolerance") {
      char* end = nullptr;
      const char* v = value("--tolerance");
      a.tolerance = std::strtod(v, &end);
      if (a.ok && (*v == 0 || *end != 0 || !(a.tolerance >= 0))) {
        std::fprintf(stderr, "mml-carmen: --tolerance '%s' is not a number of seconds >= 0\n", v);
        a.ok = false;
      }
    } else if (s == "--seed") {
      char* end = nullptr;
      const char* v = value("--seed");
      a.seed = std::strtoull(v, &end, 10);
      a.seed_given = true;
      if (a.ok && (*v == 0 || *v == '-' || *end != 0)) {
        std::fprintf(stderr, "mml-carmen: --seed '%s' is not a non-negative integer\n", v);
        a.ok = false;
      }
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
  if (a.pos.size() != 1) return wrong_count("info", "LOG", a.pos.size());
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
  if (a.pos.size() != 2) return wrong_count("convert", "IN OUT", a.pos.size());
  sim::CarmenLog log;
  std::string err;
  if (!load(a.pos[0], a, &log, &err)) return fail(err);
  if (!sim::write_carmen_log(a.pos[1], log, {}, &err)) return fail(err);
  std::printf("%s: %zu scans, %zu odometry records written\n", a.pos[1].c_str(), log.scans.size(), log.odom.size());
  return 0;
}

int cmd_trajectory(const Args& a) {
  if (a.pos.size() != 2) return wrong_count("trajectory", "LOG OUT", a.pos.size());
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
  if (a.pos.size() != 2) return wrong_count("eval", "RELATIONS TRAJECTORY", a.pos.size());
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
  if (a.pos.size() != 1) return wrong_count("dataset", "NAME", a.pos.size());
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

// Ranges quantised to 1 mm: scans of the raw and the corrected log are the same scan when these agree.
std::vector<long long> range_key(const sim::CarmenScan& s) {
  std::vector<long long> k;
  k.reserve(s.ranges.size());
  for (float r : s.ranges) k.push_back(std::llround(static_cast<double>(r) * 1000.0));
  return k;
}

struct KeyHash {
  size_t operator()(const std::vector<long long>& k) const {
    size_t h = k.size();
    for (long long v : k) h = h * 1000003u ^ static_cast<size_t>(v);
    return h;
  }
};

int cmd_reference(const Args& a) {
  if (a.help) return std::fputs(kReferenceHelp, stdout), 0;
  if (a.pos.size() != 3) {
    return usage_error("reference needs RAW CORRECTED OUT (got " + std::to_string(a.pos.size()) +
                       " arguments; see mml-carmen reference --help)");
  }
  sim::CarmenLog raw, cor;
  std::string err;
  if (!load(a.pos[0], a, &raw, &err)) return fail(err);
  if (!load(a.pos[1], a, &cor, &err)) return fail(err);
  if (raw.scans.empty()) return fail(a.pos[0] + ": no laser scans in the raw log");
  if (cor.scans.empty()) return fail(a.pos[1] + ": no laser scans in the corrected log");
  // Raw scans by their readings (several when the robot stood still), in index order.
  std::unordered_map<std::vector<long long>, std::vector<size_t>, KeyHash> by_key;
  for (size_t i = 0; i < raw.scans.size(); ++i) by_key[range_key(raw.scans[i])].push_back(i);
  std::vector<sim::CorrectedPose> cp;
  size_t next = 0, unmatched = 0;
  for (const sim::CarmenScan& c : cor.scans) {
    auto it = by_key.find(range_key(c));
    if (it == by_key.end()) {
      ++unmatched;
      continue;
    }
    auto j = std::lower_bound(it->second.begin(), it->second.end(), next);
    if (j == it->second.end()) {
      ++unmatched;
      continue;
    }
    const sim::CarmenScan& r = raw.scans[*j];
    sim::CorrectedPose p;
    p.flaser_index = r.index;
    p.ipc_timestamp = r.ipc_timestamp;
    p.logger_timestamp = r.logger_timestamp;
    p.pose = c.pose;
    cp.push_back(p);
    next = *j + 1;
  }
  if (cp.empty()) {
    return fail(a.pos[1] + ": none of its " + std::to_string(cor.scans.size()) + " scans has the range readings of a scan of " +
                a.pos[0] + " (not a corrected log of this raw log?)");
  }
  std::FILE* f = std::fopen(a.pos[2].c_str(), "w");
  if (f == nullptr) return fail(a.pos[2] + ": cannot write: " + std::strerror(errno));
  std::fprintf(f, "# ground truth for %s from %s (mml-carmen reference%s)\n", a.pos[0].c_str(), a.pos[1].c_str(),
               a.every_scan ? " --every-scan: corrected poses chained with odometry to every scan" : "");
  std::fprintf(f, "# columns: flaser_index ipc_timestamp logger_timestamp x y theta\n");
  size_t rows = 0;
  if (a.every_scan) {
    const std::vector<fw::Se2d> all = sim::reference_at_every_scan(raw, cp);
    for (size_t i = 0; i < all.size(); ++i, ++rows) {
      const sim::CarmenScan& r = raw.scans[i];
      std::fprintf(f, "%zu %.6f %.6f %.6f %.6f %.6f\n", r.index, r.ipc_timestamp, r.logger_timestamp, all[i].x, all[i].y,
                   all[i].theta);
    }
  } else {
    for (const sim::CorrectedPose& p : cp) {
      std::fprintf(f, "%zu %.6f %.6f %.6f %.6f %.6f\n", p.flaser_index, p.ipc_timestamp, p.logger_timestamp, p.pose.x,
                   p.pose.y, p.pose.theta);
      ++rows;
    }
  }
  if (std::fclose(f) != 0) return fail(a.pos[2] + ": write error");
  std::printf("%s: %zu rows; %zu of %zu corrected scans associated with scans of %s (%zu raw scans)%s\n", a.pos[2].c_str(),
              rows, cp.size(), cor.scans.size(), a.pos[0].c_str(), raw.scans.size(),
              unmatched > 0 ? "; the others have no scan with identical readings" : "");
  if (unmatched > 0) {
    std::fprintf(stderr, "mml-carmen: warning: %zu of %zu scans of %s were not found in %s\n", unmatched,
                 cor.scans.size(), a.pos[1].c_str(), a.pos[0].c_str());
  }
  return 0;
}

int cmd_synth_odom(const Args& a) {
  if (a.help) return std::fputs(kSynthHelp, stdout), 0;
  if (a.pos.size() != 2) {
    return usage_error("synth-odom needs CORRECTED OUT (got " + std::to_string(a.pos.size()) +
                       " arguments; see mml-carmen synth-odom --help)");
  }
  sim::CarmenLog log;
  std::string err;
  if (!load(a.pos[0], a, &log, &err)) return fail(err);
  if (log.scans.size() < 2) return fail(a.pos[0] + ": needs at least 2 laser scans");
  std::vector<fw::Se2d> ref;
  for (const sim::CarmenScan& s : log.scans) ref.push_back(s.pose);
  const std::vector<fw::Se2d> odo = sim::synthesize_odometry(ref, a.seed);
  double drift = 0;
  for (size_t i = 0; i < log.scans.size(); ++i) {
    sim::CarmenScan& s = log.scans[i];
    const fw::Se2d mount = s.pose.between(s.odom);  // robot pose relative to the laser pose (often 0)
    s.pose = odo[i];
    s.odom = odo[i].compose(mount);
    drift = std::max(drift, std::hypot(odo[i].x - ref[i].x, odo[i].y - ref[i].y));
  }
  log.odom.clear();
  if (!sim::write_carmen_log(a.pos[1], log, {}, &err)) return fail(err);
  std::printf("%s: %zu scans with synthesised odometry (seed %llu; drift from the corrected poses up to %.2f m)\n",
              a.pos[1].c_str(), log.scans.size(), static_cast<unsigned long long>(a.seed), drift);
  return 0;
}

}  // namespace

static int run_main(int argc, char** argv) {
  if (argc < 2) return usage_error("no command given");
  const std::string cmd = argv[1];
  if (cmd == "--help" || cmd == "-h" || cmd == "help") return std::fputs(kUsage, stdout), 0;
  const Args a = parse_args(argc, argv);
  if (!a.ok) return usage();
  if (a.seed_given && cmd != "synth-odom") return usage_error("--seed is an option of synth-odom only");
  if (a.every_scan && cmd != "reference") return usage_error("--every-scan is an option of reference only");
  if (cmd == "reference") return cmd_reference(a);
  if (cmd == "synth-odom") return cmd_synth_odom(a);
  if (a.help) return std::fputs(kUsage, stdout), 0;
  if (cmd == "info") return cmd_info(a);
  if (cmd == "convert") return cmd_convert(a);
  if (cmd == "trajectory") return cmd_trajectory(a);
  if (cmd == "eval") return cmd_eval(a);
  if (cmd == "dataset") return cmd_dataset(a);
  return usage_error("unknown command '" + cmd + "'");
}

int main(int argc, char** argv) {
  return sim::guarded_main("mml-carmen", [&] { return run_main(argc, argv); });
}
