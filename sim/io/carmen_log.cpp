#include "sim/io/carmen_log.h"

#include "sim/io/file_io.h"
#include "sim/io/text_fields.h"

#include <sys/stat.h>
#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cerrno>
#include <cstring>
#include <string_view>

namespace sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr size_t kMaxBadLineMessages = 100;
constexpr long kMaxReadings = 100000;

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

bool parse_count(std::string_view tok, long* v) {
  const char* b = tok.data();
  const char* e = b + tok.size();
  auto r = std::from_chars(b, e, *v);
  return r.ec == std::errc() && r.ptr == e && *v >= 0 && *v <= kMaxReadings;
}

bool looks_like_message_name(std::string_view tok) {
  if (tok.empty() || !(tok[0] >= 'A' && tok[0] <= 'Z')) return false;
  for (char c : tok) {
    if (!((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-')) return false;
  }
  return true;
}

std::string show(std::string_view tok) {
  std::string s(tok.substr(0, 40));
  for (char& c : s) {
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
  }
  return "'" + s + (tok.size() > 40 ? "…'" : "'");
}

// Per-line parser; returns false with *why set when the line is malformed.
class LineParser {
 public:
  LineParser(const std::vector<std::string_view>& t, std::string* why) : tok_(t), why_(why) {}

  bool num(size_t i, const char* what, double* v) {
    if (i >= tok_.size()) return fail(std::string("missing field ") + what);
    if (!parse_finite_double(tok_[i], v)) {
      return fail(std::string("field ") + std::to_string(i + 1) + " (" + what + ") is not a finite number: " +
                  show(tok_[i]));
    }
    return true;
  }
  // A finite number with |v| ≤ limit (plausibility bound; see carmen_log.h).
  bool num_in(size_t i, const char* what, double limit, const char* unit, double* v) {
    if (!num(i, what, v)) return false;
    if (!(std::fabs(*v) <= limit)) {
      char lim[32];
      std::snprintf(lim, sizeof(lim), "%g", limit);
      return fail(std::string("field ") + std::to_string(i + 1) + " (" + what + ") is " + show(tok_[i]) + unit +
                  ", outside the plausible ±" + lim + unit);
    }
    return true;
  }
  bool numf(size_t i, const char* what, float* v) {
    double d;
    if (!num(i, what, &d)) return false;
    *v = static_cast<float>(d);
    if (!std::isfinite(*v)) return fail(std::string("field ") + std::to_string(i + 1) + " (" + what + ") overflows float");
    return true;
  }
  bool count(size_t i, const char* what, long* v) {
    if (i >= tok_.size()) return fail(std::string("missing field ") + what);
    if (!parse_count(tok_[i], v)) {
      return fail(std::string("field ") + std::to_string(i + 1) + " (" + what +
                  ") is not a count in [0, 100000]: " + show(tok_[i]));
    }
    return true;
  }
  bool fields(size_t expected, const std::string& context) {
    if (tok_.size() != expected) {
      return fail(context + ": expected " + std::to_string(expected) + " fields, found " +
                  std::to_string(tok_.size()) + (tok_.size() < expected ? " (truncated line?)" : ""));
    }
    return true;
  }
  bool ranges(size_t first, long n, std::vector<float>* out) {
    out->resize(static_cast<size_t>(n));
    for (long k = 0; k < n; ++k) {
      float r;
      if (!numf(first + static_cast<size_t>(k), "range reading", &r)) return false;
      if (r < 0.0f) return fail("range reading " + std::to_string(k) + " is negative: " + show(tok_[first + k]));
      if (r > static_cast<float>(kMaxLaserRangeM)) {
        return fail("range reading " + std::to_string(k) + " is " + show(tok_[first + k]) +
                    " m, beyond the plausible 1000 m of a laser scanner");
      }
      (*out)[static_cast<size_t>(k)] = r;
    }
    return true;
  }
  bool pose(size_t i, const char* what, fw::Se2d* p) {
    return num_in(i, what, kMaxAbsPositionM, " m", &p->x) && num_in(i + 1, what, kMaxAbsPositionM, " m", &p->y) &&
           num_in(i + 2, what, kMaxAbsAngleRad, " rad", &p->theta);
  }
  // "ipc_timestamp ipc_hostname logger_timestamp" at the end of the line.
  bool stamps(double* ipc, double* logger) {
    const size_t n = tok_.size();
    return num_in(n - 3, "ipc_timestamp", kMaxAbsTimestampS, " s", ipc) &&
           num_in(n - 1, "logger_timestamp", kMaxAbsTimestampS, " s", logger);
  }
  bool fail(const std::string& m) {
    *why_ = m;
    return false;
  }

 private:
  const std::vector<std::string_view>& tok_;
  std::string* why_;
};

void flaser_geometry(size_t n, CarmenScan* s) {
  s->angle_min = static_cast<float>(-kPi / 2);
  if (n <= 1) {
    s->angle_increment = 0.0f;
  } else if (n % 2 == 0) {
    s->angle_increment = static_cast<float>(kPi / static_cast<double>(n));
  } else {
    s->angle_increment = static_cast<float>(kPi / static_cast<double>(n - 1));
  }
}

bool parse_flaser(const std::vector<std::string_view>& t, CarmenScan* s, std::string* why) {
  LineParser p(t, why);
  long n;
  if (!p.count(1, "num_readings", &n)) return false;
  if (!p.fields(static_cast<size_t>(n) + 11, s->type + " with " + std::to_string(n) + " readings")) return false;
  if (!p.ranges(2, n, &s->ranges)) return false;
  const size_t k = 2 + static_cast<size_t>(n);
  if (!p.pose(k, "x y theta", &s->pose) || !p.pose(k + 3, "odom_x odom_y odom_theta", &s->odom)) return false;
  if (!p.stamps(&s->ipc_timestamp, &s->logger_timestamp)) return false;
  flaser_geometry(static_cast<size_t>(n), s);
  return true;
}

// Common head of ROBOTLASER1 / RAWLASERn: laser_type start_angle fov resolution max_range accuracy
// remission_mode num_readings ranges num_remissions remissions.  Returns the index after remissions.
bool parse_laser_head(const std::vector<std::string_view>& t, CarmenScan* s, size_t tail, size_t* after,
                      std::string* why) {
  LineParser p(t, why);
  double laser_type, fov, accuracy, mode, start, res, maxr;
  if (!p.num(1, "laser_type", &laser_type) || !p.num(2, "start_angle", &start) || !p.num(3, "field_of_view", &fov) ||
      !p.num(4, "angular_resolution", &res) || !p.num(5, "maximum_range", &maxr) ||
      !p.num(6, "accuracy", &accuracy) || !p.num(7, "remission_mode", &mode)) {
    return false;
  }
  long n, m;
  if (!p.count(8, "num_readings", &n)) return false;
  const size_t rem_at = 9 + static_cast<size_t>(n);
  if (rem_at >= t.size()) {
    return p.fail(s->type + " with " + std::to_string(n) + " readings: line ends after " + std::to_string(t.size()) +
                  " fields (truncated line?)");
  }
  if (!p.count(rem_at, "num_remissions", &m)) return false;
  if (!p.fields(rem_at + 1 + static_cast<size_t>(m) + tail,
                s->type + " with " + std::to_string(n) + " readings and " + std::to_string(m) + " remissions")) {
    return false;
  }
  if (!p.ranges(9, n, &s->ranges)) return false;
  for (long k = 0; k < m; ++k) {
    double r;
    if (!p.num(rem_at + 1 + static_cast<size_t>(k), "remission", &r)) return false;
  }
  // Geometry the scan is projected with: a maximum range that fits a float and a laser, a positive
  // resolution (zero put every beam on one bearing; negative ones are not in the format), at most a
  // full turn of beams, start angle and field of view within a turn.
  constexpr double kTurn = 2.0 * kPi + 1e-3;  // + print rounding of 2π
  auto bad = [&](size_t field, const char* what, const std::string& reason) {
    return p.fail(std::string("field ") + std::to_string(field + 1) + " (" + what + ") is " + show(t[field]) + ": " + reason);
  };
  if (!(maxr > 0.0)) return bad(5, "maximum_range", "maximum_range must be positive");
  if (maxr > kMaxLaserRangeM) return bad(5, "maximum_range", "beyond the plausible 1000 m of a laser scanner");
  if (!(res > 0.0)) return bad(4, "angular_resolution", "must be positive");
  if (n > 1 && res * static_cast<double>(n - 1) > kTurn) {
    return bad(4, "angular_resolution", std::to_string(n) + " beams at this spacing span more than a full turn");
  }
  if (std::fabs(start) > kTurn) return bad(2, "start_angle", "more than a full turn");
  if (std::fabs(fov) > kTurn) return bad(3, "field_of_view", "more than a full turn");
  s->angle_min = static_cast<float>(start);
  s->angle_increment = static_cast<float>(res);
  s->max_range = static_cast<float>(maxr);
  *after = rem_at + 1 + static_cast<size_t>(m);
  return true;
}

bool parse_robotlaser(const std::vector<std::string_view>& t, CarmenScan* s, std::string* why) {
  size_t k;
  // tail: laser pose (3), robot pose (3), tv rv forward_safety side_safety turn_axis (5), stamps (3)
  if (!parse_laser_head(t, s, 14, &k, why)) return false;
  LineParser p(t, why);
  if (!p.pose(k, "laser_pose", &s->pose) || !p.pose(k + 3, "robot_pose", &s->odom)) return false;
  double v;
  for (size_t i = 0; i < 5; ++i) {
    if (!p.num(k + 6 + i, "tv/rv/safety/turn_axis", &v)) return false;
  }
  return p.stamps(&s->ipc_timestamp, &s->logger_timestamp);
}

bool parse_rawlaser(const std::vector<std::string_view>& t, CarmenScan* s, std::string* why) {
  size_t k;
  if (!parse_laser_head(t, s, 3, &k, why)) return false;
  LineParser p(t, why);
  return p.stamps(&s->ipc_timestamp, &s->logger_timestamp);
}

bool parse_odom(const std::vector<std::string_view>& t, CarmenOdom* o, std::string* why) {
  LineParser p(t, why);
  double accel;
  return p.fields(10, "ODOM") && p.pose(1, "x y theta", &o->pose) && p.num_in(4, "tv", kMaxAbsSpeed, " m/s", &o->tv) &&
         p.num_in(5, "rv", kMaxAbsSpeed, " rad/s", &o->rv) && p.num(6, "accel", &accel) &&
         p.stamps(&o->ipc_timestamp, &o->logger_timestamp);
}

bool parse_param(const std::vector<std::string_view>& t, std::pair<std::string, std::string>* kv, std::string* why) {
  if (t.size() < 3) {
    *why = "PARAM needs a name and a value";
    return false;
  }
  // Two layouts occur: "PARAM name value ipc host logger" and (intel, aces) "PARAM name value host logger".
  double d;
  size_t end = t.size();
  if (t.size() >= 6 && parse_finite_double(t[end - 1], &d) && !parse_finite_double(t[end - 2], &d) && parse_finite_double(t[end - 3], &d)) {
    end -= 3;
  } else if (t.size() >= 5 && parse_finite_double(t[end - 1], &d) && !parse_finite_double(t[end - 2], &d)) {
    end -= 2;
  }
  kv->first = std::string(t[1]);
  kv->second.clear();
  for (size_t i = 2; i < end; ++i) {
    if (i > 2) kv->second += ' ';
    kv->second.append(t[i]);
  }
  // The laser maxima become the FLASER/RLASER max_range (float): same bounds as a ROBOTLASER1's.
  if ((kv->first == "robot_front_laser_max" || kv->first == "robot_rear_laser_max") &&
      parse_finite_double(kv->second, &d) && !(d > 0.0 && d <= kMaxLaserRangeM)) {
    *why = "PARAM " + kv->first + " " + show(kv->second) + " is not a plausible maximum range (0, 1000] m";
    return false;
  }
  return true;
}

bool is_rawlaser(std::string_view name) {
  return name.size() == 9 && name.substr(0, 8) == "RAWLASER" && name[8] >= '1' && name[8] <= '4';
}

}  // namespace

size_t CarmenLog::count(const std::string& type) const {
  size_t n = 0;
  for (const auto& s : scans) n += (s.type == type);
  return n;
}

namespace {

std::string mib_text(std::uint64_t bytes) {
  if (bytes % (std::uint64_t(1) << 20) == 0) return std::to_string(bytes >> 20) + " MiB";
  return std::to_string(bytes) + " bytes";
}

// Inflates a gzip file held in memory: every member (gzip -d concatenates members), nothing after the
// last one (zlib's gzread silently ignores trailing bytes: a log with garbage appended read as good),
// at most max_bytes of output (a 13 MB bomb of 3 GB of newlines is stopped at the cap, not inflated).
bool inflate_gzip(const std::string& path, const std::string& gz, std::uint64_t max_bytes, std::string* out,
                  std::string* error) {
  z_stream zs{};
  if (inflateInit2(&zs, 15 + 16) != Z_OK) {
    *error = path + ": cannot initialise zlib";
    return false;
  }
  const unsigned char* in = reinterpret_cast<const unsigned char*>(gz.data());
  std::size_t in_left = gz.size();
  constexpr std::size_t kChunk = std::size_t(1) << 20;
  std::string msg;
  for (;;) {
    if (zs.avail_in == 0 && in_left > 0) {
      const std::size_t n = std::min<std::size_t>(in_left, std::size_t(1) << 30);
      zs.next_in = const_cast<unsigned char*>(in);
      zs.avail_in = static_cast<uInt>(n);
      in += n;
      in_left -= n;
    }
    if (out->size() >= max_bytes + 1) {
      msg = path + ": inflates to more than " + mib_text(max_bytes) +
            " (the limit for one file; not a log, or raise the limit with --max-log-mib)";
      break;
    }
    const std::size_t old = out->size();
    const std::size_t room = static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, max_bytes + 1 - old));
    out->resize(old + room);
    zs.next_out = reinterpret_cast<unsigned char*>(out->data() + old);
    zs.avail_out = static_cast<uInt>(room);
    const int rc = inflate(&zs, Z_NO_FLUSH);
    out->resize(old + room - zs.avail_out);
    if (rc == Z_STREAM_END) {
      const std::size_t rest = zs.avail_in + in_left;
      if (rest == 0) break;  // done: the input ends with this member
      const std::size_t at = gz.size() - rest;
      if (rest >= 2 && static_cast<unsigned char>(gz[at]) == 0x1f && static_cast<unsigned char>(gz[at + 1]) == 0x8b) {
        inflateReset(&zs);  // another gzip member follows
        continue;
      }
      msg = path + ": " + std::to_string(rest) + " bytes of trailing garbage after the gzip stream (from byte " +
            std::to_string(at) + " of " + std::to_string(gz.size()) + ")";
      break;
    }
    if (rc == Z_BUF_ERROR && zs.avail_in == 0 && in_left == 0) {
      msg = path + ": corrupt or truncated gzip data: unexpected end of file";
      break;
    }
    if (rc != Z_OK && rc != Z_BUF_ERROR) {
      msg = path + ": corrupt gzip data: " + (zs.msg ? zs.msg : "zlib error " + std::to_string(rc));
      break;
    }
  }
  inflateEnd(&zs);
  if (!msg.empty()) {
    *error = msg;
    out->clear();
    return false;
  }
  return true;
}

}  // namespace

