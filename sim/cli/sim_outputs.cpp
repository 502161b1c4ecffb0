// The table and the figures of a run as files: steps.csv and summary.json (declared in sim_runner.h).
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "sim/cli/sim_runner.h"
#include "sim/common/units.h"

namespace sim {

namespace {

// --transport: what went over the simulated bus and what the firmware's decoder made of it.
void write_transport_json(std::FILE* f, const SimSummary& s) {
  const TransportStats& t = s.transport_stats;
  const hal_can::DecoderStats& d = t.decoder;
  auto u = [](std::uint64_t v) { return static_cast<unsigned long long>(v); };
  std::fprintf(f, "  \"transport\": \"%s\",\n", s.transport.c_str());
  std::fprintf(f, "  \"transport_scans_sent\": %llu,\n  \"transport_odometry_sent\": %llu,\n  \"transport_frames_sent\": %llu,\n",
               u(t.scans_sent), u(t.odometry_sent), u(t.frames_sent));
  std::fprintf(f, "  \"transport_encode_failed\": %llu,\n  \"transport_bus_full\": %llu,\n", u(t.encode_failed),
               u(t.bus_full));
  std::fprintf(f, "  \"transport_faults_frames_dropped\": %llu,\n  \"transport_faults_frames_corrupted\": %llu,\n",
               u(t.frames_dropped), u(t.frames_corrupted));
  std::fprintf(f, "  \"decoder_frames\": %llu,\n  \"decoder_scans_ok\": %llu,\n  \"decoder_scans_dropped\": %llu,\n",
               u(d.frames), u(d.scans_ok), u(d.scans_dropped));
  std::fprintf(f, "  \"decoder_crc_errors\": %llu,\n  \"decoder_lost_segments\": %llu,\n  \"decoder_malformed\": %llu,\n",
               u(d.crc_errors), u(d.lost_segments), u(d.malformed));
  std::fprintf(f, "  \"decoder_orphan_segments\": %llu,\n  \"decoder_unknown_ids\": %llu,\n  \"decoder_invalid_scans\": %llu,\n",
               u(d.orphan_segments), u(d.unknown_ids), u(d.invalid_scans));
  std::fprintf(f, "  \"decoder_odometry_ok\": %llu,\n  \"decoder_broken_records\": %llu,\n", u(d.odometry_ok),
               u(d.broken_records));
  std::fprintf(f, "  \"sick_telegrams_sent\": %llu,\n  \"sick_parser_telegrams\": %llu,\n  \"sick_crc_errors\": %llu,\n",
               u(t.telegrams_sent), u(t.sick_telegrams), u(t.sick_crc_errors));
  std::fprintf(f, "  \"sick_bad_length\": %llu,\n  \"sick_garbage_bytes\": %llu,\n  \"sick_scans_ok\": %llu,\n",
               u(t.sick_bad_length), u(t.sick_garbage_bytes), u(t.sick_scans));
  std::fprintf(f, "  \"sick_bad_measurements\": %llu,\n  \"sick_scans_dropped\": %llu\n", u(t.sick_bad_measurements),
               u(t.scans_sent > t.sick_scans ? t.scans_sent - t.sick_scans : 0));
}

}  // namespace

bool write_steps_csv(const std::string& path, const std::vector<StepRecord>& steps, std::string* err) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    *err = "cannot write '" + path + "'";
    return false;
  }
  std::fprintf(f,
               "step,t_s,scan_id,status,mode,x,y,theta,truth_x,truth_y,truth_theta,err_m,err_deg,travelled_m,"
               "hypotheses,clusters,rating,odom_x,odom_y,odom_theta,cov_xx,cov_yy,cov_tt,step_ms,kidnapped,"
               "pl_xy_m,pl_theta_deg,unsupported_steps,in_unknown,truth_bound_m,truth_bound_deg,map_err_m,map_err_deg,reason,wait_cause\n");
  for (const StepRecord& s : steps) {
    const hal::PoseEstimate& e = s.estimate;
    std::fprintf(f, "%u,%.3f,%u,%s,%s,%.4f,%.4f,%.5f,", s.step, s.t, e.scan_id, hal::status_name(e.status),
                 e.mode == hal::LocalizationMode::kTracking ? "tracking" : "global", e.x, e.y, e.theta);
    if (s.has_truth) {
      std::fprintf(f, "%.4f,%.4f,%.5f,", s.truth.x, s.truth.y, s.truth.theta);
    } else {
      std::fprintf(f, ",,,");
    }
    // The error only where there is a pose to score (never from a placeholder).
    if (std::isfinite(s.err_m) && std::isfinite(s.err_deg)) {
      std::fprintf(f, "%.4f,%.3f,", s.err_m, s.err_deg);
    } else {
      std::fprintf(f, ",,");
    }
    std::fprintf(f, "%.3f,%u,%u,%.4f,%.4f,%.4f,%.5f,%.6g,%.6g,%.6g,%.4f,%d,", s.travelled_m, e.hypothesis_count,
                 e.cluster_count, e.rating, s.odom.x, s.odom.y, s.odom.theta, e.cov[0], e.cov[4], e.cov[8], s.step_ms,
                 s.kidnapped ? 1 : 0);
    // Protection level: empty when none was published (0).
    if (e.protection_xy_m > 0 || e.protection_theta_rad > 0) {
      std::fprintf(f, "%.4f,%.3f,", e.protection_xy_m, e.protection_theta_rad * kRadToDeg);
    } else {
      std::fprintf(f, ",,");
    }
    std::fprintf(f, "%u,%d,", e.unsupported_steps, s.in_unknown ? 1 : 0);
    // The truth's own error bound (inf where a log reference is extrapolated); empty without truth.
    if (s.has_truth) {
      std::fprintf(f, "%.4f,%.3f,", s.truth_bound_m, s.truth_bound_deg);
    } else {
      std::fprintf(f, ",,");
    }
    // The error against the map's pose for the scan, where the map explains it clearly better than
    // the log reference (asked only at steps beyond a limit: reference_judge.h).
    if (s.map_checked && s.map_pose_better) {
      std::fprintf(f, "%.4f,%.3f,", s.map_err_m, s.map_err_deg);
    } else {
      std::fprintf(f, ",,");
    }
    // Why not `localized` (none when it is), and what the wait for MML's word is charged to.
    std::fprintf(f, "%s,%s\n", hal::reason_name(e.reason), s.wait_cause);
  }
  const bool ok = std::fclose(f) == 0;
  if (!ok) *err = "error writing '" + path + "'";
  return ok;
}

