// bench_faults: the fault campaign of issue 13 in build/bench/faults.json. Runs
//  - fault_campaign.sh (the real mmlfw: serial laser over socat ptys, start-up and map-file cases on
//    the host; CAN cases inside user-mode Linux scored against the reference trajectory), and
//  - the scan-content cases (NaN / inf / zero-reading scans) in the simulator: the firmware stack as
//    mmlfw builds it (replay_budget.h, lockstep, mml-track on aces) with the scans corrupted on the way;
//    each in a child process, so a crash or a hang is observed and counted, not fatal to the bench;
// then reads the ASan and TSan stage results of scripts/test.sh (build/test-stages/*.json; true only
// when that stage ran and passed) and the soak figures (build/bench/soak.json, scripts/bench.sh soak).
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "sim/common/bench_json.h"
#include "sim/common/flat_json_read.h"
#include "tests/faults/flat_json_merge.h"
#include "tests/hil/replay_budget.h"

namespace {

struct CaseResult {
  std::string name, channel, expect, detail;
  bool passed = false, crash = false, hang = false;
  long wrong_localized = 0;
};

// One scan-content case: scans [from, to) of the log have every reading replaced by `value`.
CaseResult scan_content_case(const std::string& name, float value, const char* what) {
  constexpr size_t kFrom = 120, kTo = 135, kScans = 260;
  CaseResult c;
  c.name = name;
  c.channel = "sim";
  c.expect = std::string("15 scans with ") + what + ": no crash, no wrong localized, every scan accounted, "
             "localized again after them without restart";
  int fd[2];
  if (pipe(fd) != 0) { c.detail = "pipe failed"; return c; }
  const pid_t pid = fork();
  if (pid == 0) {
    close(fd[0]);
    mmlfw_hil::ReplayOptions o;
    o.num_scans = kScans;
    o.rate_hz = 0;  // lockstep: deterministic
    o.mutate_scan = [value](size_t index, hal::LaserScan* s) {
      if (index < kFrom || index >= kTo) return;
      for (std::uint32_t i = 0; i < s->beam_count; ++i) s->ranges[i] = value;
    };
    mmlfw_hil::ReplayResult r;
    std::string err;
    const bool ok = mmlfw_hil::run_replay(o, &r, &err);
    char line[512];
    const int n = std::snprintf(line, sizeof line, "%d %zu %zu %zu %zu %zu %zu %ld %ld %zu\n", ok ? 1 : 0, r.scans_fed,
                                r.scans_processed, r.health_dropped, r.ring_overflows, r.wrong_localized, r.localized,
                                r.first_localized_scan, r.last_localized_scan, r.pending_at_end);
    if (write(fd[1], line, static_cast<size_t>(n)) != n) _exit(3);
    if (!ok) std::fprintf(stderr, "bench_faults: %s: %s\n", name.c_str(), err.c_str());
    _exit(ok ? 0 : 2);
  }
  close(fd[1]);
  std::string out;
  char buf[512];
  pollfd p{fd[0], POLLIN, 0};
  const int kTimeoutMs = 600'000;  // a lockstep run of 260 scans takes seconds; 10 min is a hang
  for (int waited = 0; waited < kTimeoutMs;) {
    const int pr = poll(&p, 1, 1000);
    if (pr > 0) {
      const ssize_t k = read(fd[0], buf, sizeof buf);
      if (k <= 0) break;
      out.append(buf, static_cast<size_t>(k));
    } else {
      waited += 1000;
    }
  }
  close(fd[0]);
  // The pipe closes when the child exits (or the poll above gave up): give it 10 s to be reaped
  // (checking at once raced with a child still exiting and called that a hang).
  int status = 0;
  pid_t w = 0;
  for (int i = 0; i < 100 && (w = waitpid(pid, &status, WNOHANG)) == 0; ++i) usleep(100'000);
  if (w == 0) {
    c.hang = true;
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
  }
  c.crash = WIFSIGNALED(status) && !c.hang;
  int ok = 0;
  size_t fed = 0, processed = 0, dropped = 0, ring = 0, wrong = 0, localized = 0, pending = 0;
  long first = -1, last = -1;
  if (std::sscanf(out.c_str(), "%d %zu %zu %zu %zu %zu %zu %ld %ld %zu", &ok, &fed, &processed, &dropped, &ring, &wrong,
                  &localized, &first, &last, &pending) != 10) {
    ok = 0;
  }
  c.wrong_localized = static_cast<long>(wrong);
  const bool accounted = processed + dropped + pending == fed;  // HEALTH dropped includes ring overflows
  c.passed = ok && !c.crash && !c.hang && wrong == 0 && accounted && first >= 0 && first < static_cast<long>(kFrom) &&
             last >= static_cast<long>(kTo);
  char d[512];
  std::snprintf(d, sizeof d,
                "exit %s, fed %zu = processed %zu + HEALTH dropped %zu (ring overflows %zu) + pending %zu, localized %zu "
                "(first %ld, last %ld), wrong %zu",
                c.crash ? "by signal" : (c.hang ? "hang" : (ok ? "0" : "error")), fed, processed, dropped, ring, pending,
                localized, first, last, wrong);
  c.detail = d;
  std::printf("bench_faults: %s %s [sim]: %s\n", c.passed ? "PASS" : "FAIL", name.c_str(), d);
  std::fflush(stdout);
  return c;
}

std::vector<CaseResult> read_cases(const std::string& path) {
  std::vector<CaseResult> v;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    CaseResult c;
    std::string s;
    if (sim::json_value(line, "case", &s)) c.name = s;
    c.passed = sim::json_value(line, "passed", &s) && s == "true";
    c.crash = sim::json_value(line, "crash", &s) && s == "true";
    c.hang = sim::json_value(line, "hang", &s) && s == "true";
    if (sim::json_value(line, "wrong_localized", &s)) c.wrong_localized = std::strtol(s.c_str(), nullptr, 10);
    v.push_back(c);
  }
  return v;
}

// True only when scripts/test.sh ran the stage and it passed (build/test-stages/NAME.json).
bool stage_passed(const std::string& root, const std::string& stage, std::string* commit) {
  const std::string t = sim::read_all(root + "/build/test-stages/" + stage + ".json");
  std::string v;
  if (sim::json_value(t, "commit", commit)) {
    if (commit->size() > 2 && commit->front() == '"') *commit = commit->substr(1, commit->size() - 2);
  }
  return sim::json_value(t, "passed", &v) && v == "true";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_faults OUT.json\n");
    return 2;
  }
  const std::string exe = argv[0];
  const size_t slash = exe.find_last_of('/');
  const std::string build = (slash == std::string::npos ? std::string(".") : exe.substr(0, slash)) + "/..";
  const std::string src = MMLFW_SOURCE_DIR;
  const std::string out_dir = build + "/faults";

