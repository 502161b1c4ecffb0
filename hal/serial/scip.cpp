#include "hal_serial/scip.h"

#include <cstdio>
#include <cstring>

namespace hal_serial {

using fw::Errc;
using fw::Status;

namespace {

bool is_info_command(const char* c) {
  return !std::strcmp(c, "VV") || !std::strcmp(c, "PP") || !std::strcmp(c, "II");
}
bool is_scan_command(const char* c) {
  return c[0] == 'M' && (c[1] == 'D' || c[1] == 'S' || c[1] == 'E');
}

// An echo line of a command this driver sends or a SCIP device answers (Sec. 8): the measurement
// echoes are 13 digits after the command (then ";string"), the others nothing but ";string".
// Used to notice an answer cut short: only where the line also fails the data-line sum.
bool is_echo_line(const char* s, std::size_t n) {
  if (n < 2) return false;
  static const char* const kPlain[] = {"VV", "PP", "II", "BM", "QT", "RS", "TM", "SS", "CR", "HS", "DB"};
  if (s[0] == 'M' && (s[1] == 'D' || s[1] == 'S' || s[1] == 'E')) {
    if (n < 15 || (n > 15 && s[15] != ';')) return false;
    for (std::size_t i = 2; i < 15; ++i)
      if (s[i] < '0' || s[i] > '9') return false;
    return true;
  }
  if (n >= 7 && std::memcmp(s, "SCIP2.0", 7) == 0) return n == 7;
  for (const char* p : kPlain) {
    if (s[0] == p[0] && s[1] == p[1]) return n == 2 || s[2] == ';';
  }
  return false;
}

bool parse_digits(const char* s, std::size_t n, std::uint32_t* out) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (s[i] < '0' || s[i] > '9') return false;
    v = v * 10 + static_cast<std::uint32_t>(s[i] - '0');
  }
  *out = v;
  return true;
}

}  // namespace

char scip_sum(const char* s, std::size_t n) {
  unsigned sum = 0;
  for (std::size_t i = 0; i < n; ++i) sum += static_cast<unsigned char>(s[i]);
  return static_cast<char>((sum & 0x3F) + 0x30);
}

bool scip_decode(const char* s, std::size_t n, std::uint32_t* out) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const unsigned c = static_cast<unsigned char>(s[i]);
    if (c < 0x30 || c > 0x6F) return false;
    v = (v << 6) | (c - 0x30);
  }
  *out = v;
  return true;
}

void scip_encode(std::uint32_t value, std::size_t n, char* out) {
  for (std::size_t i = 0; i < n; ++i) {
    out[n - 1 - i] = static_cast<char>((value & 0x3F) + 0x30);
    value >>= 6;
  }
}

void ScipParser::reset() {
  line_len_ = 0;
  line_overlong_ = false;
  cur_lines_ = 0;
  cur_bad_ = false;
  ready_ = false;
}

std::size_t ScipParser::feed(const std::uint8_t* bytes, std::size_t n) {
  std::size_t i = 0;
  while (i < n && !ready_) {
    const char c = static_cast<char>(bytes[i++]);
    if (c == '\n') {
      on_line();
      line_len_ = 0;
      line_overlong_ = false;
    } else if (line_len_ < kScipMaxLine) {
      line_[line_len_++] = c;
    } else {
      line_overlong_ = true;
    }
  }
  return i;
}

bool ScipParser::next(ScipResponse* out) {
  if (!ready_) return false;
  *out = cur_;
  ready_ = false;
  return true;
}

void ScipParser::drop(std::uint32_t* counter) {
  if (cur_bad_) return;
  ++*counter;
  cur_bad_ = true;
}

void ScipParser::append(const char* s, std::size_t n) {
  if (cur_.data_len + n > kScipMaxData) {
    drop(&stats_.malformed);
    return;
  }
  std::memcpy(cur_.data + cur_.data_len, s, n);
  cur_.data_len += n;
  cur_.data[cur_.data_len] = '\0';
}

