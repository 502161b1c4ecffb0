#include "firmware/pransam/contact_field.h"

#include <cmath>

#include "firmware/base/memory_report.h"

namespace fw::pransam {
namespace {

// Contact byte of a distance dm (metres): Eq. 4.31 / 4.33, 255 exclusive to hard contact.
inline std::uint8_t contact_byte(float dm, float eh, float es) {
  if (dm < eh) return 255;  // Eq. 4.31
  if (dm < es) {
    float f = std::floor(255.0f * (es - dm) / (es - eh));  // Eq. 4.33
    if (f > 254.0f) f = 254.0f;
    return static_cast<std::uint8_t>(f);
  }
  return 0;
}

}  // namespace

template <int D>
Status ContactField<D>::init(const ContactFieldOptions& options, StartupArena& arena) {
  if (!(options.resolution > 0.0f) || !(options.eps_hard > 0.0f) || !(options.eps_soft > options.eps_hard)) {
    return Status::error(Errc::kInvalidArgument,
                         "pransam contact field: need resolution > 0 and 0 < eps_hard < eps_soft (got %g, %g, %g)",
                         static_cast<double>(options.resolution), static_cast<double>(options.eps_hard),
                         static_cast<double>(options.eps_soft));
  }
  if (options.max_cells == 0 || options.max_axis < 2) {
    return Status::error(Errc::kInvalidArgument, "pransam contact field: max_cells/max_axis must be positive");
  }
  options_ = options;
  Result<std::uint8_t*> c = arena.allocate_array<std::uint8_t>(options.max_cells, "pransam contact field");
  if (!c) return c.status();
  cells_ = *c;
  dist2_ = nullptr;
  if (options.keep_distance) {
    Result<float*> d = arena.allocate_array<float>(options.max_cells, "pransam distance field");
    if (!d) return d.status();
    dist2_ = *d;
  } else {
    scratch_ = EdtScratch{};
    return MemoryReport::instance().add({D == 2 ? "pransam2d" : "pransam3d", "contact field", arena_bytes(options),
                                         options.max_cells, nullptr});
  }
  const std::size_t n = options.max_axis;
  Result<int*> v = arena.allocate_array<int>(n, "pransam edt v");
  Result<float*> z = arena.allocate_array<float>(n + 1, "pransam edt z");
  Result<float*> f = arena.allocate_array<float>(n, "pransam edt f");
  Result<float*> dd = arena.allocate_array<float>(n, "pransam edt d");
  if (!v) return v.status();
  if (!z) return z.status();
  if (!f) return f.status();
  if (!dd) return dd.status();
  scratch_ = EdtScratch{*v, *z, *f, *dd, n};
  return MemoryReport::instance().add({D == 2 ? "pransam2d" : "pransam3d", "contact+distance field",
                                       arena_bytes(options), options.max_cells, nullptr});
}

template <int D>
std::size_t ContactField<D>::arena_bytes(const ContactFieldOptions& options) {
  if (!options.keep_distance) return options.max_cells;
  return options.max_cells * 5 + static_cast<std::size_t>(options.max_axis) * 16 + 4;
}

template <int D>
void ContactField<D>::stamp(const Point<D>* points, std::size_t n) {
  const float res = options_.resolution, eh = options_.eps_hard, es = options_.eps_soft;
  // Cells whose centre offset from a point's cell reaches ε_s get 0 anyway: radius ⌈ε_s/res⌉.
  const int r = static_cast<int>(std::ceil(es / res));
  for (std::size_t i = 0; i < total_; ++i) cells_[i] = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::int64_t c[D];
    for (int a = 0; a < D; ++a) c[a] = static_cast<std::int64_t>((points[i](a) - origin_(a)) * inv_res_);
    // Odometer over the (2r+1)^D offsets; cells off the field are skipped (the margin keeps the
    // disc inside, but the test is cheap).
    int off[D];
    for (int a = 0; a < D; ++a) off[a] = -r;
    for (;;) {
      std::size_t idx = 0;
      std::int64_t d2 = 0;
      bool inside = true;
      for (int a = 0; a < D; ++a) {
        const std::int64_t g = c[a] + off[a];
        if (g < 0 || g >= static_cast<std::int64_t>(dims_[a])) { inside = false; break; }
        idx = idx * dims_[a] + static_cast<std::size_t>(g);
        d2 += static_cast<std::int64_t>(off[a]) * off[a];
      }
      if (inside) {
        // The EDT path's expression for the same integer d², so the same byte.
        const std::uint8_t v = contact_byte(std::sqrt(static_cast<float>(d2)) * res, eh, es);
        if (v > cells_[idx]) cells_[idx] = v;
      }
      int a = D - 1;
      while (a >= 0 && off[a] == r) off[a--] = -r;
      if (a < 0) break;
      ++off[a];
    }
  }
}

