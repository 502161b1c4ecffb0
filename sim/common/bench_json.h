// BenchJson: collects named figures and writes the flat JSON object scripts/bench.sh expects
// (build/bench/NAME.json), keeping insertion order; also echoes each figure to stdout.
#pragma once

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace sim {

class BenchJson {
 public:
  void add(const std::string& key, double value) {
    char buf[64];
    if (!std::isfinite(value)) {
      std::snprintf(buf, sizeof(buf), "null");
    } else {
      std::snprintf(buf, sizeof(buf), "%.6g", value);
    }
    put(key, buf);
  }
  void add_int(const std::string& key, long long value) { put(key, std::to_string(value)); }
  void add_bool(const std::string& key, bool value) { put(key, value ? "true" : "false"); }
  void add_string(const std::string& key, const std::string& value) { put(key, quoted(value)); }
  // An already formatted JSON value (merging a file another benchmark wrote).
  void add_raw(const std::string& key, const std::string& json) { put(key, json); }

  bool write(const std::string& path) const {
    std::ofstream out(path);
    if (!out) {
      std::fprintf(stderr, "bench: cannot write %s\n", path.c_str());
      return false;
    }
    out << "{\n";
    for (size_t i = 0; i < items_.size(); ++i) {
      out << "  " << quoted(items_[i].first) << ": " << items_[i].second << (i + 1 < items_.size() ? ",\n" : "\n");
    }
    out << "}\n";
    return static_cast<bool>(out);
  }

  // A JSON string literal (RFC 8259 §7): quotes, backslashes and control characters escaped, so a
  // path or an error message with any of them still gives a file every JSON reader accepts.
  static std::string quoted(const std::string& s) {
    std::string o = "\"";
    for (const char ch : s) {
      const unsigned char c = static_cast<unsigned char>(ch);
      if (c == '"' || c == '\\') {
        o += '\\';
        o += ch;
      } else if (c == '\n') {
        o += "\\n";
      } else if (c == '\t') {
        o += "\\t";
      } else if (c < 0x20) {
        char buf[8];
        std::snprintf(buf, sizeof(buf), "\\u%04x", c);
        o += buf;
      } else {
        o += ch;
      }
    }
    return o + "\"";
  }

 private:
  void put(const std::string& key, const std::string& json) {
    std::printf("  %-36s %s\n", key.c_str(), json.c_str());
    for (auto& kv : items_) {
      if (kv.first == key) { kv.second = json; return; }
    }
    items_.emplace_back(key, json);
  }
  std::vector<std::pair<std::string, std::string>> items_;
};

}  // namespace sim