bool read_file_maybe_gz(const std::string& path, std::string* data, std::string* error) {
  return read_file_maybe_gz(path, kDefaultMaxLogBytes, data, error);
}

bool read_file_maybe_gz(const std::string& path, std::uint64_t max_bytes, std::string* data, std::string* error) {
  data->clear();
  // The compressed file is bounded by the same cap (it is never larger than what it inflates to,
  // short of a broken file); only regular files are opened (a FIFO would block, /dev/zero never end).
  std::string raw;
  if (!read_regular_file(path, max_bytes, &raw, error)) {
    if (error->find("more than the limit") != std::string::npos) *error += " (raise it with --max-log-mib)";
    return false;
  }
  const bool gz = raw.size() >= 2 && static_cast<unsigned char>(raw[0]) == 0x1f &&
                  static_cast<unsigned char>(raw[1]) == 0x8b;
  if (!gz) {
    *data = std::move(raw);
    return true;
  }
  return inflate_gzip(path, raw, max_bytes, data, error);
}

bool parse_carmen_log(const std::string& name, const char* data, size_t size, const CarmenReadOptions& options,
                      CarmenLog* out, std::string* error) {
  *out = CarmenLog();
  out->path = name;
  std::vector<std::string_view> tok;
  tok.reserve(512);
  std::string why;
  const char* p = data;
  const char* end = data + size;
  size_t line_no = 0;
  CarmenScan scan;
  CarmenOdom odom;
  std::pair<std::string, std::string> kv;
  size_t scan_records = 0;  // scan lines seen, malformed ones included (so index = flaser_index)
  while (p < end) {
    const char* eol = static_cast<const char*>(std::memchr(p, '\n', static_cast<size_t>(end - p)));
    if (!eol) eol = end;
    ++line_no;
    const char* q = p;
    p = eol + 1;
    if (static_cast<size_t>(eol - q) > options.max_line_bytes) {
      // Not tokenized: a multi-gigabyte line would otherwise become gigabytes of token views.
      const std::string msg = name + ":" + std::to_string(line_no) + ": line of " + std::to_string(eol - q) +
                              " bytes, longer than the limit of " + std::to_string(options.max_line_bytes) +
                              " (not a CARMEN log?)";
      if (!options.skip_bad_lines) {
        *error = msg;
        out->lines = line_no;
        return false;
      }
      ++out->bad_lines;
      if (out->bad_line_messages.size() < kMaxBadLineMessages) out->bad_line_messages.push_back(msg);
      // A dropped scan line still counts (indices keep matching the file's scan ordinals).
      const char* h = q;
      while (h < eol && is_space(*h)) ++h;
      const std::string_view head(h, static_cast<size_t>(std::min<ptrdiff_t>(eol - h, 12)));
      if (head.rfind("FLASER", 0) == 0 || head.rfind("RLASER", 0) == 0 || head.rfind("ROBOTLASER1", 0) == 0 ||
          head.rfind("RAWLASER", 0) == 0) {
        ++scan_records;
      }
      continue;
    }
    while (q < eol && is_space(*q)) ++q;
    if (q == eol) continue;
    if (*q == '#') {
      ++out->comment_lines;
      continue;
    }
    tok.clear();
    while (q < eol) {
      const char* b = q;
      while (q < eol && !is_space(*q)) ++q;
      tok.emplace_back(b, static_cast<size_t>(q - b));
      while (q < eol && is_space(*q)) ++q;
    }
    const std::string_view head = tok[0];
    bool ok = true;
    bool is_scan = false;
    if (head == "FLASER" || head == "RLASER") {
      scan.type.assign(head);
      ok = parse_flaser(tok, &scan, &why);
      is_scan = true;
    } else if (head == "ROBOTLASER1") {
      scan.type.assign(head);
      scan.pose = fw::Se2d();
      ok = parse_robotlaser(tok, &scan, &why);
      is_scan = true;
    } else if (is_rawlaser(head)) {
      scan.type.assign(head);
      scan.pose = fw::Se2d();
      scan.odom = fw::Se2d();
      ok = parse_rawlaser(tok, &scan, &why);
      is_scan = true;
    } else if (head == "ODOM") {
      ok = parse_odom(tok, &odom, &why);
      if (ok) {
        odom.line = line_no;
        out->odom.push_back(odom);
      }
    } else if (head == "PARAM") {
      ok = parse_param(tok, &kv, &why);
      if (ok) out->params.push_back(kv);
    } else if (head == "NEFF") {
      double v;
      ok = tok.size() >= 2 && parse_finite_double(tok[1], &v);
      if (ok) {
        ++out->neff_records;
      } else {
        why = "NEFF needs a numeric value";
      }
    } else if (looks_like_message_name(head)) {
      ++out->other_records;
    } else {
      ok = false;
      why = "not a CARMEN message (first field " + show(head) + ")";
    }
    if (is_scan) ++scan_records;
    if (ok && is_scan) {
      scan.line = line_no;
      scan.index = scan_records - 1;
      out->scans.push_back(scan);
    }
    if (!ok) {
      const std::string msg = name + ":" + std::to_string(line_no) + ": " + why;
      if (!options.skip_bad_lines) {
        *error = msg;
        out->lines = line_no;
        return false;
      }
      ++out->bad_lines;
      if (out->bad_line_messages.size() < kMaxBadLineMessages) out->bad_line_messages.push_back(msg);
    }
    if (options.max_scans != 0 && out->scans.size() >= options.max_scans) break;
  }
  out->lines = line_no;

  // Maximum range for FLASER/RLASER (no geometry in the record): PARAM, else the log's largest reading.
  for (const char* type : {"FLASER", "RLASER"}) {
    const std::string param = std::strcmp(type, "FLASER") == 0 ? "robot_front_laser_max" : "robot_rear_laser_max";
    double maxr = 0.0;
    for (const auto& kvp : out->params) {
      double v;
      if (kvp.first == param && parse_finite_double(kvp.second, &v) && v > 0.0) maxr = v;
    }
    if (maxr == 0.0) {
      float m = 0.0f;
      for (const auto& s : out->scans) {
        if (s.type != type) continue;
        for (float r : s.ranges) m = std::max(m, r);
      }
      maxr = m;
    }
    for (auto& s : out->scans) {
      if (s.type == type) s.max_range = static_cast<float>(maxr);
    }
  }
  return true;
}

