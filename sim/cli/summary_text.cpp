// The summary line and story of a run (declared in sim_runner.h) and the phrases they share.
#include "sim/cli/summary_text.h"

#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "sim/common/reason_list.h"

namespace sim {

std::string fmt(const char* f, ...) {
  char b[512];
  va_list ap;
  va_start(ap, f);
  std::vsnprintf(b, sizeof(b), f, ap);
  va_end(ap);
  return b;
}

std::string final_error_text(const SimSummary& s) {
  if (s.final_pose_step < 0) return "final error: none (no step with a pose)";
  if (!std::isfinite(s.final_err_m)) {
    return fmt("final pose: step %ld (%s), no ground truth", s.final_pose_step, s.final_pose_status.c_str());
  }
  return fmt("final error %.2f m / %.1f deg (step %ld, %s)", s.final_err_m, s.final_err_deg, s.final_pose_step,
             s.final_pose_status.c_str());
}

std::string availability_text(const SimSummary& s) {
  if (!std::isfinite(s.availability)) return "availability n/a";
  std::string t = fmt("availability %.1f %% (%zu/%zu steps after the fix", 100.0 * s.availability,
                      s.availability_localized, s.availability_steps);
  if (s.unknown_area_steps > 0) t += fmt(", %zu in unknown area left out", s.unknown_area_steps);
  if (s.carried_steps > 0) t += fmt(", %zu carried until the re-fix left out", s.carried_steps);
  t += ")";
  // Where it went (the reason published with each step that was not `localized`).
  const std::string why = reason_list(s.unavailable_by_reason);
  if (!why.empty()) t += " [not localized: " + why + "]";
  return t;
}

std::string pl_text(const SimSummary& s) {
  if (s.pl_steps == 0) return "protection level: none published";
  std::string t = fmt("protection level median %.2f m / %.1f deg, max %.2f m / %.1f deg", s.pl_xy_m_p50,
                      s.pl_theta_deg_p50, s.pl_xy_m_max, s.pl_theta_deg_max);
  if (s.pl_scored > 0) {
    t += fmt(", exceeded %zu/%zu (%.2f %%)", s.pl_exceeded, s.pl_scored, 100.0 * s.pl_exceedance_rate);
    if (s.pl_not_judged > 0) t += fmt(" + %zu not judged", s.pl_not_judged);
  }
  return t;
}

// Steps beyond the integrity limits against a log reference, but not beyond them plus the
// reference's own error bound between its corrected poses, or not against the map's pose for the
// scan where the map explains it clearly better (reference_judge.h): not judged, said so.
std::string truth_bound_text(const SimSummary& s) {
  if (s.integrity_not_judged == 0) return "";
  return fmt(" + %zu not judged (within the reference's own error bound, or cleared by the map's pose)",
             s.integrity_not_judged);
}

std::string kidnap_text(const SimSummary& s) {
  std::string t = fmt("kidnap at step %ld", s.kidnap_step);
  if (s.kidnap_detected_step < 0) return t + ": never detected (localized to the end)";
  t += fmt(": detected after %ld steps", s.kidnap_detection_delay_steps);
  if (s.relocalized_step < 0) return t + ", no re-fix before the end";
  return t + fmt(", re-fixed after %.1f m / %.1f s", s.refix_travelled_m, s.refix_s);
}

namespace {

// --transport hokuyo|rplidar: the driver's common counters (hal_serial::SerialLaserCounters).
std::string serial_lidar_text(const SimSummary& s) {
  const TransportStats& t = s.transport_stats;
  std::string x = fmt("transport %s: %llu scans sent, %llu dropped + %llu corrupted by fault injection; driver: %u scans, "
                      "%u checksum errors, %u dropped, %u bad measurements, %u handshakes again",
                      s.transport.c_str(), static_cast<unsigned long long>(t.scans_sent),
                      static_cast<unsigned long long>(t.frames_dropped), static_cast<unsigned long long>(t.frames_corrupted),
                      t.serial.scans, t.serial.checksum_errors, t.serial.dropped, t.serial.bad_measurements,
                      t.serial.device_restarts);
  if (!t.serial_handshake_error.empty()) x += "; start-up handshake failed: " + t.serial_handshake_error;
  return x;
}

}  // namespace

std::string transport_text(const SimSummary& s) {
  if (s.transport == "none") return {};
  if (s.transport == "hokuyo" || s.transport == "rplidar") return serial_lidar_text(s);
  const TransportStats& t = s.transport_stats;
  if (s.transport == "sick") {
    const std::uint64_t lost = t.scans_sent > t.sick_scans ? t.scans_sent - t.sick_scans : 0;
    return fmt("transport sick: %llu telegrams, %llu dropped + %llu corrupted by fault injection; driver: %u scans ok, "
               "%llu dropped (CRC %u, bad length %u, garbage bytes %u, bad measurements %u)",
               static_cast<unsigned long long>(t.telegrams_sent), static_cast<unsigned long long>(t.frames_dropped),
               static_cast<unsigned long long>(t.frames_corrupted), t.sick_scans, static_cast<unsigned long long>(lost),
               t.sick_crc_errors, t.sick_bad_length, t.sick_garbage_bytes, t.sick_bad_measurements);
  }
  std::string x = fmt("transport %s: %llu frames, %llu dropped + %llu corrupted by fault injection; decoder: %u scans ok, "
                      "%u dropped (CRC %u, lost segments %u, malformed %u), %u odometry ok, %u broken records",
                      s.transport.c_str(), static_cast<unsigned long long>(t.frames_sent),
                      static_cast<unsigned long long>(t.frames_dropped), static_cast<unsigned long long>(t.frames_corrupted),
                      t.decoder.scans_ok, t.decoder.scans_dropped, t.decoder.crc_errors, t.decoder.lost_segments,
                      t.decoder.malformed, t.decoder.odometry_ok, t.decoder.broken_records);
  if (t.encode_failed > 0) x += fmt(", %llu not encodable", static_cast<unsigned long long>(t.encode_failed));
  if (t.bus_full > 0) x += fmt(", %llu refused by a full bus", static_cast<unsigned long long>(t.bus_full));
  return x;
}

std::string summary_line(const SimSummary& s) {
  std::string t = "mml-sim summary: " + s.source + ", " + s.localizer + ", " + std::to_string(s.steps) + " steps: ";
  if (s.first_localized_step >= 0) {
    t += fmt("first fix at step %ld (%.1f s, %.1f m)", s.first_localized_step, s.first_localized_t,
             s.first_localized_travelled_m);
  } else {
    t += "no fix";
  }
  t += "; " + availability_text(s);
  t += fmt("; integrity failures %zu (> %.1f m or > %.0f deg)", s.integrity_failures, kIntegrityLimitM,
           kIntegrityLimitDeg);
  t += truth_bound_text(s);
  t += "; " + pl_text(s);
  if (std::isfinite(s.tracking_err_m_p50)) {
    t += fmt("; tracking error median %.3f m, p95 %.3f m", s.tracking_err_m_p50, s.tracking_err_m_p95);
  }
  if (s.kidnap_step >= 0) t += "; " + kidnap_text(s);
  t += fmt("; step p50 %.2f ms, p99 %.2f ms", s.step_ms_p50, s.step_ms_p99);
  t += "; " + final_error_text(s);
  if (s.transport != "none") t += "; " + transport_text(s);
  return t;
}

std::string summary_story(const SimSummary& s) {
  std::string t;
  if (s.first_localized_step < 0) {
    t += fmt("  no fix in %zu steps (%.1f m driven)\n", s.steps, s.path_length_m);
  } else {
    t += fmt("  first fix at step %ld after %.1f s and %.1f m", s.first_localized_step, s.first_localized_t,
             s.first_localized_travelled_m);
    if (std::isfinite(s.first_localized_err_m)) t += fmt(", error %.2f m", s.first_localized_err_m);
    if (std::isfinite(s.first_localized_pl_xy_m)) t += fmt(", protection level %.2f m", s.first_localized_pl_xy_m);
    t += "\n  then: " + availability_text(s);
    if (std::isfinite(s.tracking_err_m_p50)) {
      t += fmt("; error while localized median %.3f m, p95 %.3f m (%.2f / %.2f deg)", s.tracking_err_m_p50,
               s.tracking_err_m_p95, s.tracking_err_deg_p50, s.tracking_err_deg_p95);
    }
    t += "\n";
  }
  if (s.kidnap_step >= 0) {
    t += fmt("  kidnapped at step %ld", s.kidnap_step);
    if (std::isfinite(s.kidnap_jump_m)) t += fmt(" (carried %.1f m; the odometry saw nothing)", s.kidnap_jump_m);
    if (s.kidnap_detected_step < 0) {
      t += ": never detected, localized to the end";
    } else {
      t += fmt(": not localized from step %ld (detected after %ld steps)", s.kidnap_detected_step,
               s.kidnap_detection_delay_steps);
      if (s.relocalized_step < 0) {
        t += "; no re-fix before the end of the run";
      } else {
        t += fmt("; localized again at step %ld after %.1f m / %.1f s", s.relocalized_step, s.refix_travelled_m,
                 s.refix_s);
        if (std::isfinite(s.refix_err_m)) t += fmt(", error %.2f m", s.refix_err_m);
      }
    }
    t += "\n";
  }
  t += fmt("  integrity: %zu of %zu localized steps off by > %.1f m or > %.0f deg", s.integrity_failures,
           s.localized_steps, kIntegrityLimitM, kIntegrityLimitDeg);
  if (s.integrity_failures_kidnap > 0) t += fmt(" (%zu before the kidnap was detected)", s.integrity_failures_kidnap);
  t += truth_bound_text(s);
  t += "; " + pl_text(s) + "\n";
  t += "  " + final_error_text(s) + "\n";
  if (s.transport != "none") t += "  " + transport_text(s) + "\n";
  return t;
}

}  // namespace sim
