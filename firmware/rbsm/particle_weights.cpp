#include "firmware/rbsm/particle_weights.h"

namespace fw {

namespace {

// The loop itself, inlined into each build below so that each is compiled for its own target.
__attribute__((always_inline)) inline void weigh_kernel(const EndpointGrid::LookupView& v, const float* px,
                                                         const float* py, std::uint32_t num_points,
                                                         const ParticleBlock& b) {
  const float lim = v.extent - 1.0f;
  constexpr std::uint32_t kChunk = 256;
  alignas(64) float ox[kChunk], oy[kChunk], cs[kChunk], sn[kChunk];
  alignas(64) std::uint32_t idx[kChunk], acc[kChunk];
  const std::uint32_t osx = static_cast<std::uint32_t>(v.origin_sx), osy = static_cast<std::uint32_t>(v.origin_sy);
  const std::uint32_t mask = v.mask, pshift = v.shift - 6, zero = v.zero_index;
  for (std::uint32_t c0 = b.begin; c0 < b.end; c0 += kChunk) {
    const std::uint32_t n = b.end - c0 < kChunk ? b.end - c0 : kChunk;
    for (std::uint32_t j = 0; j < n; ++j) {
      ox[j] = (b.x[c0 + j] - v.origin_x) * v.inv_subcell;
      oy[j] = (b.y[c0 + j] - v.origin_y) * v.inv_subcell;
      cs[j] = b.cos[c0 + j] * v.inv_subcell;
      sn[j] = b.sin[c0 + j] * v.inv_subcell;
      acc[j] = 0;
    }
    for (std::uint32_t i = 0; i < num_points; ++i) {
      const float bx = px[i], by = py[i];
      for (std::uint32_t j = 0; j < n; ++j) {
        float fx = ox[j] + (cs[j] * bx - sn[j] * by);
        float fy = oy[j] + (sn[j] * bx + cs[j] * by);
        const bool inside = (fx >= 0.0f) & (fx < v.extent) & (fy >= 0.0f) & (fy < v.extent);
        fx = fx < 0.0f ? 0.0f : (fx > lim ? lim : fx);
        fy = fy < 0.0f ? 0.0f : (fy > lim ? lim : fy);
        const std::uint32_t sx = (static_cast<std::uint32_t>(static_cast<std::int32_t>(fx)) + osx) & mask;
        const std::uint32_t sy = (static_cast<std::uint32_t>(static_cast<std::int32_t>(fy)) + osy) & mask;
        // EndpointGrid::tiled_index: 64×64 pages of 8×8 blocks of 8×8 sub-cells.
        const std::uint32_t page = ((sy >> 6) << pshift) | (sx >> 6);
        const std::uint32_t t =
            (page << 12) | (((sy >> 3) & 7u) << 9) | (((sx >> 3) & 7u) << 6) | ((sy & 7u) << 3) | (sx & 7u);
        idx[j] = inside ? t : zero;
      }
      for (std::uint32_t j = 0; j < n; ++j) acc[j] += v.values[idx[j]];
    }
    for (std::uint32_t j = 0; j < n; ++j) b.weights[c0 + j] = acc[j];
  }
}

void weigh_portable(const EndpointGrid::LookupView& v, const float* px, const float* py, std::uint32_t num_points,
                    const ParticleBlock& b) {
  weigh_kernel(v, px, py, num_points, b);
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define MMLFW_WIDE_PARTICLE_WEIGHTS 1
__attribute__((target("avx2"))) void weigh_avx2(const EndpointGrid::LookupView& v, const float* px, const float* py,
                                                 std::uint32_t num_points, const ParticleBlock& b) {
  weigh_kernel(v, px, py, num_points, b);
}
#endif

}  // namespace

bool wide_particle_weights_available() {
#ifdef MMLFW_WIDE_PARTICLE_WEIGHTS
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

void weigh_particles(const EndpointGrid::LookupView& view, const float* px, const float* py, std::uint32_t num_points,
                     const ParticleBlock& block, bool allow_wide) {
#ifdef MMLFW_WIDE_PARTICLE_WEIGHTS
  if (allow_wide && wide_particle_weights_available()) {
    weigh_avx2(view, px, py, num_points, block);
    return;
  }
#else
  (void)allow_wide;
#endif
  weigh_portable(view, px, py, num_points, block);
}

}  // namespace fw