bool write_summary_json(const std::string& path, const SimSummary& s, std::string* err) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    *err = "cannot write '" + path + "'";
    return false;
  }
  auto num = [](double v) {
    char b[48];
    if (!std::isfinite(v)) return std::string("null");
    std::snprintf(b, sizeof(b), "%.6g", v);
    return std::string(b);
  };
  std::fprintf(f, "{\n  \"source\": \"%s\",\n  \"localizer\": \"%s\",\n  \"steps\": %zu,\n", s.source.c_str(),
               s.localizer.c_str(), s.steps);
  std::fprintf(f, "  \"first_localized_step\": %ld,\n  \"first_localized_t_s\": %s,\n", s.first_localized_step,
               s.first_localized_step >= 0 ? num(s.first_localized_t).c_str() : "null");
  std::fprintf(f, "  \"first_localized_travelled_m\": %s,\n  \"first_localized_err_m\": %s,\n",
               s.first_localized_step >= 0 ? num(s.first_localized_travelled_m).c_str() : "null",
               s.first_localized_step >= 0 ? num(s.first_localized_err_m).c_str() : "null");
  std::fprintf(f, "  \"first_localized_pl_xy_m\": %s,\n", num(s.first_localized_pl_xy_m).c_str());
  std::fprintf(f, "  \"availability\": %s,\n  \"availability_steps\": %zu,\n  \"availability_localized_steps\": %zu,\n",
               num(s.availability).c_str(), s.availability_steps, s.availability_localized);
  std::fprintf(f, "  \"availability_carried_steps\": %zu,\n", s.carried_steps);
  std::fprintf(f, "  \"unavailable_by_reason\": {");
  for (std::size_t k = 1; k < hal::kStatusReasonCount; ++k) {
    std::fprintf(f, "%s\"%s\": %zu", k > 1 ? ", " : "", hal::reason_name(static_cast<hal::StatusReason>(k)),
                 s.unavailable_by_reason[k]);
  }
  std::fprintf(f, "},\n");
  std::fprintf(f, "  \"unknown_area_steps_excluded\": %zu,\n", s.unknown_area_steps);
  std::fprintf(f, "  \"integrity_failures\": %zu,\n  \"integrity_failures_before_kidnap_detection\": %zu,\n",
               s.integrity_failures, s.integrity_failures_kidnap);
  std::fprintf(f, "  \"first_integrity_failure_step\": %ld,\n  \"integrity_limit_m\": %s,\n  \"integrity_limit_deg\": %s,\n",
               s.first_integrity_failure_step, num(kIntegrityLimitM).c_str(), num(kIntegrityLimitDeg).c_str());
  std::fprintf(f, "  \"integrity_not_judged_steps\": %zu,\n  \"pl_not_judged_steps\": %zu,\n",
               s.integrity_not_judged, s.pl_not_judged);
  std::fprintf(f, "  \"pl_steps\": %zu,\n  \"pl_scored_steps\": %zu,\n  \"pl_exceeded_steps\": %zu,\n  \"pl_exceedance_rate\": %s,\n",
               s.pl_steps, s.pl_scored, s.pl_exceeded, num(s.pl_exceedance_rate).c_str());
  std::fprintf(f, "  \"pl_xy_m_p50\": %s,\n  \"pl_xy_m_max\": %s,\n  \"pl_theta_deg_p50\": %s,\n  \"pl_theta_deg_max\": %s,\n",
               num(s.pl_xy_m_p50).c_str(), num(s.pl_xy_m_max).c_str(), num(s.pl_theta_deg_p50).c_str(),
               num(s.pl_theta_deg_max).c_str());
  std::fprintf(f, "  \"tracking_steps\": %zu,\n  \"tracking_err_m_p50\": %s,\n  \"tracking_err_m_p95\": %s,\n",
               s.tracking_steps, num(s.tracking_err_m_p50).c_str(), num(s.tracking_err_m_p95).c_str());
  std::fprintf(f, "  \"tracking_err_deg_p50\": %s,\n  \"tracking_err_deg_p95\": %s,\n", num(s.tracking_err_deg_p50).c_str(),
               num(s.tracking_err_deg_p95).c_str());
  std::fprintf(f, "  \"kidnap_step\": %ld,\n  \"kidnap_jump_m\": %s,\n  \"kidnap_detected_step\": %ld,\n", s.kidnap_step,
               num(s.kidnap_jump_m).c_str(), s.kidnap_detected_step);
  std::fprintf(f, "  \"kidnap_detection_delay_steps\": %ld,\n  \"relocalized_step\": %ld,\n",
               s.kidnap_detection_delay_steps, s.relocalized_step);
  std::fprintf(f, "  \"refix_travelled_m\": %s,\n  \"refix_s\": %s,\n  \"refix_err_m\": %s,\n", num(s.refix_travelled_m).c_str(),
               num(s.refix_s).c_str(), num(s.refix_err_m).c_str());
  std::fprintf(f, "  \"localized_steps\": %zu,\n  \"wrong_localized_steps\": %zu,\n", s.localized_steps,
               s.wrong_localized_steps);
  std::fprintf(f, "  \"mean_err_localized_m\": %s,\n  \"max_err_localized_m\": %s,\n", num(s.mean_err_localized_m).c_str(),
               num(s.max_err_localized_m).c_str());
  std::fprintf(f, "  \"final_err_m\": %s,\n  \"final_err_deg\": %s,\n  \"final_pose_step\": %ld,\n  \"final_pose_status\": %s,\n",
               num(s.final_err_m).c_str(), num(s.final_err_deg).c_str(), s.final_pose_step,
               s.final_pose_step >= 0 ? ("\"" + s.final_pose_status + "\"").c_str() : "null");
  const char* names[5] = {"searching", "ambiguous", "localized", "outside_map", "fault"};
  for (int i = 0; i < 5; ++i) std::fprintf(f, "  \"steps_%s\": %zu,\n", names[i], s.status_counts[i]);
  std::fprintf(f, "  \"step_ms_mean\": %s,\n  \"step_ms_p50\": %s,\n  \"step_ms_p99\": %s,\n  \"step_ms_max\": %s,\n",
               num(s.step_ms_mean).c_str(), num(s.step_ms_p50).c_str(), num(s.step_ms_p99).c_str(),
               num(s.step_ms_max).c_str());
  std::fprintf(f, "  \"path_length_m\": %s,\n  \"load_s\": %s,\n  \"wall_s\": %s,\n  \"scans_per_s\": %s,\n",
               num(s.path_length_m).c_str(), num(s.load_s).c_str(), num(s.wall_s).c_str(), num(s.scans_per_s).c_str());
  std::fprintf(f, "  \"scans_dropped\": %zu,\n  \"ring_drops\": %llu,\n  \"odom_rejected\": %llu,\n", s.scans_dropped,
               static_cast<unsigned long long>(s.ring_drops), static_cast<unsigned long long>(s.odom_rejected));
  std::fprintf(f, "  \"scans_restamped\": %zu,\n  \"deadline_misses\": %llu,\n", s.scans_restamped,
               static_cast<unsigned long long>(s.deadline_misses));
  std::fprintf(f, "  \"scans_held\": %llu,\n  \"step_errors\": %llu,\n", static_cast<unsigned long long>(s.scans_held),
               static_cast<unsigned long long>(s.step_errors));
  write_transport_json(f, s);
  std::fprintf(f, "}\n");
  const bool ok = std::fclose(f) == 0;
  if (!ok) *err = "error writing '" + path + "'";
  return ok;
}

}  // namespace sim
