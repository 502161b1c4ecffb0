// bench_sim: figures of issue 3 (scripts/bench.sh sim → build/bench/sim.json): scan records read
// from the logs in ../shared/data, the Kümmerle et al. 2009 relations metric of raw odometry and of
// the reference trajectory, PGM+YAML round trip, and log replay throughput (read + parse +
// conversion to hal::LaserScan).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "hal/msg/laser_scan.h"
#include "hal_sim/sim_sensor_io.h"
#include "sim/common/bench_json.h"
#include "sim/io/carmen_log.h"
#include "sim/io/datasets.h"
#include "sim/io/log_replay.h"
#include "sim/io/reference_trajectory.h"
#include "sim/io/relations.h"
#ifdef MMLFW_HAVE_SIM_MAP
#include "sim/io/ros_map.h"
#include "sim/common/cli_main.h"
#endif

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

bool read_log(const std::string& rel, sim::CarmenLog* log) {
  std::string err;
  if (!sim::read_carmen_log(sim::data_path(rel), {}, log, &err)) {
    std::fprintf(stderr, "bench_sim: %s\n", err.c_str());
    return false;
  }
  return true;
}

#ifdef MMLFW_HAVE_SIM_MAP
std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

// Occupancy-like image from the intel corrected log (scan endpoints occupied, poses' cells free,
// rest unknown) → write → read → compare every field and pixel → write again → identical bytes.
// Done for P5 and P2.
bool pgm_roundtrip(const std::string& dir, const sim::CarmenLog& corrected) {
  sim::RosMap m;
  m.resolution = 0.1;
  m.origin[0] = -25.0;
  m.origin[1] = -25.0;
  m.width = 500;
  m.height = 500;
  m.pixels.assign(static_cast<size_t>(m.width) * m.height, 205);
  auto put = [&](double x, double y, uint8_t v) {
    const int c = static_cast<int>(std::floor((x - m.origin[0]) / m.resolution));
    const int r = m.height - 1 - static_cast<int>(std::floor((y - m.origin[1]) / m.resolution));
    if (c >= 0 && c < m.width && r >= 0 && r < m.height) m.pixels[static_cast<size_t>(r) * m.width + c] = v;
  };
  for (const auto& s : corrected.scans) {
    put(s.pose.x, s.pose.y, 254);
    for (size_t b = 0; b < s.ranges.size(); ++b) {
      if (s.ranges[b] >= s.max_range || s.ranges[b] < 0.05f) continue;
      const double a = s.pose.theta + s.angle_min + static_cast<double>(b) * s.angle_increment;
      put(s.pose.x + s.ranges[b] * std::cos(a), s.pose.y + s.ranges[b] * std::sin(a), 0);
    }
  }
  bool all_ok = true;
  for (bool ascii : {false, true}) {
    m.pgm_ascii = ascii;
    const std::string yaml = dir + (ascii ? "/roundtrip_p2.yaml" : "/roundtrip_p5.yaml");
    m.image = ascii ? "roundtrip_p2.pgm" : "roundtrip_p5.pgm";
    std::string err;
    sim::RosMap back;
    if (!sim::write_ros_map(yaml, m, &err) || !sim::read_ros_map(yaml, &back, &err)) {
      std::fprintf(stderr, "bench_sim: pgm round trip: %s\n", err.c_str());
      return false;
    }
    const std::string pgm1 = slurp(dir + "/" + m.image), yaml1 = slurp(yaml);
    bool ok = back.width == m.width && back.height == m.height && back.pixels == m.pixels &&
              back.resolution == m.resolution && back.origin[0] == m.origin[0] && back.origin[1] == m.origin[1] &&
              back.origin[2] == m.origin[2] && back.negate == m.negate && back.occupied_thresh == m.occupied_thresh &&
              back.free_thresh == m.free_thresh && back.mode == m.mode && back.maxval == m.maxval &&
              back.pgm_ascii == m.pgm_ascii && back.image == m.image;
    if (!sim::write_ros_map(yaml, back, &err)) {
      std::fprintf(stderr, "bench_sim: pgm round trip: %s\n", err.c_str());
      return false;
    }
    ok = ok && slurp(dir + "/" + m.image) == pgm1 && slurp(yaml) == yaml1;
    std::printf("  pgm round trip %s: %s\n", ascii ? "P2" : "P5", ok ? "exact" : "MISMATCH");
    all_ok = all_ok && ok;
  }
  return all_ok;
}
#endif

}  // namespace

