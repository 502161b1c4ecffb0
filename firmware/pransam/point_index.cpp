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
bool PointIndex<D>::draw(RandomStream& rng, Triple* t) const {
  if (n_ < 3) return false;
  const std::uint32_t i = rng.uniform_index(n_);
  std::uint32_t c = cell_of_[i];
  std::int32_t coord[D];
  for (int a = D - 1; a >= 0; --a) {
    coord[a] = static_cast<std::int32_t>(c % dims_[a]);
    c /= dims_[a];
  }
  constexpr int kNb = D == 2 ? 9 : 27;
  std::uint32_t cells[kNb];
  std::uint32_t counts[kNb];
  int m = 0;
  std::uint32_t total = 0;
  for (int o = 0; o < kNb; ++o) {
    int rem = o;
    std::uint32_t id = 0;
    bool inside = true;
    for (int a = 0; a < D; ++a) {
      const std::int32_t k = coord[a] + (rem % 3) - 1;
      rem /= 3;
      if (k < 0 || k >= static_cast<std::int32_t>(dims_[a])) { inside = false; break; }
      id = id * dims_[a] + static_cast<std::uint32_t>(k);
    }
    if (!inside) continue;
    const std::uint32_t cnt = cell_start_[id + 1] - cell_start_[id];
    if (cnt == 0) continue;
    cells[m] = id;
    counts[m] = cnt;
    total += cnt;
    ++m;
  }
  if (total < 3) return false;
  std::uint32_t pick[2];
  for (int p = 0; p < 2; ++p) {
    std::uint32_t r = rng.uniform_index(total);
    int q = 0;
    while (r >= counts[q]) { r -= counts[q]; ++q; }
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
