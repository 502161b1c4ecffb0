#include "sim/localizers/localizer_context.h"

#include <algorithm>

namespace sim {

std::string unknown_option_keys(const std::string& localizer, const std::map<std::string, std::string>& options,
                                const std::vector<std::string>& known) {
  std::string bad;
  for (const auto& [k, v] : options) {
    if (std::find(known.begin(), known.end(), k) == known.end()) bad += (bad.empty() ? "" : ", ") + k;
  }
  if (bad.empty()) return {};
  std::string list;
  for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
  return "localizer " + localizer + ": unknown option(s) " + bad + " (known: " + (list.empty() ? "none" : list) + ")";
}

}  // namespace sim
