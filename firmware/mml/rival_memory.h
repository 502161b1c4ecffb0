// Rival memory (extension, not in the dissertation): a cluster that stops appearing is not thereby
// eliminated. MML's constraints (Eq. 5.8–5.17) see only the clusters of the current step; when the
// adaptive threshold (Eq. 5.18–5.21) rises just below the best Ω, pRANSAM's random triples may
// return only one of two equally good places for several steps, and the survivor is then
// "isolated" by elimination. Seen in the simulator (large office, kidnap at step 400, SICK
// transport): the true corridor and its 180° mirror 80 m away alternated as the best cluster; the
// true one was not returned for 20 steps and MML published the mirror as `localized` for 12 steps.
//
// So every cluster that was a serious candidate (rating ≥ rival_min_rating_ratio × the step's best)
// is remembered as the transform H = map ← local map it implies — H is fixed while the local map
// is consistent, so it needs no odometry propagation. Before MML first reports `localized`, every
// remembered rival farther than the separation from the candidate is refined on the local map and
// compared with the candidate by the paired test of firmware/map/paired_fit_test.h, with the local
// map's occupied correlation cells as the independent observations: a rival the local map explains
// significantly worse is forgotten (contradicted); any other rival keeps the status `ambiguous`.
// A candidate held back only by open rivals stays pending (mml_localizer.cpp): it is re-checked on
// the growing local map at each step, isolated once every rival is contradicted, dropped when a
// rival fits significantly better than it.
// Fixed storage (kMaxRivals entries, kMaxRivalPoints test points); never allocates.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/se2.h"
#include "firmware/map/global_map.h"
#include "firmware/mml/interpretation.h"
#include "firmware/mml/mml_options.h"

namespace fw {
namespace mml {

constexpr std::size_t kMaxRivals = 16;
constexpr std::size_t kMaxRivalPoints = 2048;

struct RivalCheck {
  bool resolved = true;           // no remembered rival is left open by the local map
  std::uint32_t checked = 0;      // rivals beyond the separation that were tested
  std::uint32_t contradicted = 0; // of those, forgotten because the local map rejects them
  std::uint32_t independent = 0;  // correlation cells of the local map points used
  Se2f open_rival;                // robot pose of the first rival left open (when !resolved)
  bool candidate_rejected = false;  // a rival fits the local map significantly better than the candidate
};

class RivalMemory {
 public:
  void reset() { count_ = 0; }
  std::size_t size() const { return count_; }

  // Remembers this step's serious clusters (robot poses in the map) as H = pose ⊕ local_pose⁻¹;
  // a cluster within the separation of a remembered rival refreshes it.
  void observe(const Cluster* clusters, std::size_t n, const Se2f& local_pose, const MmlOptions& o, std::uint64_t step);

  // `local_pts`: the local map (local frame); `h_best`: the candidate's map ← local map transform.
  RivalCheck check(const GlobalMap& map, const Point2f* local_pts, std::size_t n, const Se2f& h_best,
                   const Se2f& local_pose, const MmlOptions& o);

 private:
  struct Rival {
    Se2f h;                      // map ← local map
    float strength = 0.0f;       // max over steps of rating / best rating of that step
    std::uint64_t last_seen = 0;
  };
  bool separated(const Se2f& a, const Se2f& b, const MmlOptions& o) const;
  std::uint32_t count_cells(std::size_t n, float cell_m);

  Rival rivals_[kMaxRivals];
  std::size_t count_ = 0;
  Point2f pts_[kMaxRivalPoints];
  std::int64_t keys_[kMaxRivalPoints];
};

}  // namespace mml
}  // namespace fw
