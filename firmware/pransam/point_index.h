// Triple sampler for one point set. A triple whose longest side exceeds the relation table's extent
// can never be keyed, and in a large global map almost every uniform triple is such a triple. So
// the sampler buckets the points into a grid of cells of size `extent` and draws the first point
// uniformly, the other two uniformly among the points of the 3^D neighbouring cells: every keyable
// triple keeps a non-zero probability, and far fewer draws are wasted. Sets that fit into one
// cell degenerate to uniform sampling (the dissertation's draw).
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/arena.h"
#include "firmware/base/rng.h"
#include "firmware/base/status.h"
#include "firmware/pransam/relation_table.h"

namespace fw::pransam {

template <int D>
class PointIndex {
 public:
  // Capacity: points and grid cells.
  Status init(std::uint32_t max_points, std::uint32_t max_cells, StartupArena& arena, const char* name);
  // Indexes `points` (non-owning; must outlive the index). Points must be finite.
  Status build(const Point<D>* points, std::uint32_t n, float cell_size, const char* name);

  // Draws a triple of distinct indices; false when the neighbourhood is too sparse (a wasted draw).
  bool draw(RandomStream& rng, Triple* t) const;

  const Point<D>* points() const { return points_; }
  std::uint32_t size() const { return n_; }
  float cell_size() const { return cell_size_; }

 private:
  static constexpr int kNeighbours = D == 2 ? 9 : 27;
  // The 3^D cells around cell c (axis 0 the fastest digit, offsets −1, 0, +1) and their point counts
  // (0 off the grid); returns the sum of the counts.
  std::uint32_t neighbourhood(std::uint32_t c, std::uint32_t* cells, std::uint32_t* counts) const;

  std::uint32_t max_points_ = 0, max_cells_ = 0;
  const Point<D>* points_ = nullptr;
  std::uint32_t n_ = 0;
  float cell_size_ = 1.0f;
  Point<D> origin_ = Point<D>::Zero();
  std::uint32_t dims_[D] = {};
  std::uint32_t* order_ = nullptr;       // point indices sorted by cell
  std::uint32_t* cell_start_ = nullptr;  // max_cells + 1
  std::uint32_t* cell_of_ = nullptr;     // cell of each point
};

}  // namespace fw::pransam
