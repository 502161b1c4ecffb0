// Relation table of pRANSAM (Eq. 4.1–4.3): a dense 3-D hash table keyed by the three side lengths of
// a point triple, kSlotsPerAxis slots per axis (80 in the dissertation, Sec. 4.5.1), one triple per
// slot, overwritten on a clash. The table stores point INDICES into the point set it was filled
// from (12 bytes per slot), so R_B of a global map can be precomputed offline and shipped as a map
// image section (Sec. 5.5.2) that is used in place.
//
// Canonical vertex order (a deliberate refinement of Eq. 4.1): the dissertation keys the sides in
// draw order, so one physical triangle lands in 6 different slots depending on how its vertices
// were drawn and only 1 of 6 congruent draws collides. We order the vertices so that the key is
// (shortest, middle, longest) side: all draw orders of one triangle share a slot. The triangle
// frame (Fig. 4.2) is order-independent except for the sign of the normal, which the canonical
// order makes consistent between A and B; a mirrored triangle (same sides, opposite orientation)
// then gives a flipped frame, which 2-D rejects (Eq. 5.3).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "firmware/base/arena.h"
#include "firmware/base/status.h"

#ifndef MMLFW_PRANSAM_SLOTS_PER_AXIS
#define MMLFW_PRANSAM_SLOTS_PER_AXIS 80
#endif

namespace fw::pransam {

template <int D>
using Point = Eigen::Matrix<float, D, 1>;

constexpr std::uint32_t kSlotsPerAxis = MMLFW_PRANSAM_SLOTS_PER_AXIS;
static_assert(kSlotsPerAxis >= 4 && kSlotsPerAxis <= 1024, "MMLFW_PRANSAM_SLOTS_PER_AXIS out of range");
constexpr std::size_t kNumSlots =
    static_cast<std::size_t>(kSlotsPerAxis) * kSlotsPerAxis * kSlotsPerAxis;
constexpr std::uint32_t kEmptySlot = 0xFFFFFFFFu;

// Point indices of a triple; in canonical order once keyed (v[0] opposite the shortest side).
struct Triple {
  std::uint32_t v[3] = {kEmptySlot, kEmptySlot, kEmptySlot};
  bool empty() const { return v[0] == kEmptySlot; }
};
static_assert(sizeof(Triple) == 12, "Triple is part of the map image format");

// Geometric filter applied before keying.
struct TripleFilter {
  float extent = 10.0f;            // longest side allowed (the table's spatial extent), metres
  float min_height_ratio = 0.1f;   // collinear test: triangle height over its longest side
  float min_side = 0.0f;           // shortest side allowed (0: one slot width)
};

enum class KeyResult : std::uint8_t { kOk, kCollinear, kTooLarge, kTooSmall, kNotFinite };

// Orders `t` canonically and computes its slot. Pure function of the three points.
template <int D>
KeyResult key_triple(const Point<D>* pts, const TripleFilter& filter, Triple* t, std::uint32_t* slot) {
  const Point<D>& a = pts[t->v[0]];
  const Point<D>& b = pts[t->v[1]];
  const Point<D>& c = pts[t->v[2]];
  // Side opposite each vertex.
  float s[3] = {(b - c).norm(), (c - a).norm(), (a - b).norm()};
  if (!(std::isfinite(s[0]) && std::isfinite(s[1]) && std::isfinite(s[2]))) return KeyResult::kNotFinite;
  // Sort vertices by ascending opposite side (3-element sorting network; ties keep draw order).
  std::uint32_t v[3] = {t->v[0], t->v[1], t->v[2]};
  auto swap_if = [&](int i, int j) {
    if (s[j] < s[i]) {
      const float ts = s[i]; s[i] = s[j]; s[j] = ts;
      const std::uint32_t tv = v[i]; v[i] = v[j]; v[j] = tv;
    }
  };
  swap_if(0, 1);
  swap_if(1, 2);
  swap_if(0, 1);
  const float slot_width = filter.extent / static_cast<float>(kSlotsPerAxis);
  if (s[2] >= filter.extent) return KeyResult::kTooLarge;
  if (s[0] < (filter.min_side > 0.0f ? filter.min_side : slot_width)) return KeyResult::kTooSmall;
  // Height over the longest side: 2·area / longest. Collinear triples give no frame (Sec. 4.3).
  const Point<D>& p0 = pts[v[0]];
  const Point<D>& p1 = pts[v[1]];
  const Point<D>& p2 = pts[v[2]];
  float area2;
  if constexpr (D == 2) {
    const Point<D> e1 = p1 - p0, e2 = p2 - p0;
    area2 = std::fabs(e1(0) * e2(1) - e1(1) * e2(0));
  } else {
    area2 = (p1 - p0).cross(p2 - p0).norm();
  }
  if (area2 < filter.min_height_ratio * s[2] * s[2]) return KeyResult::kCollinear;
  t->v[0] = v[0];
  t->v[1] = v[1];
  t->v[2] = v[2];
  const float inv = static_cast<float>(kSlotsPerAxis) / filter.extent;
  // Eq. 4.1 in canonical order: (shortest, middle, longest) = (|v1v2|, |v2v0|, |v0v1|).
  const std::uint32_t k0 = static_cast<std::uint32_t>(s[0] * inv);
  const std::uint32_t k1 = static_cast<std::uint32_t>(s[1] * inv);
  std::uint32_t k2 = static_cast<std::uint32_t>(s[2] * inv);
  if (k2 >= kSlotsPerAxis) k2 = kSlotsPerAxis - 1;  // rounding at the upper edge
  *slot = (k0 * kSlotsPerAxis + k1) * kSlotsPerAxis + k2;
  return KeyResult::kOk;
}

struct RelationTableStats {
  std::size_t filled = 0;        // occupied slots
  std::size_t inserts = 0;       // triples written since clear()
  std::size_t overwrites = 0;    // inserts that replaced an entry ("overwrite on clash")
};

// The table itself: non-owning view over kNumSlots Triples (arena or map-image memory).
class RelationTable {
 public:
  RelationTable() = default;
  // Takes kNumSlots slots from the arena and registers them with MemoryReport.
  Status allocate(StartupArena& arena, const char* name);
  // Read-only use of existing storage (a precomputed map-image section).
  void attach_read_only(const Triple* slots, float extent) {
    slots_ = const_cast<Triple*>(slots);
    read_only_ = true;
    extent_ = extent;
  }
  bool valid() const { return slots_ != nullptr; }
  bool read_only() const { return read_only_; }
  void clear();
  // Empties only the given slots (the ones a match touched) — cheaper than clear() for 6 MB.
  void clear_slots(const std::uint32_t* slots, std::size_t n);
  float extent() const { return extent_; }
  void set_extent(float e) { extent_ = e; }

  const Triple& at(std::uint32_t slot) const { return slots_[slot]; }
  // Overwrite on clash (Sec. 4.3); returns true when an entry was replaced.
  bool insert(std::uint32_t slot, const Triple& t) {
    const bool had = !slots_[slot].empty();
    slots_[slot] = t;
    ++stats_.inserts;
    if (had) ++stats_.overwrites; else ++stats_.filled;
    return had;
  }
  const RelationTableStats& stats() const { return stats_; }
  // Recounts filled slots (for read-only tables whose stats came from elsewhere).
  std::size_t count_filled() const;
  const Triple* data() const { return slots_; }

 private:
  Triple* slots_ = nullptr;
  bool read_only_ = false;
  float extent_ = 0.0f;
  RelationTableStats stats_;
};

}  // namespace fw::pransam
