#include "sim/cli/corpus/corpus_runner.h"

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "hal/msg/pose_estimate.h"
#include "sim/cli/corpus/corpus_figures.h"
#include "sim/world/odometry_profiles.h"
#include "sim/world/sensor_profiles.h"

namespace sim::corpus {

namespace {

CorpusRunOptions options_for(const CorpusOptions& opt, std::size_t k) {
  CorpusRunOptions ro = opt.run;
  ro.timing = opt.timing;
  ro.picture_dir = k < opt.first_draw + opt.pictures ? opt.out_dir + "/draw_" + std::to_string(k) : "";
  if (!ro.picture_dir.empty()) std::filesystem::create_directories(ro.picture_dir);
  return ro;
}

bool write_file(const std::string& path, const std::string& bytes) {
  const std::string tmp = path + ".tmp";
  std::ofstream f(tmp, std::ios::binary);
  f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  f.close();
  return f && std::rename(tmp.c_str(), path.c_str()) == 0;
}

bool read_file(const std::string& path, std::string* bytes) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return false;
  std::ostringstream s;
  s << f.rdbuf();
  *bytes = s.str();
  return true;
}

class Progress {
 public:
  Progress(bool on, std::size_t total) : on_(on), total_(total), t0_(std::chrono::steady_clock::now()) {}
  void done(const CorpusRun& r, std::size_t finished) {
    if (r.ok) {
      for (const CorpusStep& s : r.steps) {
        if (s.status == static_cast<std::uint8_t>(hal::LocalizationStatus::kLocalized)) {
          ++localized_;
          if (s.err_m > kAlertM || s.err_deg > kAlertDeg) ++wrong_;
        }
      }
    } else {
      ++failed_;
    }
    if (!on_) return;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
    const double eta = finished > 0 ? s / finished * (total_ - finished) : 0;
    std::fprintf(stderr, "%scorpus: %zu/%zu runs, %.0f s (eta %.0f s), %zu localized steps, %zu wrong, %zu failed runs%s",
                 tty_ ? "\r\033[K" : "", finished, total_, s, eta, localized_, wrong_, failed_, tty_ ? "" : "\n");
    if (tty_ && finished == total_) std::fprintf(stderr, "\n");
  }

