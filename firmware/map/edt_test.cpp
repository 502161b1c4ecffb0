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

// Long rows (beyond 4096 cells, where q² is no longer exact in float): features must keep distance
// 0 and every cell must match brute force. Regression: the fr-clinic map (4404 cells wide) had
// occupied cells at √2 cells before the intersection formula was made relative.
TEST(EdtTest, LongRowsStayExact) {
  const std::size_t dims[2] = {3, 6000};
  std::vector<float> grid(dims[0] * dims[1], kEdtInf);
  // Dense feature runs far from the origin plus a few isolated ones with finite column values.
  std::vector<std::size_t> feats;
  for (std::size_t x = 4200; x < 4300; x += 1) feats.push_back(1 * dims[1] + x);
  for (std::size_t x = 5000; x < 5990; x += 3) feats.push_back(0 * dims[1] + x);
  feats.push_back(2 * dims[1] + 10);
  feats.push_back(2 * dims[1] + 5999);
  for (std::size_t f : feats) grid[f] = 0.0f;
  Scratch sc(dims[1]);
  squared_edt<2>(grid.data(), dims, sc.s);
  for (std::size_t f : feats) ASSERT_EQ(grid[f], 0.0f) << "feature " << f;
  for (std::size_t y = 0; y < dims[0]; ++y) {
    for (std::size_t x = 0; x < dims[1]; x += 7) {
      double best = 1e30;
      for (std::size_t f : feats) {
        const double dy = static_cast<double>(y) - static_cast<double>(f / dims[1]);
        const double dx = static_cast<double>(x) - static_cast<double>(f % dims[1]);
        best = std::min(best, dx * dx + dy * dy);
      }
      ASSERT_EQ(grid[y * dims[1] + x], static_cast<float>(best)) << y << "," << x;
    }
  }
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
