// One draw of the generated corpus (issue 55): a (building, sensor, odometry, map-change, route)
// combination, drawn from the corpus seed alone so that `mml-eval --corpus N --seed S` measures the
// same N runs on every machine. Draw k depends on (S, k) only: a corpus of 200 holds the first 20's
// runs unchanged.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim/world/building_generator.h"
#include "sim/world/map_changes.h"

namespace sim::corpus {

struct CorpusDraw {
  std::size_t index = 0;
  std::uint64_t seed = 0;           // of this run: building, map changes, route, sensors
  BuildingOptions building;
  std::string sensor;               // sensor_profiles.h name
  std::string odometry;             // odometry_profiles.h name
  MapChangeOptions changes;
  double route_length_m = 0;        // driven path
  double speed_min = 0.3, speed_max = 1.5;  // m/s, drawn per leg
  double stop_probability = 0.15;   // a stop at a route node
  std::size_t kidnap_at_scan = 0;   // 0 = no kidnap
  bool via_unknown = false;         // drive first into an unmapped wing
  int people = 0;                   // people walking through (never in the map)
};

// What the corpus draws from; the defaults are the corpus of scripts/bench.sh corpus.
struct CorpusDrawOptions {
  double clean_share = 0.3;        // draws whose map is the world (no change at all)
  double kidnap_share = 0.15;      // draws carried elsewhere once, mid-run
  double unmapped_share = 0.1;     // draws that first drive into a wing erased from the map
  double distorted_share = 0.2;    // of the changed draws: a wing of the map drawn turned 0.5–1°
  double route_length_min_m = 60, route_length_max_m = 120;
};

// Draws k = 0 … n−1 of corpus `seed`.
std::vector<CorpusDraw> draw_corpus(std::uint64_t seed, std::size_t n, const CorpusDrawOptions& opt = {});
// One line naming the draw ("#12 hospital 64×18 m, utm30lx, diff-poor, clutter 2.1/100 m², …").
std::string describe_draw(const CorpusDraw& d);

}  // namespace sim::corpus