template <int D>
Status ContactField<D>::build(const Point<D>* points, std::size_t n, const char* name) {
  if (cells_ == nullptr) return Status::error(Errc::kNotInitialized, "%s: contact field not initialised", name);
  if (n == 0) return Status::error(Errc::kInvalidArgument, "%s: empty point set", name);
  Point<D> lo = points[0], hi = points[0];
  for (std::size_t i = 0; i < n; ++i) {
    if (!points[i].allFinite()) {
      return Status::error(Errc::kInvalidArgument, "%s: point %zu is not finite", name, i);
    }
    lo = lo.cwiseMin(points[i]);
    hi = hi.cwiseMax(points[i]);
  }
  const float res = options_.resolution;
  const float margin = options_.eps_soft + 2.0f * res;
  std::size_t total = 1;
  std::size_t dims[D];
  for (int a = 0; a < D; ++a) {
    const double span = static_cast<double>(hi(a) - lo(a)) + 2.0 * margin;
    const double cells = std::ceil(span / res) + 1.0;
    if (cells > static_cast<double>(options_.max_axis)) {
      return Status::error(Errc::kCapacityExceeded, "%s: contact field axis %d needs %.0f cells > max_axis %u", name,
                           a, cells, options_.max_axis);
    }
    dims[a] = static_cast<std::size_t>(cells);
    total *= dims[a];
  }
  if (total > options_.max_cells) {
    return Status::error(Errc::kCapacityExceeded, "%s: contact field needs %zu cells > capacity %zu", name, total,
                         options_.max_cells);
  }
  origin_ = lo - Point<D>::Constant(margin);
  inv_res_ = 1.0f / res;
  for (int a = 0; a < D; ++a) {
    dims_[a] = dims[a];
    dims_f_[a] = static_cast<float>(dims[a]);
  }
  total_ = total;
  if (dist2_ == nullptr) {
    stamp(points, n);
    return Status::ok();
  }
  for (std::size_t i = 0; i < total; ++i) dist2_[i] = kEdtInf;
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t idx = 0;
    for (int a = 0; a < D; ++a) {
      const std::size_t c = static_cast<std::size_t>((points[i](a) - origin_(a)) * inv_res_);
      idx = idx * dims_[a] + c;
    }
    dist2_[idx] = 0.0f;
  }
  squared_edt<D>(dist2_, dims, scratch_);
  const float eh = options_.eps_hard, es = options_.eps_soft;
  for (std::size_t i = 0; i < total; ++i) {
    cells_[i] = contact_byte(std::sqrt(dist2_[i]) * res, eh, es);
  }
  return Status::ok();
}

template <int D>
float ContactField<D>::distance(const Point<D>& p) const {
  if (dist2_ == nullptr) return INFINITY;  // keep_distance = false: no field (the matcher refuses first)
  std::size_t idx = 0;
  for (int a = 0; a < D; ++a) {
    const float f = (p(a) - origin_(a)) * inv_res_;
    if (!(f >= 0.0f && f < dims_f_[a])) return INFINITY;
    idx = idx * dims_[a] + static_cast<std::size_t>(f);
  }
  return std::sqrt(dist2_[idx]) * options_.resolution;
}

template <int D>
bool ContactField<D>::distance_gradient(const Point<D>& p, float* d, Point<D>* grad) const {
  if (dist2_ == nullptr) return false;
  std::size_t base[D];
  float frac[D];
  for (int a = 0; a < D; ++a) {
    const float f = (p(a) - origin_(a)) * inv_res_ - 0.5f;  // relative to cell centres
    if (!(f >= 0.0f && f < dims_f_[a] - 1.0f)) return false;
    base[a] = static_cast<std::size_t>(f);
    frac[a] = f - static_cast<float>(base[a]);
  }
  float val = 0.0f;
  Point<D> g = Point<D>::Zero();
  for (int corner = 0; corner < (1 << D); ++corner) {
    std::size_t idx = 0;
    float w = 1.0f;
    float dw[D];
    for (int a = 0; a < D; ++a) {
      const int bit = (corner >> a) & 1;
      idx = idx * dims_[a] + base[a] + static_cast<std::size_t>(bit);
      dw[a] = bit ? 1.0f : -1.0f;
    }
    float wa[D];
    for (int a = 0; a < D; ++a) wa[a] = ((corner >> a) & 1) ? frac[a] : 1.0f - frac[a];
    for (int a = 0; a < D; ++a) w *= wa[a];
    const float v = std::sqrt(dist2_[idx]) * options_.resolution;
    val += w * v;
    for (int a = 0; a < D; ++a) {
      float wo = dw[a];
      for (int b = 0; b < D; ++b) if (b != a) wo *= wa[b];
      g(a) += wo * v;
    }
  }
  *d = val;
  *grad = g * inv_res_;
  return true;
}

template class ContactField<2>;
template class ContactField<3>;

}  // namespace fw::pransam
