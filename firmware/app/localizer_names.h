// The localizers the start-up builder (system.h) can build, by their config / command-line names.
#pragma once

#include <cstring>

namespace fw {

constexpr const char* kDefaultLocalizer = "mml-track";
constexpr const char* kLocalizerNames[] = {"mml-track", "mml", "handoff", "mcl", "odom"};
// For messages.
constexpr const char* kKnownLocalizers = "mml-track, mml, handoff, mcl, odom";

inline bool is_known_localizer(const char* name) {
  if (name == nullptr) return false;
  for (const char* n : kLocalizerNames)
    if (std::strcmp(n, name) == 0) return true;
  return false;
}

}  // namespace fw
