#include "sim/devices/global_log_line.h"

#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace sim {
namespace {

// "SEC.USEC" (in parentheses when `paren`) as integer ns: a double loses the µs of an epoch stamp.
bool parse_time(const std::string& s, bool paren, std::uint64_t* ns) {
  const std::size_t open = paren ? 1 : 0, close = paren ? 1 : 0;
  if (s.size() < open + close + 8 || (paren && (s.front() != '(' || s.back() != ')'))) return false;
  const std::string t = s.substr(open, s.size() - open - close);
  const std::size_t dot = t.find('.');
  if (dot == 0 || dot == std::string::npos || t.size() != dot + 7 || dot > 12) return false;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (i != dot && (t[i] < '0' || t[i] > '9')) return false;
  }
  const unsigned long long sec = std::strtoull(t.substr(0, dot).c_str(), nullptr, 10);
  const unsigned long long usec = std::strtoull(t.substr(dot + 1).c_str(), nullptr, 10);
  *ns = (sec * 1000000ull + usec) * 1000ull;
  return true;
}

bool parse_rounds(const std::string& s, std::uint32_t* rounds) {
  if (s.empty() || s.size() > 9) return false;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
  }
  *rounds = static_cast<std::uint32_t>(std::strtoul(s.c_str(), nullptr, 10));
  return true;
}

}  // namespace

bool is_global_log_line(const std::string& line) {
  std::istringstream in(line);
  std::string a, b;
  return static_cast<bool>(in >> a >> b) && b == "global";
}

bool parse_global_log_line(const std::string& line, hal::GlobalRecord* out, std::string* error) {
  std::istringstream in(line);
  std::string stamp, tag, verb, job, rounds, extra;
  in >> stamp >> tag >> verb >> job >> rounds;
  *out = hal::GlobalRecord();
  if (!parse_time(stamp, true, &out->scan_ns)) {
    *error = "bad time stamp '" + stamp + "' (expected (SEC.USEC) with 6 digits of µs)";
    return false;
  }
  if (verb != "take" && verb != "drop") {
    *error = "global record '" + verb + "' (expected take or drop)";
    return false;
  }
  if (!parse_time(job, false, &out->job_scan_ns)) {
    *error = job.empty() ? "global record without the job's scan (a cut line?)"
                         : "bad job scan time '" + job + "' (expected SEC.USEC with 6 digits of µs)";
    return false;
  }
  if (!parse_rounds(rounds, &out->deadline_rounds)) {
    *error = rounds.empty() ? "global record without pRANSAM's rounds (a cut line?)"
                            : "bad rounds '" + rounds + "' (expected a decimal count, 0 = no deadline stop)";
    return false;
  }
  if (in >> extra) {
    *error = "unexpected field '" + extra + "' after the rounds";
    return false;
  }
  if (out->job_scan_ns > out->scan_ns) {
    *error = "the job's scan " + job + " comes after the scan its result was taken at";
    return false;
  }
  out->dropped = verb == "drop";
  return true;
}

}  // namespace sim
