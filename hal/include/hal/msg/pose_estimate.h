// PoseEstimate: what the firmware publishes: pose in the map frame, its covariance and whether the
// localizer is sure (the product's promise is to say *when* it is sure).
#pragma once

#include <cstdint>

namespace hal {

enum class LocalizationStatus : std::uint8_t {
  kSearching = 0,   // no hypothesis yet / too little local map
  kAmbiguous = 1,   // several candidate poses, none isolated
  kLocalized = 2,   // constraints met (Eq. 5.17): the pose is isolated
  kOutsideMap = 3,  // robot is in an area the global map does not contain (Eq. 5.37)
  kFault = 4,       // internal fault; pose invalid
};

enum class LocalizationMode : std::uint8_t {
  kGlobal = 0,    // MML global localization
  kTracking = 1,  // tracking against the global map after a fix (mml-track: scan-to-map; handoff: MCL)
};

const char* status_name(LocalizationStatus s);

struct PoseEstimate {
  std::uint64_t timestamp_ns = 0;  // time of the scan this estimate belongs to
  std::uint32_t scan_id = 0;
  float x = 0.0f, y = 0.0f, theta = 0.0f;  // map frame
  float cov[9] = {};                       // row-major 3×3 (x, y, θ)
  LocalizationStatus status = LocalizationStatus::kSearching;
  LocalizationMode mode = LocalizationMode::kGlobal;
  std::uint16_t hypothesis_count = 0;
  std::uint16_t cluster_count = 0;
  float rating = 0.0f;  // normalised rating r of the best cluster (Eq. 5.7)
  // Protection level (RAIM style, firmware/track/protection_level.h): the true horizontal error
  // exceeds protection_xy_m, or the heading error protection_theta_rad, in at most 1 of 1000
  // `localized` steps. 0 = no bound (status not localized, or a localizer without integrity monitor).
  float protection_xy_m = 0.0f;
  float protection_theta_rad = 0.0f;
  // Consecutive scans since a scan last confirmed the pose (0 = this scan did).
  std::uint16_t unsupported_steps = 0;
};

inline const char* status_name(LocalizationStatus s) {
  switch (s) {
    case LocalizationStatus::kSearching: return "searching";
    case LocalizationStatus::kAmbiguous: return "ambiguous";
    case LocalizationStatus::kLocalized: return "localized";
    case LocalizationStatus::kOutsideMap: return "outside-map";
    case LocalizationStatus::kFault: return "fault";
  }
  return "unknown";
}

}  // namespace hal
