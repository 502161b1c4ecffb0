// Closed-form eigen-decomposition of a symmetric 2×2 matrix [[a, b], [b, c]]. Used instead of
// Eigen's SelfAdjointEigenSolver, whose generic code pulls malloc into the firmware libraries
// (the symbol check forbids it) for what is two lines of algebra.
#pragma once

#include <cmath>

namespace fw {

struct Sym2Eigen {
  float lambda_min = 0.0f, lambda_max = 0.0f;
  float vmin_x = 1.0f, vmin_y = 0.0f;  // unit eigenvector of lambda_min (the vector of lambda_max is its normal)
};

inline Sym2Eigen sym2_eigen(double a, double b, double c) {
  Sym2Eigen e;
  const double mean = 0.5 * (a + c), half = 0.5 * (a - c);
  const double r = std::sqrt(half * half + b * b);
  e.lambda_min = static_cast<float>(mean - r);
  e.lambda_max = static_cast<float>(mean + r);
  // (A − λ_min I) v = 0: v = (b, λ_min − a), or (λ_min − c, b); take the better conditioned one.
  double vx = b, vy = (mean - r) - a;
  const double ux = (mean - r) - c, uy = b;
  if (ux * ux + uy * uy > vx * vx + vy * vy) { vx = ux; vy = uy; }
  const double n = std::sqrt(vx * vx + vy * vy);
  if (n > 1e-12) {  // else A ∝ I: every direction is an eigenvector, keep (1, 0)
    e.vmin_x = static_cast<float>(vx / n);
    e.vmin_y = static_cast<float>(vy / n);
  }
  return e;
}

}  // namespace fw
