#include "firmware/pransam/point_index.h"

#include <cmath>

#include "firmware/base/memory_report.h"

namespace fw::pransam {

template <int D>
Status PointIndex<D>::init(std::uint32_t max_points, std::uint32_t max_cells, StartupArena& arena, const char* name) {
  if (max_points < 3 || max_cells < 1) {
    return Status::error(Errc::kInvalidArgument, "%s: point index needs max_points >= 3 and max_cells >= 1", name);
  }
  Result<std::uint32_t*> o = arena.allocate_array<std::uint32_t>(max_points, name);
  Result<std::uint32_t*> c = arena.allocate_array<std::uint32_t>(max_points, name);
  Result<std::uint32_t*> s = arena.allocate_array<std::uint32_t>(static_cast<std::size_t>(max_cells) + 1, name);
  if (!o) return o.status();
  if (!c) return c.status();
  if (!s) return s.status();
  order_ = *o;
  cell_of_ = *c;
  cell_start_ = *s;
  max_points_ = max_points;
  max_cells_ = max_cells;
  return MemoryReport::instance().add({D == 2 ? "pransam2d" : "pransam3d", name,
                                       (2 * static_cast<std::size_t>(max_points) + max_cells + 1) * 4, max_points,
                                       nullptr});
}

template <int D>
Status PointIndex<D>::build(const Point<D>* points, std::uint32_t n, float cell_size, const char* name) {
  if (order_ == nullptr) return Status::error(Errc::kNotInitialized, "%s: point index not initialised", name);
  if (n > max_points_) {
    return Status::error(Errc::kCapacityExceeded, "%s: %u points > capacity %u", name, n, max_points_);
  }
  if (!(cell_size > 0.0f) || !std::isfinite(cell_size)) {
    return Status::error(Errc::kInvalidArgument, "%s: cell size %g is not positive", name,
                         static_cast<double>(cell_size));
  }
  points_ = points;
  n_ = n;
  if (n == 0) return Status::ok();
  Point<D> lo = points[0], hi = points[0];
  for (std::uint32_t i = 1; i < n; ++i) {
    lo = lo.cwiseMin(points[i]);
    hi = hi.cwiseMax(points[i]);
  }
  // Coarsen the grid until it fits the capacity (a coarser grid only wastes more draws).
  for (;;) {
    double total = 1.0;
    for (int a = 0; a < D; ++a) total *= std::floor(static_cast<double>(hi(a) - lo(a)) / cell_size) + 1.0;
    if (total <= static_cast<double>(max_cells_)) break;
    cell_size *= 1.5f;
  }
  cell_size_ = cell_size;
  origin_ = lo;
  std::uint32_t total = 1;
  for (int a = 0; a < D; ++a) {
    dims_[a] = static_cast<std::uint32_t>(std::floor((hi(a) - lo(a)) / cell_size)) + 1;
    total *= dims_[a];
  }
  for (std::uint32_t c = 0; c <= total; ++c) cell_start_[c] = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    std::uint32_t c = 0;
    for (int a = 0; a < D; ++a) {
      std::uint32_t k = static_cast<std::uint32_t>((points[i](a) - origin_(a)) / cell_size);
      if (k >= dims_[a]) k = dims_[a] - 1;
      c = c * dims_[a] + k;
    }
    cell_of_[i] = c;
    ++cell_start_[c + 1];
  }
  for (std::uint32_t c = 0; c < total; ++c) cell_start_[c + 1] += cell_start_[c];
  // Counting sort (stable): uses cell_of_ as keys; a cursor per cell would need more memory, so
  // fill by walking cells' running starts and then restore them.
  for (std::uint32_t i = 0; i < n; ++i) order_[cell_start_[cell_of_[i]]++] = i;
  for (std::uint32_t c = total; c > 0; --c) cell_start_[c] = cell_start_[c - 1];
  cell_start_[0] = 0;
  return Status::ok();
}

template <int D>
inline std::uint32_t PointIndex<D>::neighbourhood(std::uint32_t c, std::uint32_t* cells, std::uint32_t* counts) const {
  std::uint32_t total = 0;
  if constexpr (D == 2) {
    // The 3×3 block unrolled, read a row at a time (axis 1 is contiguous in the cell ids, so a row's
    // three counts take four loads of cell_start_): the generic loop below cost ~370 instructions a
    // draw, most of pRANSAM's start-up fill of R_B (~26 million draws on a corpus map). A cell off the
    // grid counts 0 points, as an empty one does: the picks' walk passes both.
    const std::uint32_t* const start = cell_start_;  // a local: the stores below cannot move it
    const std::uint32_t d0 = dims_[0], d1 = dims_[1];
    const std::uint32_t c0 = c / d1, c1 = c - c0 * d1;  // coord[0], coord[1] as build() composed them
    const bool left = c1 > 0, right = c1 + 1 < d1;
    for (std::uint32_t i = 0; i < 3; ++i) {  // axis 0: the walk's faster digit (q = 3·j + i)
      const std::uint32_t k0 = c0 + i - 1;   // wraps to ≥ d0 below the grid
      const std::uint32_t id = k0 * d1 + c1;
      std::uint32_t n_left = 0, n_mid = 0, n_right = 0;
      if (k0 < d0) {
        const std::uint32_t s0 = start[id], s1 = start[id + 1];
        n_mid = s1 - s0;
        if (left) n_left = s0 - start[id - 1];
        if (right) n_right = start[id + 2] - s1;
      }
      cells[i] = id - 1;
      cells[3 + i] = id;
      cells[6 + i] = id + 1;
      counts[i] = n_left;
      counts[3 + i] = n_mid;
      counts[6 + i] = n_right;
      total += n_left + n_mid + n_right;
    }
    return total;
  } else {
    std::int32_t coord[D];
    for (int a = D - 1; a >= 0; --a) {
      coord[a] = static_cast<std::int32_t>(c % dims_[a]);
      c /= dims_[a];
    }
    for (int o = 0; o < kNeighbours; ++o) {
      int rem = o;
      std::uint32_t id = 0;
      bool inside = true;
      for (int a = 0; a < D; ++a) {
        const std::int32_t k = coord[a] + (rem % 3) - 1;
        rem /= 3;
        if (k < 0 || k >= static_cast<std::int32_t>(dims_[a])) { inside = false; break; }
        id = id * dims_[a] + static_cast<std::uint32_t>(k);
      }
      const std::uint32_t cnt = inside ? cell_start_[id + 1] - cell_start_[id] : 0;
      cells[o] = id;
      counts[o] = cnt;
      total += cnt;
    }
    return total;
  }
}

template <int D>
bool PointIndex<D>::draw(RandomStream& rng, Triple* t) const {
  if (n_ < 3) return false;
  const std::uint32_t i = rng.uniform_index(n_);
  std::uint32_t cells[kNeighbours];
  std::uint32_t counts[kNeighbours];
  const std::uint32_t total = neighbourhood(cell_of_[i], cells, counts);
  if (total < 3) return false;
  std::uint32_t pick[2];
  for (int p = 0; p < 2; ++p) {
    std::uint32_t r = rng.uniform_index(total);
    int q = 0;
    while (r >= counts[q]) { r -= counts[q]; ++q; }  // an empty neighbour (0 points) is passed over
    pick[p] = order_[cell_start_[cells[q]] + r];
  }
  if (pick[0] == i || pick[1] == i || pick[0] == pick[1]) return false;
  t->v[0] = i;
  t->v[1] = pick[0];
  t->v[2] = pick[1];
  return true;
}

template class PointIndex<2>;
template class PointIndex<3>;

}  // namespace fw::pransam
