// Every Jacobian of se2.h checked against central finite differences.
#include "firmware/base/se2.h"

#include <gtest/gtest.h>

namespace fw {
namespace {

using Mat3 = Eigen::Matrix<double, 3, 3>;
using Vec3 = Eigen::Matrix<double, 3, 1>;

Vec3 diff(const Se2d& a, const Se2d& b) {
  return Vec3(a.x - b.x, a.y - b.y, wrap_angle(a.theta - b.theta));
}

template <typename F>
Mat3 numeric_jacobian(const Se2d& at, F f) {
  const double h = 1e-6;
  Mat3 j;
  for (int k = 0; k < 3; ++k) {
    Vec3 dp = Vec3::Zero(), dm = Vec3::Zero();
    dp(k) = h;
    dm(k) = -h;
    const Se2d p = Se2d::from_vector(at.vector() + dp), m = Se2d::from_vector(at.vector() + dm);
    j.col(k) = diff(f(p), f(m)) / (2 * h);
  }
  return j;
}

class Se2JacobianTest : public ::testing::TestWithParam<int> {
 protected:
  Se2d a() const {
    const int i = GetParam();
    return Se2d(0.3 * i - 1.0, 2.0 - 0.7 * i, -3.0 + 0.9 * i);
  }
  Se2d b() const {
    const int i = GetParam();
    return Se2d(1.5 - 0.2 * i, 0.4 * i, 2.5 - 0.8 * i);
  }
};

TEST_P(Se2JacobianTest, ComposeFirst) {
  const Se2d bb = b();
  EXPECT_TRUE(a().jacobian_compose_first(bb).isApprox(
      numeric_jacobian(a(), [&](const Se2d& p) { return p.compose(bb); }), 1e-6));
}
TEST_P(Se2JacobianTest, ComposeSecond) {
  const Se2d aa = a();
  EXPECT_TRUE(aa.jacobian_compose_second().isApprox(
      numeric_jacobian(b(), [&](const Se2d& p) { return aa.compose(p); }), 1e-6));
}
TEST_P(Se2JacobianTest, Inverse) {
  EXPECT_TRUE(a().jacobian_inverse().isApprox(numeric_jacobian(a(), [](const Se2d& p) { return p.inverse(); }), 1e-6));
}
TEST_P(Se2JacobianTest, BetweenFirst) {
  const Se2d bb = b();
  EXPECT_TRUE(a().jacobian_between_first(bb).isApprox(
      numeric_jacobian(a(), [&](const Se2d& p) { return p.between(bb); }), 1e-6));
}
TEST_P(Se2JacobianTest, BetweenSecond) {
  const Se2d aa = a();
  EXPECT_TRUE(aa.jacobian_between_second().isApprox(
      numeric_jacobian(b(), [&](const Se2d& p) { return aa.between(p); }), 1e-6));
}

INSTANTIATE_TEST_SUITE_P(Poses, Se2JacobianTest, ::testing::Range(0, 8));

TEST(Se2Test, ComposeInverseIsIdentity) {
  const Se2d a(1.0, -2.0, 0.7);
  const Se2d i = a.compose(a.inverse());
  EXPECT_NEAR(i.x, 0, 1e-12);
  EXPECT_NEAR(i.y, 0, 1e-12);
  EXPECT_NEAR(i.theta, 0, 1e-12);
  const Se2d b(0.5, 0.25, -2.0);
  const Se2d r = a.between(a.compose(b));
  EXPECT_NEAR(r.x, b.x, 1e-12);
  EXPECT_NEAR(r.y, b.y, 1e-12);
  EXPECT_NEAR(r.theta, b.theta, 1e-12);
}

TEST(Se2Test, WrapAngle) {
  EXPECT_NEAR(wrap_angle(3.5), 3.5 - 2 * M_PI, 1e-12);
  EXPECT_NEAR(wrap_angle(-3.5), -3.5 + 2 * M_PI, 1e-12);
  EXPECT_NEAR(wrap_angle(M_PI), M_PI, 1e-12);
}

TEST(Se2Test, CovariancePropagationEq34) {
  PoseWithCovariance<double> x, u;
  x.pose = Se2d(1, 2, 0.5);
  x.cov = Mat3::Identity() * 0.01;
  u.pose = Se2d(1, 0, 0.1);
  u.cov = Mat3::Identity() * 0.001;
  const auto out = compose_with_covariance(x, u);
  // Covariance grows and stays symmetric.
  EXPECT_TRUE(out.cov.isApprox(out.cov.transpose()));
  EXPECT_GT(out.cov.trace(), x.cov.trace());
  const auto rel = between_with_covariance(x, x);
  EXPECT_NEAR(rel.pose.x, 0, 1e-12);
  EXPECT_GT(rel.cov.trace(), 0);
}

}  // namespace
}  // namespace fw
