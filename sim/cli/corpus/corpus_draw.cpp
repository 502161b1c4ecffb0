#include "sim/cli/corpus/corpus_draw.h"

#include <cmath>
#include <cstdio>

#include "firmware/base/rng.h"
#include "sim/world/odometry_profiles.h"
#include "sim/world/sensor_profiles.h"

namespace sim::corpus {

namespace {

double uniform(fw::RandomStream* r, double lo, double hi) { return lo + (hi - lo) * r->uniform01(); }

// The map changes of a draw that is not clean: each kind present or not, with a rate drawn over
// the range issue 55 names (clutter a few items per 100 m², a tenth to a third of the doors, a
// tenth to a quarter of the furniture moved, a wing turned 0.5–1°).
MapChangeOptions draw_changes(fw::RandomStream* r, const CorpusDrawOptions& opt) {
  MapChangeOptions c;
  if (r->uniform01() < 0.7) c.clutter_per_100m2 = uniform(r, 0.5, 4.0);
  if (r->uniform01() < 0.5) c.door_flip_fraction = uniform(r, 0.1, 0.35);
  if (r->uniform01() < 0.4) c.rearranged_fraction = uniform(r, 0.1, 0.25);
  if (r->uniform01() < opt.distorted_share) c.distortion_deg = uniform(r, 0.5, 1.0);
  return c;
}

}  // namespace

std::vector<CorpusDraw> draw_corpus(std::uint64_t seed, std::size_t n, const CorpusDrawOptions& opt) {
  std::vector<CorpusDraw> out;
  const std::vector<SensorProfile>& sensors = sensor_profiles();
  const std::vector<OdometryProfile>& wheels = odometry_profiles();
  for (std::size_t k = 0; k < n; ++k) {
    // Stream k of the corpus seed: draw k never depends on the corpus size.
    fw::RandomStream r(seed, 1000 + k);
    CorpusDraw d;
    d.index = k;
    d.seed = (seed << 20) ^ (k * 0x9E3779B97F4A7C15ull) ^ 0x5DEECE66Dull;
    // Families, sensors and wheels in rotation with a random offset per corpus: every N ≥ 30 draws
    // cover each combination of family and sensor about equally (a uniform draw would leave some
    // families with a handful of runs at N = 200).
    d.building.family = static_cast<BuildingFamily>((k + seed) % kBuildingFamilyCount);
    d.sensor = sensors[(k / kBuildingFamilyCount + seed) % sensors.size()].name;
    d.odometry = wheels[r.uniform_index(static_cast<std::uint32_t>(wheels.size()))].name;
    d.building.glass_fraction = uniform(&r, 0.0, 0.25);
    d.building.closed_door_fraction = uniform(&r, 0.0, 0.3);
    if (r.uniform01() >= opt.clean_share) d.changes = draw_changes(&r, opt);
    d.route_length_m = uniform(&r, opt.route_length_min_m, opt.route_length_max_m);
    d.stop_probability = uniform(&r, 0.0, 0.3);
    d.people = d.changes.clean() ? 0 : static_cast<int>(r.uniform_index(6));
    const double u = r.uniform01();
    if (u < opt.kidnap_share) {
      d.kidnap_at_scan = 100 + r.uniform_index(100);
    } else if (u < opt.kidnap_share + opt.unmapped_share) {
      d.via_unknown = true;
    }
    out.push_back(d);
  }
  return out;
}

std::string describe_draw(const CorpusDraw& d) {
  char buf[320];
  std::snprintf(buf, sizeof(buf),
                "#%zu %s, %s, %s, route %.0f m%s%s; clutter %.1f/100m2, doors flipped %.0f%%, moved %.0f%%, "
                "map turned %.2f deg, %d people",
                d.index, building_family_name(d.building.family), d.sensor.c_str(), d.odometry.c_str(),
                d.route_length_m, d.kidnap_at_scan > 0 ? ", kidnap" : "", d.via_unknown ? ", via unmapped" : "",
                d.changes.clutter_per_100m2, 100 * d.changes.door_flip_fraction, 100 * d.changes.rearranged_fraction,
                d.changes.distortion_deg, d.people);
  return buf;
}

}  // namespace sim::corpus