static int run_main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : "build/bench/sim.json";
  std::printf("bench_sim: data from %s\n", sim::data_dir().c_str());
  sim::BenchJson json;

  // Scan records per log (all raw logs).
  const struct {
    const char* dataset;
    const char* key;
  } logs[] = {{"intel", "intel_scans"},
              {"fr079", "fr079_scans"},
              {"aces", "aces_scans"},
              {"fr-clinic", "fr_clinic_scans"},
              {"mit-killian", "mit_killian_scans"}};
  sim::CarmenLog intel;
  for (const auto& l : logs) {
    const sim::Dataset& d = *sim::find_dataset(l.dataset);
    sim::CarmenLog log;
    if (!read_log(d.raw_log, &log)) return 1;
    json.add_int(l.key, static_cast<long long>(log.scans.size()));
    if (d.relations_match_log) {
      std::vector<sim::Relation> rel;
      std::string err;
      if (!sim::read_relations(sim::data_path(d.relations), &rel, &err)) {
        std::fprintf(stderr, "bench_sim: %s\n", err.c_str());
        return 1;
      }
      const sim::RelationsMetric m = sim::evaluate_relations(rel, sim::odometry_trajectory(log));
      std::string prefix = l.key;
      prefix = prefix.substr(0, prefix.size() - 6);  // strip "_scans"
      json.add(prefix + "_odom_trans_err", m.trans_mean);
      json.add(prefix + "_odom_rot_err_deg", m.rot_mean_deg);
      if (!d.corrected_poses.empty()) {
        std::vector<sim::CorrectedPose> cp;
        if (!sim::read_corrected_poses(sim::data_path(d.corrected_poses), &cp, &err)) {
          std::fprintf(stderr, "bench_sim: %s\n", err.c_str());
          return 1;
        }
        const auto ref = sim::make_trajectory(log, sim::reference_at_every_scan(log, cp));
        const sim::RelationsMetric mr = sim::evaluate_relations(rel, ref);
        json.add(prefix + "_reference_trans_err", mr.trans_mean);
        json.add(prefix + "_reference_rot_err_deg", mr.rot_mean_deg);
      }
    }
    if (std::strcmp(l.dataset, "intel") == 0) intel = std::move(log);
  }

  // intel in more detail (the headline figure).
  {
    std::vector<sim::Relation> rel;
    std::string err;
    if (!sim::read_relations(sim::data_path(sim::find_dataset("intel")->relations), &rel, &err)) return 1;
    const sim::RelationsMetric m = sim::evaluate_relations(rel, sim::odometry_trajectory(intel));
    json.add("intel_odom_trans_std", m.trans_std);
    json.add("intel_odom_trans2_err", m.trans2_mean);
    json.add("intel_odom_rot2_err_deg2", m.rot2_mean);
    json.add_int("intel_relations_used", static_cast<long long>(m.used));
  }

  // Parse speed and replay throughput: read + parse the gzip log, build the time-ordered event
  // stream, convert every record to its HAL message and pass it through the hal/sim rings
  // (SimLaserSource / SimOdometrySource, polled through the hal:: interfaces as the firmware does).
  // Best of 3 to damp the shared machine's noise.
  {
    const std::string path = sim::data_path(sim::find_dataset("intel")->raw_log);
    double best_parse = 1e9, best_replay = 1e9;
    double checksum = 0;
    size_t scans = 0;
    for (int rep = 0; rep < 3; ++rep) {
      const auto t0 = Clock::now();
      sim::CarmenLog log;
      std::string err;
      if (!sim::read_carmen_log(path, {}, &log, &err)) {
        std::fprintf(stderr, "bench_sim: %s\n", err.c_str());
        return 1;
      }
      best_parse = std::min(best_parse, seconds_since(t0));
      static hal_sim::SimLaserSource lasers;
      static hal_sim::SimOdometrySource odometry;
      hal::LaserScanSource& laser_if = lasers;
      hal::OdometrySource& odom_if = odometry;
      static hal::LaserScan msg;
      hal::Odometry odo;
      scans = 0;
      for (const auto& e : sim::make_replay_events(log)) {
        if (e.kind == sim::ReplayEvent::Kind::kScan) {
          lasers.push(sim::event_scan(log, e));
          while (laser_if.poll(&msg)) {
            checksum += msg.ranges[msg.beam_count / 2];
            ++scans;
          }
        } else {
          odometry.push(sim::event_odometry(log, e));
          while (odom_if.poll(&odo)) checksum += odo.x;
        }
      }
      best_replay = std::min(best_replay, seconds_since(t0));
      if (scans != log.scans.size() || lasers.stats().dropped != 0) {
        std::fprintf(stderr, "bench_sim: replay delivered %zu of %zu scans\n", scans, log.scans.size());
        return 1;
      }
    }
    json.add("intel_parse_s", best_parse);
    json.add("replay_scans_per_s", static_cast<double>(scans) / best_replay);
    std::printf("  (replay checksum %.3f)\n", checksum);
  }

#ifdef MMLFW_HAVE_SIM_MAP
  {
    sim::CarmenLog corrected;
    if (!read_log(sim::find_dataset("intel")->corrected_log, &corrected)) return 1;
    const std::string dir = std::filesystem::path(out).parent_path().string() + "/sim_tmp";
    std::filesystem::create_directories(dir);
    json.add_bool("pgm_roundtrip_exact", pgm_roundtrip(dir, corrected));
  }
#else
  std::printf("  pgm_roundtrip_exact: sim_map not built, figure omitted\n");
#endif

  return json.write(out) ? 0 : 1;
}

int main(int argc, char** argv) {
  return sim::guarded_main("bench_sim", [&] { return run_main(argc, argv); });
}
