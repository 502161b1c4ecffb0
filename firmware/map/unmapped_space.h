// Unmapped space: the unknown regions of a map that the building surrounds (a room the mapping run
// never entered, a block erased from the map). The robot may be switched on there, and what its
// scans show there is anything at all — a copy of a mapped place included. So a point that falls
// there under a pose hypothesis is no evidence against that pose: while MML holds that hypothesis
// (MmlLocalizer::set_unmapped_hypothesis; mml-track: until the robot is first located) pRANSAM
// gives such a point contact, which keeps "the robot is in the unmapped room" beside the mapped
// look-alike until the scans tell them apart (issue 56, corpus seed 505 #56: without it a twin
// cross-aisle 36 m away was isolated while the robot stood in the erased block). Regions of at
// least MmlOptions::unmapped_space_min_area_m2 count. The unknown margin around the building
// (connected to the image border) is outside
// the map, not unmapped space; regions smaller than `min_area_m2` (pillars, the inside of thick
// walls) cannot hold the robot or anything it walks around, and are left as misses.
//
// Computed once at start-up on blocks of `block_m` (a block is unknown when all its cells are; one
// byte per block in the start-up arena, 1.7 MB for fr-clinic's 106,000 m² box):
// the outside by sweeps from the border (no queue, so no capacity to overflow on any map shape),
// then each inner unknown component's size by a flood bounded at the area that decides it.
#pragma once

#include <cstdint>

#include "firmware/base/arena.h"
#include "firmware/base/status.h"
#include "firmware/map/global_map.h"

namespace fw {

struct UnmappedSpaceOptions {
  float block_m = 0.25f;     // block edge (≥ one map cell)
  float min_area_m2 = 1.0f;  // an inner unknown region at least this large is unmapped space
};

class UnmappedSpace {
 public:
  // Labels `map`'s blocks; the labels live in `arena`.
  Status build(const GlobalMap& map, const UnmappedSpaceOptions& options, StartupArena& arena);
  // True where (x, y) lies in unmapped space.
  bool contains(float x, float y) const;
  // Blocks in unmapped space (for the start-up log and tests).
  std::uint32_t unmapped_blocks() const { return unmapped_blocks_; }
  float block_m() const { return block_m_; }

 private:
  enum Label : std::uint8_t { kKnown = 0, kUnknown = 1, kOutside = 2, kUnmapped = 3, kSmall = 4 };
  Label at(std::int32_t bx, std::int32_t by) const { return static_cast<Label>(labels_[static_cast<std::size_t>(by) * bw_ + bx]); }
  void sweep_outside();
  void classify_inner(std::uint32_t min_blocks);
  std::uint8_t* labels_ = nullptr;
  std::int32_t bw_ = 0, bh_ = 0;
  float origin_x_ = 0.0f, origin_y_ = 0.0f, block_m_ = 0.0f;
  std::uint32_t unmapped_blocks_ = 0;
};

}  // namespace fw