 private:
  bool on_;
  std::size_t total_, localized_ = 0, wrong_ = 0, failed_ = 0;
  std::chrono::steady_clock::time_point t0_;
  const bool tty_ = isatty(fileno(stderr)) != 0;
};

// Runs every draw in child processes, `jobs` at once; each child writes its run to a file that the
// parent reads back by index. A child that dies leaves a failed run that says so.
void run_in_children(const CorpusOptions& opt, const std::vector<CorpusDraw>& draws, std::vector<CorpusRun>* runs) {
  const std::string dir = opt.out_dir + "/runs";
  std::filesystem::create_directories(dir);
  const auto path_of = [&](std::size_t k) { return dir + "/run_" + std::to_string(k) + ".bin"; };
  std::map<pid_t, std::size_t> active;
  std::size_t next = 0, finished = 0;
  Progress progress(opt.progress, draws.size());
  const auto collect = [&](pid_t pid, int status) {
    const std::size_t k = active.at(pid);
    active.erase(pid);
    CorpusRun& r = (*runs)[k];
    std::string bytes, err;
    r.draw = draws[k];
    if (!read_file(path_of(k), &bytes) || !deserialize_run(bytes, &r, &err)) {
      r.ok = false;
      r.error = WIFSIGNALED(status) ? "run process killed by signal " + std::to_string(WTERMSIG(status))
                                    : "run process left no result (exit " + std::to_string(WEXITSTATUS(status)) + ")";
    }
    std::filesystem::remove(path_of(k));
    progress.done(r, ++finished);
  };
  while (next < draws.size() || !active.empty()) {
    if (next < draws.size() && active.size() < static_cast<std::size_t>(opt.jobs)) {
      const std::size_t k = next++;
      std::filesystem::remove(path_of(k));
      std::fflush(nullptr);
      const pid_t pid = fork();
      if (pid == 0) {
        const CorpusRun r = run_draw(draws[k], options_for(opt, draws[k].index));
        _exit(write_file(path_of(k), serialize_run(r)) ? 0 : 3);
      }
      if (pid > 0) {
        active[pid] = k;
        continue;
      }
      (*runs)[k].draw = draws[k];
      (*runs)[k].error = "fork failed";
      progress.done((*runs)[k], ++finished);
      continue;
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid > 0 && active.count(pid) > 0) collect(pid, status);
  }
}

void write_runs_csv(const std::string& path, const std::vector<CorpusRun>& runs) {
  std::ofstream f(path);
  f << "index,family,sensor,odometry,width_m,height_m,clutter_items,doors_flipped,furniture_moved,distorted,kidnap,"
       "via_unknown,people,ok,steps,fixed,metres_to_fix,availability,longest_gap_m,localized,wrong,pl_exceed_xy,"
       "pl_exceed_theta,error\n";
  for (const CorpusRun& r : runs) {
    const RunFigures rf = run_figures(r);
    std::size_t loc = 0, wrong = 0, exy = 0, eth = 0;
    for (const CorpusStep& s : r.steps) {
      if (s.status != static_cast<std::uint8_t>(hal::LocalizationStatus::kLocalized) || !s.has_pose) continue;
      ++loc;
      wrong += s.err_m > kAlertM || s.err_deg > kAlertDeg;
      exy += s.pl_xy_m > 0 && s.err_m > s.pl_xy_m;
      eth += s.pl_xy_m > 0 && s.err_deg > s.pl_theta_deg;
    }
    const CorpusDraw& d = r.draw;
    f << d.index << ',' << building_family_name(d.building.family) << ',' << d.sensor << ',' << d.odometry << ','
      << r.width_m << ',' << r.height_m << ',' << r.changes.clutter_items << ',' << r.changes.doors_flipped << ','
      << r.changes.furniture_moved << ',' << r.changes.distorted << ',' << (d.kidnap_at_scan > 0) << ','
      << d.via_unknown << ',' << d.people << ',' << r.ok << ',' << r.steps.size() << ',' << rf.fixed << ','
      << rf.metres_to_fix << ',' << (rf.judged ? static_cast<double>(rf.judged_localized) / rf.judged : 0) << ','
      << rf.longest_gap_m << ',' << loc << ',' << wrong << ',' << exy << ',' << eth << ",\""
      << r.error << "\"\n";
  }
}

// Groups: per family, per sensor profile, per odometry profile, the distorted maps on their own.
std::vector<std::pair<std::string, std::vector<const CorpusRun*>>> groups_of(const std::vector<CorpusRun>& runs) {
  std::vector<std::pair<std::string, std::vector<const CorpusRun*>>> g;
  const auto add = [&](const std::string& key, const CorpusRun& r) {
    for (auto& e : g) {
      if (e.first == key) {
        e.second.push_back(&r);
        return;
      }
    }
    g.push_back({key, {&r}});
  };
  for (int f = 0; f < kBuildingFamilyCount; ++f) {
    for (const CorpusRun& r : runs) {
      if (static_cast<int>(r.draw.building.family) == f) add(std::string("FAMILY_") + building_family_name(r.draw.building.family), r);
    }
  }
  for (const SensorProfile& p : sensor_profiles()) {
    for (const CorpusRun& r : runs) if (r.draw.sensor == p.name) add("SENSOR_" + p.name, r);
  }
  for (const OdometryProfile& p : odometry_profiles()) {
    for (const CorpusRun& r : runs) if (r.draw.odometry == p.name) add("ODOM_" + p.name, r);
  }
  for (const CorpusRun& r : runs) {
    add(r.changes.distorted ? "MAP_distorted" : "MAP_undistorted", r);
    add(r.draw.changes.clean() && r.draw.people == 0 ? "MAP_clean" : "MAP_changed", r);
  }
  return g;
}

void write_table(const std::string& path, const CorpusOptions& opt,
                 const std::vector<std::pair<std::string, CorpusFigures>>& rows) {
  std::ofstream f(path);
  f << "# Corpus seed " << opt.seed << ", " << opt.runs << " runs\n\n"
    << "| group | runs | fixed | localized steps | wrong | PL exceed xy (ucb95) | PL exceed θ (ucb95) | availability "
       "median | withheld while right | longest gap p99 (m) | error p50 / p95 (m) |\n"
    << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  char buf[512];
  for (const auto& [name, x] : rows) {
    std::snprintf(buf, sizeof(buf),
                  "| %s | %zu | %zu | %zu | %zu | %.4f (%.4f) | %.4f (%.4f) | %.3f | %.3f | %.1f | %.3f / %.3f |\n",
                  name.c_str(), x.runs, x.runs_fixed, x.localized_steps, x.integrity_failures, x.pl_exceed_xy_rate,
                  x.pl_exceed_xy_ucb95, x.pl_exceed_theta_rate, x.pl_exceed_theta_ucb95, x.availability_median,
                  x.withheld_while_right_rate, x.longest_gap_m_p99, x.track_err_m_p50, x.track_err_m_p95);
    f << buf;
  }
  // The wait for MML's word is most of the silence: what each wait was charged to.
  for (const auto& [name, x] : rows) {
    if (x.awaiting_by_cause.empty()) continue;
    f << "\nWithheld while right awaiting MML, " << name << ", by cause:";
    for (const auto& [cause, count] : x.awaiting_by_cause) f << " " << cause << " " << count << ";";
    f << "\n";
  }
}

}  // namespace

