#include "firmware/mml/mml_presets.h"

#include <algorithm>

namespace fw {
namespace mml {

MmlLocalizerConfig mml_preset(int preset, std::uint64_t seed) {
  if (preset < 1 || preset > 4) preset = kDefaultMmlPreset;
  MmlLocalizerConfig c = default_mml_config();
  c.mml.seed = seed;
  c.rbsm.seed = seed;
  c.mml.bollinger = true;
  c.mml.matching_iterations = preset == 4 ? 60000 : 30000;
  c.mml.precomputed_table = preset != 1;
  c.local_map.keep_last = preset >= 3 ? 8 : 0;
  return c;
}

MmlLocalizerConfig mml_track_preset(int preset, std::uint64_t seed) {
  MmlLocalizerConfig c = mml_preset(preset, seed);
  c.mml.pool_cluster_support = true;
  c.mml.keep_support_across_empty_steps = true;
  c.mml.keep_support_across_contested_steps = true;
  // Range of the local map: the tracker's (TrackOptions::align.max_range_m, 30 m) instead of the
  // dissertation's 8 m. The 8 m of Ch. 5 is the LMS 200's millimetre mode (8.19 m at most); every log
  // here was recorded in centimetre mode (50–82 m), and outdoors the 8 m cut leaves MML almost nothing
  // to match (fr-campus: first fix in 1 of 1 whole runs 0 → 1 within 2.5 m, availability 0.47 → 0.56;
  // README "Protection level"). C1–C4 themselves (bench mml, the dissertation's comparison) keep 8 m.
  c.front_end.scan.max_range = 30.0f;
  c.rbsm.max_range = 30.0f;
  // pRANSAM's local refinement (matcher.h, an addition to Ch. 4) on the map's distance field: a
  // triangle correspondence is only as precise as the point spacing, so a right hypothesis often
  // rates a few hundredths below Ω_thres and is lost, or joins its cluster a few centimetres off.
  // Hypotheses near the threshold (within MmlOptions::refine_window of this step's threshold) are
  // polished by two Gauss–Newton steps on 64 points of the local map and rated again, at most 300
  // per match (mit-killian's corridors bring p50 560, p99 2339 such hypotheses per match). Measured
  // in README "Protection level" (first fix, 10 kidnapped starts per log).
  c.match.refine_iterations = 2;
  c.match.refine_min_quality = c.mml.omega_thres_min;
  c.match.refine_max_points = 64;
  c.match.refine_max_hypotheses = 300;
  // `outside-map` is the tracker's call (the scan at the tracked pose, and after a track is given up
  // the scan at its last pose carried by the wheels: TrackedLocalizer), not MML's: while searching,
  // MML has no pose it trusts. Its no-match rule (MmlOptions::outside_map_no_match_steps) takes
  // pRANSAM finding nothing for unmapped space, and Eq. 5.37 on a best hypothesis that is a wrong
  // alias finds the new observations unexplained too: on whole runs they said `outside-map` at 937
  // steps of fr-clinic and 102 of fr-campus, all where the map covers the reference's scan
  // (sim/eval/mml_eval/unmapped_scan.h; README "Protection level").
  c.mml.detect_unknown = false;
  return c;
}

MmlLocalizerConfig fit_contact_field_to_map(MmlLocalizerConfig config, const GlobalMap& map) {
  const float res = std::max(0.05f, map.geometry.resolution);
  auto& f = config.matcher.field;
  f.resolution = res;
  f.eps_hard = 2.0f * res;
  f.eps_soft = 4.0f * res;
  const float sx = map.geometry.size_x() / res + 64.0f, sy = map.geometry.size_y() / res + 64.0f;
  f.max_axis = static_cast<std::uint32_t>(std::max(sx, sy)) + 1;
  f.max_cells = static_cast<std::size_t>(sx + 1) * static_cast<std::size_t>(sy + 1);
  // The contact field keeps no float distance field: it would duplicate the map's own, 4 bytes per
  // cell (issue 14); pRANSAM's refinement (mml_track_preset) samples the map's field instead
  // (Matcher::set_refine_distance), and MML uses no free-space test.
  f.keep_distance = false;
  return config;
}

}  // namespace mml
}  // namespace fw
