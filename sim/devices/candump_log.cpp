#include "sim/devices/candump_log.h"

#include "sim/io/file_io.h"

#include <cstdio>
#include <cstdlib>
#include <fstream>

namespace sim {
namespace {
int hexval(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}
}  // namespace

std::string format_candump_line(double t, const std::string& iface, const hal::CanFrame& f) {
  char buf[256];
  int n = std::snprintf(buf, sizeof(buf), "(%.6f) %s ", t, iface.c_str());
  if (f.extended) {
    n += std::snprintf(buf + n, sizeof(buf) - n, "%08X", f.id & 0x1FFFFFFFu);
  } else {
    n += std::snprintf(buf + n, sizeof(buf) - n, "%03X", f.id & 0x7FFu);
  }
  if (f.fd) {
    n += std::snprintf(buf + n, sizeof(buf) - n, "##%X", f.brs ? 1 : 0);
  } else {
    n += std::snprintf(buf + n, sizeof(buf) - n, "#");
  }
  for (int i = 0; i < f.len; ++i) n += std::snprintf(buf + n, sizeof(buf) - n, "%02X", f.data[i]);
  return std::string(buf, static_cast<size_t>(n));
}

std::string format_error_frame_line(double t, const std::string& iface, std::uint32_t err_class) {
  char buf[128];
  std::snprintf(buf, sizeof(buf), "(%.6f) %s %08X#0000000000000000", t, iface.c_str(),
                (kCanErrFlag | err_class) & 0x3FFFFFFFu);
  return buf;
}

bool parse_candump_line(const std::string& line, CanLogLine* out, std::string* error) {
  *out = CanLogLine{};
  size_t p = 0;
  if (line.empty() || line[0] != '(') { *error = "expected '(timestamp)'"; return false; }
  size_t close = line.find(')');
  if (close == std::string::npos) { *error = "unterminated timestamp"; return false; }
  char* end = nullptr;
  std::string ts = line.substr(1, close - 1);
  out->t = std::strtod(ts.c_str(), &end);
  if (end == ts.c_str() || *end) { *error = "bad timestamp '" + ts + "'"; return false; }
  p = close + 1;
  while (p < line.size() && line[p] == ' ') ++p;
  size_t sp = line.find(' ', p);
  if (sp == std::string::npos) { *error = "missing interface or frame"; return false; }
  out->iface = line.substr(p, sp - p);
  p = sp + 1;
  size_t hash = line.find('#', p);
  if (hash == std::string::npos) { *error = "missing '#'"; return false; }
  std::string id = line.substr(p, hash - p);
  if (id.size() != 3 && id.size() != 8) { *error = "CAN ID '" + id + "' must have 3 or 8 hex digits"; return false; }
  std::uint32_t v = 0;
  for (char c : id) {
    int h = hexval(c);
    if (h < 0) { *error = "bad hex in CAN ID '" + id + "'"; return false; }
    v = (v << 4) | static_cast<std::uint32_t>(h);
  }
  hal::CanFrame& f = out->frame;
  if (id.size() == 8) {
    if (v & kCanErrFlag) {
      out->error_frame = true;
      f.id = v & ~kCanErrFlag;
    } else {
      f.extended = true;
      f.id = v & 0x1FFFFFFFu;
    }
  } else {
    f.id = v;
  }
  p = hash + 1;
  size_t maxlen = 8;
  if (p < line.size() && line[p] == '#') {
    f.fd = true;
    maxlen = 64;
    ++p;
    if (p >= line.size() || hexval(line[p]) < 0) { *error = "CAN FD frame without flags digit"; return false; }
    f.brs = (hexval(line[p]) & 1) != 0;
    ++p;
  }
  std::string data = line.substr(p);
  while (!data.empty() && (data.back() == '\r' || data.back() == ' ')) data.pop_back();
  if (!data.empty() && data[0] == 'R') { *error = "remote frames are not part of the protocol"; return false; }
  if (data.size() % 2) { *error = "odd number of data hex digits"; return false; }
  if (data.size() / 2 > maxlen) { *error = "too many data bytes (" + std::to_string(data.size() / 2) + ")"; return false; }
  for (size_t i = 0; i < data.size(); i += 2) {
    int a = hexval(data[i]), b = hexval(data[i + 1]);
    if (a < 0 || b < 0) { *error = "bad hex in data"; return false; }
    f.data[i / 2] = static_cast<std::uint8_t>(a * 16 + b);
  }
  f.len = static_cast<std::uint8_t>(data.size() / 2);
  f.timestamp_ns = static_cast<std::uint64_t>(out->t * 1e9);
  return true;
}

bool read_candump_log(const std::string& path, std::vector<CanLogLine>* out, std::string* error) {
  // Regular files only (a FIFO would block, /dev/zero never end), at most 1 GiB.
  if (!check_regular_file(path, std::uint64_t(1) << 30, nullptr, error)) return false;
  std::ifstream in(path);
  if (!in) { *error = path + ": cannot open"; return false; }
  std::string line;
  size_t n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty()) continue;
    CanLogLine l;
    std::string e;
    if (!parse_candump_line(line, &l, &e)) {
      *error = path + ":" + std::to_string(n) + ": " + e;
      return false;
    }
    out->push_back(l);
  }
  return true;
}

}  // namespace sim
