// Reads a flat JSON object written by sim::BenchJson back into key → raw value pairs, so that the
// fault and soak benchmarks can each update their own keys of build/bench/faults.json.
#pragma once

#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace mmlfw_faults {

inline std::vector<std::pair<std::string, std::string>> read_flat_json(const std::string& path) {
  std::vector<std::pair<std::string, std::string>> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    const size_t q0 = line.find('"');
    const size_t q1 = q0 == std::string::npos ? q0 : line.find('"', q0 + 1);
    const size_t colon = q1 == std::string::npos ? q1 : line.find(':', q1);
    if (colon == std::string::npos) continue;
    std::string v = line.substr(colon + 1);
    while (!v.empty() && (v.back() == ',' || v.back() == ' ' || v.back() == '\r')) v.pop_back();
    while (!v.empty() && v.front() == ' ') v.erase(v.begin());
    out.emplace_back(line.substr(q0 + 1, q1 - q0 - 1), v);
  }
  return out;
}

inline bool write_flat_json(const std::string& path, const std::vector<std::pair<std::string, std::string>>& kv) {
  std::ofstream out(path);
  out << "{\n";
  for (size_t i = 0; i < kv.size(); ++i) {
    out << "  \"" << kv[i].first << "\": " << kv[i].second << (i + 1 < kv.size() ? ",\n" : "\n");
  }
  out << "}\n";
  return static_cast<bool>(out);
}

// Sets (or appends) the keys of `update` in `base`.
inline void merge_flat_json(std::vector<std::pair<std::string, std::string>>* base,
                            const std::vector<std::pair<std::string, std::string>>& update) {
  for (const auto& u : update) {
    bool found = false;
    for (auto& b : *base) {
      if (b.first == u.first) { b.second = u.second; found = true; }
    }
    if (!found) base->push_back(u);
  }
}

}  // namespace mmlfw_faults