bool read_carmen_log(const std::string& path, const CarmenReadOptions& options, CarmenLog* out, std::string* error) {
  std::string data;
  if (!read_file_maybe_gz(path, options.max_bytes, &data, error)) {
    *out = CarmenLog();
    out->path = path;
    return false;
  }
  return parse_carmen_log(path, data.data(), data.size(), options, out, error);
}

hal::LaserScan to_laser_scan(const CarmenScan& scan, uint64_t timestamp_ns) {
  hal::LaserScan m;
  m.timestamp_ns = timestamp_ns;
  m.scan_id = static_cast<uint32_t>(scan.index);
  const size_t n = std::min<size_t>(scan.ranges.size(), hal::LaserScan::kMaxBeams);
  m.beam_count = static_cast<uint32_t>(n);
  m.angle_min = scan.angle_min;
  m.angle_increment = scan.angle_increment;
  m.range_min = 0.01f;
  m.range_max = scan.max_range;
  // A record with 0 readings ("FLASER 0 ...") has no data pointer: copying 0 bytes from null is
  // still undefined (UBSan). The result is an empty scan (beam_count 0), which the localization
  // loop drops as malformed and counts; localizers skip it.
  if (n > 0) std::memcpy(m.ranges, scan.ranges.data(), n * sizeof(float));
  return m;
}