void ScipParser::begin(const char* line, std::size_t n) {
  cur_.command[0] = n > 0 ? line[0] : '\0';
  cur_.command[1] = n > 1 ? line[1] : '\0';
  cur_.command[2] = '\0';
  std::memcpy(cur_.echo, line, n);
  cur_.echo[n] = '\0';
  cur_.echo_len = n;
  cur_.status[0] = cur_.status[1] = cur_.status[2] = '\0';
  cur_.has_timestamp = false;
  cur_.timestamp_ms = 0;
  cur_.data_len = 0;
  cur_.data[0] = '\0';
  cur_lines_ = 1;
  cur_bad_ = n < 2;
  if (cur_bad_) ++stats_.malformed;
}

void ScipParser::on_status_line(const char* line, std::size_t n) {
  if (n != 3) {
    drop(&stats_.malformed);
    return;
  }
  if (scip_sum(line, 2) != line[2]) {
    drop(&stats_.checksum_errors);
    return;
  }
  cur_.status[0] = line[0];
  cur_.status[1] = line[1];
  cur_.status[2] = '\0';
}

void ScipParser::on_body_line(const char* line, std::size_t n) {
  if (is_info_command(cur_.command)) {
    // "KEY:value;S": the sum covers what is before the ';'.
    if (n < 3 || line[n - 2] != ';') return drop(&stats_.malformed);
    if (scip_sum(line, n - 2) != line[n - 1]) return drop(&stats_.checksum_errors);
    append(line, n - 2);
    append("\n", 1);
    return;
  }
  if (n < 2) return drop(&stats_.malformed);
  if (scip_sum(line, n - 1) != line[n - 1]) return drop(&stats_.checksum_errors);
  const bool scan_data = is_scan_command(cur_.command) && cur_.status[0] == '9' && cur_.status[1] == '9';
  if (scan_data && cur_lines_ == 3) {  // the line after the status: the time stamp
    if (n != 5 || !scip_decode(line, 4, &cur_.timestamp_ms)) return drop(&stats_.malformed);
    cur_.has_timestamp = true;
    return;
  }
  if (scan_data && n - 1 > 64) return drop(&stats_.malformed);  // data lines carry at most 64 characters
  append(line, n - 1);
}

void ScipParser::on_line() {
  std::size_t n = line_len_;
  if (n > 0 && line_[n - 1] == '\r') --n;  // hosts may send CR LF; a device never does, but be lenient
  line_[n] = '\0';
  if (n > 0) {
    std::size_t k = 0;
    for (std::size_t i = 0; i < n && k + 1 < sizeof(last_line_); ++i) {
      const char c = line_[i];
      last_line_[k++] = (c >= 0x20 && c < 0x7F) ? c : '?';
    }
    last_line_[k] = '\0';
  }
  if (line_overlong_) {
    if (cur_lines_ == 0) {
      cur_lines_ = 1;
      cur_bad_ = false;
    }
    drop(&stats_.malformed);
    return;
  }
  if (n == 0) {
    if (cur_lines_ == 0) {
      ++stats_.stray_lines;
      return;
    }
    if (!cur_bad_ && cur_lines_ < 2) {
      ++stats_.malformed;  // an echo without a status line is no answer
    } else if (!cur_bad_) {
      ready_ = true;
      ++stats_.responses;
    }
    cur_lines_ = 0;
    cur_bad_ = false;
    return;
  }
  if (cur_lines_ == 0) return begin(line_, n);
  if (cur_lines_ >= 1 && is_echo_line(line_, n) && scip_sum(line_, n - 1) != line_[n - 1]) {
    // The answer in progress was cut short (device reset, lost bytes): this is the next one.
    if (!cur_bad_) ++stats_.truncated;
    return begin(line_, n);
  }
  ++cur_lines_;
  if (cur_bad_) return;
  if (cur_lines_ == 2) return on_status_line(line_, n);
  on_body_line(line_, n);
}

