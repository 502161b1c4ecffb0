// Minimal reader for the flat JSON objects the HIL scripts write ("key": value pairs, one level),
// so that a benchmark can merge their figures into its own output (bench_json.h).
#pragma once

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "sim/common/bench_json.h"

namespace sim {

inline std::string read_all(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
inline bool json_value(const std::string& text, const std::string& key, std::string* out) {
  const std::string k = "\"" + key + "\":";
  size_t p = text.find(k);
  if (p == std::string::npos) return false;
  p += k.size();
  while (p < text.size() && text[p] == ' ') ++p;
  size_t e = p;
  while (e < text.size() && text[e] != ',' && text[e] != '}' && text[e] != '\n') ++e;
  *out = text.substr(p, e - p);
  return true;
}
inline void copy_num(sim::BenchJson& j, const std::string& text, const std::string& key, const std::string& as = "") {
  std::string v;
  const std::string name = as.empty() ? key : as;
  if (!json_value(text, key, &v) || v == "null") {
    j.add(name, std::nan(""));
  } else if (v == "true" || v == "false") {
    j.add_bool(name, v == "true");
  } else {
    j.add(name, std::strtod(v.c_str(), nullptr));
  }
}

}  // namespace sim