namespace {

// Shortest representation that reads back to the same value (exact round trip).
void put_num(std::string* s, double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof(buf), v);
  s->push_back(' ');
  s->append(buf, r.ptr);
}
void put_numf(std::string* s, float v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof(buf), v);
  s->push_back(' ');
  s->append(buf, r.ptr);
}
void put_pose(std::string* s, const fw::Se2d& p) {
  put_num(s, p.x);
  put_num(s, p.y);
  put_num(s, p.theta);
}
void put_stamps(std::string* s, double ipc, const std::string& host, double logger) {
  put_num(s, ipc);
  s->push_back(' ');
  s->append(host);
  put_num(s, logger);
  s->push_back('\n');
}

void put_scan(std::string* s, const CarmenScan& sc, const std::string& host) {
  if (sc.type == "ROBOTLASER1" || is_rawlaser(sc.type)) {
    s->append(sc.type);
    s->append(" 0");
    put_numf(s, sc.angle_min);
    put_numf(s, sc.angle_increment * static_cast<float>(sc.ranges.empty() ? 0 : sc.ranges.size() - 1));
    put_numf(s, sc.angle_increment);
    put_numf(s, sc.max_range);
    s->append(" 0.01 0 ");
    s->append(std::to_string(sc.ranges.size()));
    for (float r : sc.ranges) put_numf(s, r);
    s->append(" 0");
    if (sc.type == "ROBOTLASER1") {
      put_pose(s, sc.pose);
      put_pose(s, sc.odom);
      s->append(" 0 0 0 0 0");
    }
  } else {
    s->append(sc.type == "RLASER" ? "RLASER " : "FLASER ");
    s->append(std::to_string(sc.ranges.size()));
    for (float r : sc.ranges) put_numf(s, r);
    put_pose(s, sc.pose);
    put_pose(s, sc.odom);
  }
  put_stamps(s, sc.ipc_timestamp, host, sc.logger_timestamp);
}

}  // namespace