bool parse_scip_scan_echo(const ScipResponse& r, ScipScanEcho* out) {
  if (!is_scan_command(r.command) || r.echo_len < 15) return false;
  const char* e = r.echo;
  return parse_digits(e + 2, 4, &out->start) && parse_digits(e + 6, 4, &out->end) &&
         parse_digits(e + 10, 2, &out->cluster) && parse_digits(e + 12, 1, &out->interval) &&
         parse_digits(e + 13, 2, &out->scans);
}

Status decode_scip_scan(const ScipResponse& r, ScipScan* out) {
  if (!is_scan_command(r.command)) {
    return Status::error(Errc::kInvalidArgument, "SCIP answer '%s' is not MD/MS/ME", r.command);
  }
  if (r.status[0] != '9' || r.status[1] != '9' || !r.has_timestamp) {
    return Status::error(Errc::kInvalidArgument, "SCIP %s answer with status '%s' carries no scan", r.command, r.status);
  }
  if (!parse_scip_scan_echo(r, &out->echo)) {
    return Status::error(Errc::kCorruptData, "SCIP %s echo '%.20s' is not start/end/cluster/interval/scans", r.command,
                         r.echo);
  }
  const ScipScanEcho& e = out->echo;
  if (e.end < e.start) return Status::error(Errc::kCorruptData, "SCIP %s: end step %u before start %u", r.command, e.end, e.start);
  const std::uint32_t cluster = e.cluster == 0 ? 1 : e.cluster;
  const std::uint32_t count = (e.end - e.start + cluster) / cluster;
  if (count > kScipMaxSteps) {
    return Status::error(Errc::kCorruptData, "SCIP %s: %u values, more than %zu", r.command, count, kScipMaxSteps);
  }
  const std::size_t chars = r.command[1] == 'S' ? 2 : 3;
  const bool intensity = r.command[1] == 'E';
  const std::size_t per_value = intensity ? 2 * chars : chars;
  if (r.data_len != count * per_value) {
    return Status::error(Errc::kCorruptData, "SCIP %s: %zu data characters for %u values (%zu expected)", r.command,
                         r.data_len, count, count * per_value);
  }
  out->count = count;
  out->has_intensity = intensity;
  out->timestamp_ms = r.timestamp_ms;
  for (std::uint32_t i = 0; i < count; ++i) {
    const char* p = r.data + i * per_value;
    if (!scip_decode(p, chars, &out->ranges_mm[i]) || (intensity && !scip_decode(p + chars, chars, &out->intensity[i]))) {
      return Status::error(Errc::kCorruptData, "SCIP %s: value %u is not in the SCIP encoding", r.command, i);
    }
    if (!intensity) out->intensity[i] = 0;
  }
  return Status::ok();
}

bool scip_info_value(const ScipResponse& r, const char* key, char* out, std::size_t cap) {
  const std::size_t kl = std::strlen(key);
  const char* p = r.data;
  const char* end = r.data + r.data_len;
  while (p < end) {
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
    const char* le = nl ? nl : end;
    if (static_cast<std::size_t>(le - p) > kl && std::memcmp(p, key, kl) == 0 && p[kl] == ':') {
      std::size_t n = static_cast<std::size_t>(le - p) - kl - 1;
      if (n >= cap) n = cap - 1;
      std::memcpy(out, p + kl + 1, n);
      out[n] = '\0';
      return true;
    }
    p = le + 1;
  }
  return false;
}