  std::printf("bench_faults: fault campaign against mmlfw (host + user-mode Linux) ...\n");
  std::fflush(stdout);
  const int rc = std::system(("bash " + src + "/tests/faults/fault_campaign.sh " + build + " " + out_dir + " 2>&1 | tee " +
                              build + "/faults.log").c_str());
  (void)rc;
  std::vector<CaseResult> cases = read_cases(out_dir + "/cases.jsonl");
  std::printf("bench_faults: scan-content cases in the simulator ...\n");
  std::fflush(stdout);
  cases.push_back(scan_content_case("sim_nan_scans", std::numeric_limits<float>::quiet_NaN(), "NaN readings"));
  cases.push_back(scan_content_case("sim_inf_scans", std::numeric_limits<float>::infinity(), "+inf readings"));
  cases.push_back(scan_content_case("sim_zero_scans", 0.0f, "zero readings"));

  sim::BenchJson j;
  long passed = 0, crashes = 0, hangs = 0, wrong = 0;
  for (const CaseResult& c : cases) {
    passed += c.passed;
    crashes += c.crash;
    hangs += c.hang;
    wrong += c.wrong_localized;
  }
  j.add_int("fault_cases", static_cast<long long>(cases.size()));
  j.add_int("fault_cases_passed", passed);
  j.add_int("fault_wrong_localized", wrong);
  j.add_int("fault_crashes", crashes);
  j.add_int("fault_hangs", hangs);
  std::string failed;
  for (const CaseResult& c : cases) {
    if (!c.passed) failed += (failed.empty() ? "" : " ") + c.name;
  }
  j.add_string("fault_cases_failed", failed);
  std::string asan_commit, tsan_commit;
  j.add_bool("asan_tests_passed", stage_passed(src, "asan", &asan_commit));
  j.add_string("asan_tests_commit", asan_commit);
  j.add_bool("tsan_tests_passed", stage_passed(src, "tsan", &tsan_commit));
  j.add_string("tsan_tests_commit", tsan_commit);
  if (!j.write(argv[1])) return 1;
  // The soak's figures (scripts/bench.sh soak) belong in the same file.
  auto kv = mmlfw_faults::read_flat_json(argv[1]);
  const auto soak = mmlfw_faults::read_flat_json(src + "/build/bench/soak.json");
  if (soak.empty()) std::printf("bench_faults: no build/bench/soak.json yet (scripts/bench.sh soak)\n");
  mmlfw_faults::merge_flat_json(&kv, soak);
  return mmlfw_faults::write_flat_json(argv[1], kv) ? 0 : 1;
}
