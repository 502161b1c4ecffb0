// Wall-clock seconds and milliseconds for the host tools' timing figures (steady clock: never jumps).
#pragma once

#include <chrono>

namespace sim {

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

inline double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace sim
