// Contact field of the model set B: the quality Ω (Eq. 4.7) needs, for every transformed point of A,
// its distance Δ to the closest point of B. Instead of a kd-tree (the dissertation) we precompute
// an exact distance grid (2-D) / voxel field (3-D) of B once with fw::squared_edt<D> and store the
// contact value per cell as a byte: 255 = hard contact (Δ < ε_h, Eq. 4.31); 0..254 = the linear
// fuzzy contact (ε_s − Δ)/(ε_s − ε_h) for ε_h ≤ Δ < ε_s (Eq. 4.33), floored so that 255 stays
// exclusive to hard contact. One byte per cell keeps the field cache-resident (intel: ~0.4 MB).
//
// The float distance field (4 bytes per cell) is only needed by the optional refinement and the
// free-space test (matcher.h); MML uses neither, and on a large map it was the biggest single
// array of the firmware (fr-clinic: 42 MB, a duplicate of the map's own field). With
// keep_distance = false the contact bytes are stamped directly: every cell within ε_s of a point
// takes the largest contact over those points, which is the contact of its nearest point (contact
// falls with distance) — the same integer cell offsets the EDT measures, so the same bytes.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/arena.h"
#include "firmware/base/status.h"
#include "firmware/map/edt.h"
#include "firmware/pransam/relation_table.h"

namespace fw::pransam {

struct ContactFieldOptions {
  float resolution = 0.05f;   // cell size, metres
  float eps_hard = 0.10f;     // ε_h (Eq. 4.31), metres
  float eps_soft = 0.20f;     // ε_s (Eq. 4.33), metres; > ε_h
  std::size_t max_cells = std::size_t(1) << 21;  // capacity (arena bytes: 5 per cell, 1 without distance)
  bool keep_distance = true;  // false: contact bytes only; distance()/distance_gradient() unavailable
  std::uint32_t max_axis = 8192;                 // longest axis in cells (EDT scratch)
};

template <int D>
class ContactField {
 public:
  Status init(const ContactFieldOptions& options, StartupArena& arena);
  // Arena bytes init() takes for these options (before alignment padding).
  static std::size_t arena_bytes(const ContactFieldOptions& options);
  // Rebuilds the field for `points` (finite); cells cover their bounding box + ε_s.
  Status build(const Point<D>* points, std::size_t n, const char* name);

  // Contact value of a point in [0,255]; 0 outside the field.
  std::uint8_t contact(const Point<D>& p) const {
    std::size_t idx = 0;
    for (int a = 0; a < D; ++a) {
      const float f = (p(a) - origin_(a)) * inv_res_;
      // Negative and NaN fail this test; the cast is safe afterwards.
      if (!(f >= 0.0f && f < dims_f_[a])) return 0;
      idx = idx * dims_[a] + static_cast<std::size_t>(f);
    }
    return cells_[idx];
  }
  // Whether distance()/distance_gradient() may be called (options.keep_distance).
  bool has_distance() const { return dist2_ != nullptr; }
  // Distance (metres) to the nearest point of B at p's cell; +inf outside or without has_distance().
  float distance(const Point<D>& p) const;
  // Multilinear interpolation of the distance between cell centres and its gradient (for the
  // optional local refinement); false outside the field or without has_distance().
  bool distance_gradient(const Point<D>& p, float* d, Point<D>* grad) const;

  const ContactFieldOptions& options() const { return options_; }
  std::size_t cells() const { return total_; }
  std::size_t dim(int a) const { return dims_[a]; }
  const Point<D>& origin() const { return origin_; }

 private:
  ContactFieldOptions options_;
  std::uint8_t* cells_ = nullptr;
  float* dist2_ = nullptr;  // squared distance in cells² (kept for distance()); null unless keep_distance
  // Contact bytes without a distance field: stamps a disc of radius ε_s around every point.
  void stamp(const Point<D>* points, std::size_t n);
  EdtScratch scratch_;
  Point<D> origin_ = Point<D>::Zero();
  float inv_res_ = 1.0f;
  std::size_t dims_[D] = {};
  float dims_f_[D] = {};
  std::size_t total_ = 0;
};

}  // namespace fw::pransam
