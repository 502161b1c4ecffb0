// particle_weights.h: the AVX2 build gives the portable build's weights bit for bit, and both are
// the summed likelihood of Eq. 2.8 on the end-point grid.
#include "firmware/rbsm/particle_weights.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "firmware/base/rng.h"
#include "firmware/base/arena.h"

namespace {

struct Scene {
  std::vector<unsigned char> block;
  fw::StartupArena arena;
  fw::EndpointGrid grid;
  std::vector<float> px, py, x, y, c, s;
  // A room of random wall cells, a scan of 181 points, 1000 particles scattered around the origin
  // (some far enough that points fall outside the window: the zero sentinel).
  void make() {
    fw::EndpointGridOptions o;
    o.size_log2 = 8;  // 256 cells = 12.8 m
    block.assign(fw::EndpointGrid::required_bytes(o) + 256, 0);
    ASSERT_TRUE(arena.init(block.data(), block.size(), "test").is_ok());
    ASSERT_TRUE(grid.init(o, arena).is_ok());
    grid.center_on(0, 0);
    fw::RandomStream rng;
    rng.reseed(7, 0);
    for (int i = 0; i < 400; ++i) {
      const float t = static_cast<float>(i) * 0.0157f;
      grid.insert(4.0f * std::cos(t), 3.0f * std::sin(t));
    }
    for (int i = 0; i < 181; ++i) {
      const float a = -1.5708f + 0.01745f * static_cast<float>(i);
      const float r = 3.0f + 0.5f * static_cast<float>(rng.gaussian());
      px.push_back(r * std::cos(a));
      py.push_back(r * std::sin(a));
    }
    for (int j = 0; j < 1000; ++j) {
      x.push_back(0.3f * static_cast<float>(rng.gaussian()) + (j % 97 == 0 ? 6.0f : 0.0f));
      y.push_back(0.3f * static_cast<float>(rng.gaussian()));
      const float th = 0.2f * static_cast<float>(rng.gaussian());
      c.push_back(std::cos(th));
      s.push_back(std::sin(th));
    }
  }
  std::vector<std::uint32_t> weigh(bool wide, std::uint32_t begin, std::uint32_t end) {
    std::vector<std::uint32_t> w(x.size(), 0xdeadbeefu);
    const fw::ParticleBlock b{x.data(), y.data(), c.data(), s.data(), w.data(), begin, end};
    fw::weigh_particles(grid.lookup_view(), px.data(), py.data(), static_cast<std::uint32_t>(px.size()), b, wide);
    return w;
  }
};

TEST(ParticleWeights, WideBuildEqualsPortableBitForBit) {
  if (!fw::wide_particle_weights_available()) {
    GTEST_SKIP() << "this CPU has no AVX2 build of the particle weights (only the portable one runs here)";
  }
  Scene sc;
  sc.make();
  // Odd bounds: chunks of 256 plus a tail that is not a multiple of the vector width.
  const auto portable = sc.weigh(false, 3, 997);
  const auto wide = sc.weigh(true, 3, 997);
  EXPECT_EQ(portable, wide);
  EXPECT_EQ(portable[0], 0xdeadbeefu);  // outside [begin, end) untouched
  EXPECT_EQ(portable[997], 0xdeadbeefu);
}

TEST(ParticleWeights, AreTheSummedLikelihoodOfEq28) {
  Scene sc;
  sc.make();
  for (const bool wide : {false, true}) {
    const auto w = sc.weigh(wide, 0, 1000);
    std::uint64_t nonzero = 0;
    for (std::uint32_t j = 0; j < 1000; ++j) {
      // Reference: the grid's own likelihood lookup of every transformed point (world coordinates;
      // a point on a sub-cell border may round to the neighbour, so allow a few δ of 255).
      std::uint64_t ref = 0;
      for (std::size_t i = 0; i < sc.px.size(); ++i) {
        const float wx = sc.x[j] + sc.c[j] * sc.px[i] - sc.s[j] * sc.py[i];
        const float wy = sc.y[j] + sc.s[j] * sc.px[i] + sc.c[j] * sc.py[i];
        ref += sc.grid.likelihood(wx, wy);
      }
      EXPECT_NEAR(static_cast<double>(w[j]), static_cast<double>(ref), 3 * 255.0) << "particle " << j;
      if (w[j] > 0) ++nonzero;
    }
    EXPECT_GT(nonzero, 900u);  // the scene is not empty: the comparison says something
  }
}

}  // namespace
