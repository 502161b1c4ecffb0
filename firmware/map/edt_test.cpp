#include "firmware/map/edt.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "firmware/base/rng.h"

namespace fw {
namespace {

struct Scratch {
  std::vector<int> v;
  std::vector<float> z, f, d;
  EdtScratch s;
  explicit Scratch(std::size_t n) : v(n), z(n + 1), f(n), d(n) { s = {v.data(), z.data(), f.data(), d.data(), n}; }
};

template <int D>
void check_against_brute_force(const std::size_t (&dims)[D], unsigned seed, int features) {
  std::size_t total = 1, maxd = 0;
  for (auto d : dims) { total *= d; maxd = std::max(maxd, d); }
  std::vector<float> grid(total, kEdtInf);
  RandomStream rng(seed, 0);
  std::vector<std::size_t> feats;
  for (int i = 0; i < features; ++i) {
    const std::size_t idx = rng.uniform_index(static_cast<std::uint32_t>(total));
    grid[idx] = 0.0f;
    feats.push_back(idx);
  }
  Scratch sc(maxd);
  squared_edt<D>(grid.data(), dims, sc.s);
  auto coords = [&](std::size_t idx, int* c) {
    for (int a = D - 1; a >= 0; --a) { c[a] = static_cast<int>(idx % dims[a]); idx /= dims[a]; }
  };
  for (std::size_t i = 0; i < total; ++i) {
    int ci[D];
    coords(i, ci);
    float best = kEdtInf;
    for (std::size_t fidx : feats) {
      int cf[D];
      coords(fidx, cf);
      float d2 = 0;
      for (int a = 0; a < D; ++a) d2 += static_cast<float>((ci[a] - cf[a]) * (ci[a] - cf[a]));
      best = std::min(best, d2);
    }
    ASSERT_FLOAT_EQ(grid[i], best) << "cell " << i;
  }
}

TEST(EdtTest, Matches2DBruteForce) {
  const std::size_t dims[2] = {23, 31};
  check_against_brute_force<2>(dims, 1, 12);
  check_against_brute_force<2>(dims, 2, 1);
}

TEST(EdtTest, Matches3DBruteForce) {
  const std::size_t dims[3] = {9, 11, 7};
  check_against_brute_force<3>(dims, 3, 10);
}

TEST(EdtTest, EmptyGridStaysInfinite) {
  std::vector<float> grid(50, kEdtInf);
  Scratch sc(10);
  const std::size_t dims[2] = {5, 10};
  squared_edt<2>(grid.data(), dims, sc.s);
  for (float v : grid) EXPECT_GE(v, kEdtInf);
}

}  // namespace
}  // namespace fw