bool write_carmen_log(const std::string& path, const CarmenLog& log, const CarmenWriteOptions& options,
                      std::string* error) {
  std::string s;
  s.reserve(log.scans.size() * (log.scans.empty() ? 0 : log.scans[0].ranges.size() * 6 + 200) + log.odom.size() * 120);
  s += "# CARMEN log written by mmlfw sim_io\n";
  s += "# message_name [message contents] ipc_timestamp ipc_hostname logger_timestamp\n";
  s += "# FLASER num_readings [range_readings] x y theta odom_x odom_y odom_theta\n";
  s += "# ODOM x y theta tv rv accel\n";
  const std::string& host = options.hostname;
  for (const auto& kv : log.params) {
    s += "PARAM " + kv.first + " " + (kv.second.empty() ? std::string("0") : kv.second) + " 0 " + host + " 0\n";
  }
  // Merge scans and odometry in their original line order (records written by a program have line 0:
  // then the order is odometry before scans of equal line number, i.e. all kept in vector order).
  size_t i = 0, j = 0;
  while (i < log.scans.size() || j < log.odom.size()) {
    const bool take_odom =
        j < log.odom.size() && (i >= log.scans.size() || log.odom[j].line < log.scans[i].line ||
                                (log.odom[j].line == log.scans[i].line && log.odom[j].line == 0 &&
                                 log.odom[j].ipc_timestamp <= log.scans[i].ipc_timestamp));
    if (take_odom) {
      const auto& o = log.odom[j++];
      s += "ODOM";
      put_pose(&s, o.pose);
      put_num(&s, o.tv);
      put_num(&s, o.rv);
      s += " 0";
      put_stamps(&s, o.ipc_timestamp, host, o.logger_timestamp);
    } else {
      put_scan(&s, log.scans[i++], host);
    }
  }
  const bool gz = options.gzip || (path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0);
  if (gz) {
    gzFile f = gzopen(path.c_str(), "wb6");
    if (!f) {
      *error = path + ": cannot open for writing";
      return false;
    }
    const int n = s.empty() ? 0 : gzwrite(f, s.data(), static_cast<unsigned>(s.size()));
    const int rc = gzclose(f);
    if (static_cast<size_t>(n) != s.size() || rc != Z_OK) {
      *error = path + ": write error";
      return false;
    }
    return true;
  }
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) {
    *error = path + ": cannot open for writing: " + std::strerror(errno);
    return false;
  }
  const size_t n = std::fwrite(s.data(), 1, s.size(), f);
  const bool ok = std::fclose(f) == 0 && n == s.size();
  if (!ok) *error = path + ": write error";
  return ok;
}

}  // namespace sim