Status decode_scip_parameters(const ScipResponse& r, ScipParameters* out) {
  if (std::strcmp(r.command, "PP") != 0 || r.status[0] != '0' || r.status[1] != '0') {
    return Status::error(Errc::kInvalidArgument, "SCIP answer '%s' status '%s' is not a PP answer", r.command, r.status);
  }
  *out = ScipParameters{};
  if (!scip_info_value(r, "MODL", out->model, sizeof(out->model))) out->model[0] = '\0';
  struct Field {
    const char* key;
    std::uint32_t* value;
    bool required;
  };
  const Field fields[] = {{"DMIN", &out->dmin_mm, true}, {"DMAX", &out->dmax_mm, true}, {"ARES", &out->ares, true},
                          {"AMIN", &out->amin, true},    {"AMAX", &out->amax, true},    {"AFRT", &out->afrt, true},
                          {"SCAN", &out->scan_rpm, false}};
  for (const Field& f : fields) {
    char v[24];
    if (!scip_info_value(r, f.key, v, sizeof(v))) {
      if (!f.required) continue;
      return Status::error(Errc::kCorruptData, "SCIP PP answer has no %s", f.key);
    }
    // Some firmwares pad with a space ("DMIN: 20"): skip it.
    const char* s = v;
    while (*s == ' ') ++s;
    std::size_t n = std::strlen(s);
    if (n == 0 || n > 9 || !parse_digits(s, n, f.value)) {
      return Status::error(Errc::kCorruptData, "SCIP PP %s '%s' is not a number", f.key, v);
    }
  }
  // Steps are 4-digit fields of MD/MS (Sec. 8.1): a unit with more than 9999 is not SCIP 2.0.
  if (out->ares == 0 || out->amin > out->amax || out->amax >= 2 * out->ares || out->amax > 9999 ||
      out->dmax_mm <= out->dmin_mm) {
    return Status::error(Errc::kCorruptData, "SCIP PP geometry impossible (ARES %u, AMIN %u, AMAX %u, DMIN %u, DMAX %u)",
                         out->ares, out->amin, out->amax, out->dmin_mm, out->dmax_mm);
  }
  return Status::ok();
}

namespace {

struct Writer {
  char* out;
  std::size_t cap;
  std::size_t n = 0;
  bool ok = true;
  void put(const char* s, std::size_t len) {
    if (n + len > cap) {
      ok = false;
      return;
    }
    std::memcpy(out + n, s, len);
    n += len;
  }
  void put(char c) { put(&c, 1); }
  void line(const char* s, std::size_t len) {  // s + its sum + LF
    put(s, len);
    put(scip_sum(s, len));
    put('\n');
  }
  void head(const char* echo, const char* status) {
    put(echo, std::strlen(echo));
    put('\n');
    line(status, 2);
  }
  std::size_t done() const { return ok ? n : 0; }
};

}  // namespace

std::size_t encode_scip_status(const char* echo, const char* status, char* out, std::size_t cap) {
  Writer w{out, cap};
  w.head(echo, status);
  w.put('\n');
  return w.done();
}

std::size_t encode_scip_info(const char* echo, const char* const* lines, std::size_t n_lines, char* out,
                             std::size_t cap) {
  Writer w{out, cap};
  w.head(echo, "00");
  for (std::size_t i = 0; i < n_lines; ++i) {
    const std::size_t len = std::strlen(lines[i]);
    w.put(lines[i], len);
    w.put(';');
    w.put(scip_sum(lines[i], len));
    w.put('\n');
  }
  w.put('\n');
  return w.done();
}

std::size_t encode_scip_scan(const char* echo, std::uint32_t timestamp_ms, const std::uint32_t* ranges_mm,
                             const std::uint32_t* intensity, std::size_t count, std::size_t chars, char* out,
                             std::size_t cap) {
  if (chars != 2 && chars != 3) return 0;
  Writer w{out, cap};
  w.head(echo, "99");
  char ts[4];
  scip_encode(timestamp_ms & 0xFFFFFF, 4, ts);
  w.line(ts, 4);
  char block[64];
  std::size_t fill = 0;
  auto emit = [&](std::uint32_t v) {
    const std::uint32_t max = chars == 2 ? 0xFFF : 0x3FFFF;
    char c[3];
    scip_encode(v > max ? max : v, chars, c);
    for (std::size_t k = 0; k < chars; ++k) {
      block[fill++] = c[k];
      if (fill == sizeof(block)) {
        w.line(block, fill);
        fill = 0;
      }
    }
  };
  for (std::size_t i = 0; i < count; ++i) {
    emit(ranges_mm[i]);
    if (intensity) emit(intensity[i]);
  }
  if (fill > 0) w.line(block, fill);
  w.put('\n');
  return w.done();
}

}  // namespace hal_serial
