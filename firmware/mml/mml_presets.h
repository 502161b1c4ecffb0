// The evaluated MML configurations, shared by the firmware binary and the host tools so that what
// runs on the robot is what was measured (mml-sim, mml-eval, bench_mml, mmlfw).
// Configurations C1..C4 follow the dissertation's Tables 5.1–5.4:
//   C1  relation tables of both point sets filled online, whole local map
//   C2  precomputed global relation table (Sec. 5.5.2), whole local map
//   C3  precomputed table, local map limited to the last 8 fragments (Sec. 5.4)   [default]
//   C4  as C3 with twice the matching iterations
// All use the Bollinger-band threshold adaptation (Eq. 5.18–5.21).
#pragma once

#include <cstdint>

#include "firmware/map/global_map.h"
#include "firmware/mml/mml_localizer.h"

namespace fw {
namespace mml {

constexpr int kDefaultMmlPreset = 3;

// Configuration C`preset` (1..4; other values give C3) with `seed` for RBSM and pRANSAM.
MmlLocalizerConfig mml_preset(int preset, std::uint64_t seed);

// The MML part of mml-track: C`preset` with the pooled cluster support (MmlOptions::
// pool_cluster_support, kept across empty and contested steps), which the tracker's confirmation
// of every fix makes safe to use.
MmlLocalizerConfig mml_track_preset(int preset, std::uint64_t seed);

// pRANSAM's contact field must cover the whole global map: its cell follows the map's resolution
// (never finer than 5 cm) and its capacity the map's extent plus a margin (fr-clinic: 440 × 241 m).
MmlLocalizerConfig fit_contact_field_to_map(MmlLocalizerConfig config, const GlobalMap& map);

}  // namespace mml
}  // namespace fw