bool run_corpus(const CorpusOptions& opt, BenchJson* json, std::vector<CorpusRun>* runs_out, std::string* err) {
  std::error_code ec;
  std::filesystem::create_directories(opt.out_dir, ec);
  if (ec || !std::filesystem::is_directory(opt.out_dir)) {
    *err = "cannot create output directory '" + opt.out_dir + "'";
    return false;
  }
  if (opt.jobs < 1 || opt.jobs > 64) {
    *err = "jobs must be in [1, 64]";
    return false;
  }
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<CorpusDraw> draws = draw_corpus(opt.seed, opt.first_draw + opt.runs, opt.draws);
  draws.erase(draws.begin(), draws.begin() + static_cast<std::ptrdiff_t>(opt.first_draw));
  std::vector<CorpusRun> runs(draws.size());
  if (opt.jobs == 1) {
    Progress progress(opt.progress, draws.size());
    for (std::size_t k = 0; k < draws.size(); ++k) {
      runs[k] = run_draw(draws[k], options_for(opt, draws[k].index));
      progress.done(runs[k], k + 1);
    }
  } else {
    run_in_children(opt, draws, &runs);
  }
  std::vector<const CorpusRun*> all;
  for (const CorpusRun& r : runs) all.push_back(&r);
  json->add_int("corpus_seed", static_cast<long long>(opt.seed));
  std::string given;
  for (const auto& [key, value] : opt.run.localizer_options) given += (given.empty() ? "" : ",") + key + "=" + value;
  json->add_string("corpus_localizer_options", given);
  json->add_int("corpus_families", kBuildingFamilyCount);
  json->add_int("corpus_sensor_profiles", static_cast<long long>(sensor_profiles().size()));
  json->add_int("corpus_odometry_profiles", static_cast<long long>(odometry_profiles().size()));
  std::vector<std::pair<std::string, CorpusFigures>> rows;
  rows.push_back({"corpus", corpus_figures(all)});
  add_figures("corpus_", rows.back().second, opt.timing, json);
  for (const auto& [name, members] : groups_of(runs)) {
    rows.push_back({name, corpus_figures(members)});
    add_figures(name + "_", rows.back().second, opt.timing, json);
  }
  if (opt.timing) json->add("corpus_seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  write_runs_csv(opt.out_dir + "/runs.csv", runs);
  write_table(opt.out_dir + "/corpus.md", opt, rows);
  if (runs_out != nullptr) *runs_out = std::move(runs);
  return true;
}

}  // namespace sim::corpus
