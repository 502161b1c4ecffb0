// "name n, name n, …": the steps that were not `localized`, counted by the reason published with
// them (hal::StatusReason), largest first (ties in code order), reasons never seen left out. With
// `denominator` > 0 each count is printed as its share (3 decimals) instead. Used by mml-sim's
// summary line and mml-eval's localize.md ("where the availability went").
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>

#include "hal/msg/pose_estimate.h"

namespace sim {

inline std::string reason_list(const std::size_t (&counts)[hal::kStatusReasonCount], std::size_t denominator = 0) {
  std::string out;
  bool used[hal::kStatusReasonCount] = {};
  for (;;) {
    std::size_t best = hal::kStatusReasonCount, n = 0;
    for (std::size_t k = 0; k < hal::kStatusReasonCount; ++k) {
      if (!used[k] && counts[k] > n) {
        n = counts[k];
        best = k;
      }
    }
    if (best == hal::kStatusReasonCount) return out;
    used[best] = true;
    char buf[96];
    const char* name = hal::reason_name(static_cast<hal::StatusReason>(best));
    if (denominator > 0) {
      std::snprintf(buf, sizeof(buf), "%s%s %.3f", out.empty() ? "" : ", ", name,
                    static_cast<double>(n) / static_cast<double>(denominator));
    } else {
      std::snprintf(buf, sizeof(buf), "%s%s %zu", out.empty() ? "" : ", ", name, n);
    }
    out += buf;
  }
}

}  // namespace sim
