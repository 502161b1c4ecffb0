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

// Why a pose is not `localized` (the product's silence explained; POSE layout 2 on CAN, the
// `reason` column of steps.csv). One reason per estimate; where several hold, the first of this
// order that applies: awaiting MML > fault > alias > beyond the alert limit > recovering.
enum class StatusReason : std::uint8_t {
  kNone = 0,             // localized (or not stated: a POSE record of layout < 2)
  kSearching = 1,        // global: local map too small, or no candidate pose
  kAmbiguous = 2,        // global: candidate poses, none isolated yet
  kFixRejected = 3,      // global: MML isolated a pose that the scan, checked on the map, did not confirm
  kOutsideMap = 4,       // the robot is in space the map does not contain
  kTrackFault = 5,       // tracked: this scan contradicts the pose (fit, innovation, odometry window)
  kTrackAlias = 6,       // tracked: the scan fits a rival pose as well (alias check)
  kTrackBeyondAlert = 7, // tracked: the protection level exceeds an alert limit
  kTrackRecovering = 8,  // tracked: too few consistent scans since the last fault or alias
  kTrackAwaitingMml = 9, // tracked: after a large fault (or a conflict), until MML isolates the tracked pose
  kFault = 10,           // internal fault
};
constexpr std::uint8_t kStatusReasonCount = 11;

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
  StatusReason reason = StatusReason::kNone;  // why not `localized` (kNone when it is)
};

// The reason a status implies by itself (for localizers that know no more: odometry, MCL, MML alone).
inline StatusReason reason_of_status(LocalizationStatus s) {
  switch (s) {
    case LocalizationStatus::kLocalized: return StatusReason::kNone;
    case LocalizationStatus::kSearching: return StatusReason::kSearching;
    case LocalizationStatus::kAmbiguous: return StatusReason::kAmbiguous;
    case LocalizationStatus::kOutsideMap: return StatusReason::kOutsideMap;
    case LocalizationStatus::kFault: return StatusReason::kFault;
  }
  return StatusReason::kFault;
}

// Every estimate that is not `localized` says why: the status's own reason unless a more specific one is set;
// a `localized` estimate has none.
inline void complete_reason(PoseEstimate* e) {
  if (e->status == LocalizationStatus::kLocalized) {
    e->reason = StatusReason::kNone;
  } else if (e->reason == StatusReason::kNone) {
    e->reason = reason_of_status(e->status);
  }
}

// Declared first in a Localizer's step(): whatever path step() returns by, its estimate says why
// it is not `localized` (complete_reason).
struct CompleteReasonOnExit {
  PoseEstimate* estimate;
  ~CompleteReasonOnExit() {
    if (estimate != nullptr) complete_reason(estimate);
  }
};

inline const char* reason_name(StatusReason r) {
  switch (r) {
    case StatusReason::kNone: return "none";
    case StatusReason::kSearching: return "searching";
    case StatusReason::kAmbiguous: return "ambiguous";
    case StatusReason::kFixRejected: return "fix-rejected";
    case StatusReason::kOutsideMap: return "outside-map";
    case StatusReason::kTrackFault: return "track-fault";
    case StatusReason::kTrackAlias: return "track-alias";
    case StatusReason::kTrackBeyondAlert: return "track-beyond-alert";
    case StatusReason::kTrackRecovering: return "track-recovering";
    case StatusReason::kTrackAwaitingMml: return "track-awaiting-mml";
    case StatusReason::kFault: return "fault";
  }
  return "unknown";
}

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
