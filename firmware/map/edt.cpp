#include "firmware/map/edt.h"

namespace fw {

void squared_edt_1d(float* data, std::size_t n, std::size_t stride, const EdtScratch& s) {
  if (n == 0) return;
  for (std::size_t q = 0; q < n; ++q) s.f[q] = data[q * stride];
  // Lower envelope of parabolas rooted at each sample (Felzenszwalb & Huttenlocher, Alg. 1).
  int k = 0;
  s.v[0] = 0;
  s.z[0] = -kEdtInf;
  s.z[1] = kEdtInf;
  for (std::size_t qi = 1; qi < n; ++qi) {
    const float q = static_cast<float>(qi);
    if (s.f[qi] >= kEdtInf) continue;  // no parabola from an empty cell
    for (;;) {
      const int vk = s.v[k];
      if (s.f[vk] >= kEdtInf) {  // envelope root is an empty cell: replace it
        if (k == 0) { s.v[0] = static_cast<int>(qi); s.z[0] = -kEdtInf; s.z[1] = kEdtInf; break; }
        --k;
        continue;
      }
      const float fv = static_cast<float>(vk);
      // Intersection of the parabolas rooted at q and v, written as (f_q - f_v) / 2(q - v) + (q + v) / 2
      // instead of ((f_q + q²) - (f_v + v²)) / 2(q - v): q² exceeds float's exact-integer range (2^24)
      // beyond 4096 cells, and the rounded intersection then put occupied cells (f = 0) under a
      // neighbour's parabola (distance √2 cells on a cell that is itself a feature).
      const float sx = (s.f[qi] - s.f[vk]) / (2.0f * (q - fv)) + 0.5f * (q + fv);
      if (sx <= s.z[k]) {
        if (k == 0) { s.v[0] = static_cast<int>(qi); s.z[0] = -kEdtInf; s.z[1] = kEdtInf; break; }
        --k;
        continue;
      }
      ++k;
      s.v[k] = static_cast<int>(qi);
      s.z[k] = sx;
      s.z[k + 1] = kEdtInf;
      break;
    }
  }
  if (s.f[s.v[0]] >= kEdtInf && k == 0) {
    for (std::size_t q = 0; q < n; ++q) data[q * stride] = kEdtInf;
    return;
  }
  k = 0;
  for (std::size_t qi = 0; qi < n; ++qi) {
    const float q = static_cast<float>(qi);
    while (s.z[k + 1] < q) ++k;
    const float dq = q - static_cast<float>(s.v[k]);
    const float val = dq * dq + s.f[s.v[k]];
    data[qi * stride] = val < kEdtInf ? val : kEdtInf;
  }
}

}  // namespace fw
