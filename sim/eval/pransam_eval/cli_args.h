// `--key value` / `--flag` arguments of the pRANSAM evaluation CLIs (mml-pransam-eval, mml-pransam-pcl).
#pragma once

#include <map>
#include <string>

namespace sim::pransam_eval {

inline std::map<std::string, std::string> parse(int argc, char** argv, int first) {
  std::map<std::string, std::string> a;
  for (int i = first; i < argc; ++i) {
    std::string k = argv[i];
    if (k.rfind("--", 0) != 0) continue;
    k = k.substr(2);
    if (i + 1 < argc && std::string(argv[i + 1]).rfind("--", 0) != 0) a[k] = argv[++i]; else a[k] = "1";
  }
  return a;
}

inline std::string get(const std::map<std::string, std::string>& a, const std::string& k, const std::string& d) {
  auto it = a.find(k);
  return it == a.end() ? d : it->second;
}

}  // namespace sim::pransam_eval
