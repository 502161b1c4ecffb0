#include "firmware/mml/pose_refiner.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "firmware/map/distance_batch.h"
#include "firmware/scan/point_to_line.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define MMLFW_WIDE_REFINE_SUMS 1
#endif

namespace fw {
namespace mml {

namespace {

// One Gauss-Newton pass's sums over a batch of samples — PointToLineSystem::add_jacobian(gx, gy, jt,
// d, wd) per used sample, with the inlier count and Σ d² — for the passes that neither count the
// truncated cost nor are the last. Each sum is the scalar code's chain of IEEE products and sums in
// point order, so every build gives the same bits.
struct PassSums {
  double h[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};  // PointToLineSystem::h (lower triangle)
  double b[3] = {0, 0, 0};
  double sq = 0.0;
  std::size_t inl = 0;
};

void add_batch_scalar(const DistanceBatch& batch, std::size_t m, double wd, PassSums* p) {
  for (std::size_t j = 0; j < m; ++j) {
    if (!batch.use[j]) continue;
    const float d = batch.d[j];
    ++p->inl;
    p->sq += static_cast<double>(d) * d;
    const double jv[3] = {batch.gx[j], batch.gy[j], static_cast<double>(batch.jt[j])};
    const double wj[3] = {wd * jv[0], wd * jv[1], wd * jv[2]};
    for (int a = 0; a < 3; ++a)
      for (int e = 0; e <= a; ++e) p->h[3 * a + e] += wj[a] * jv[e];
    const double wr = wd * static_cast<double>(d);
    for (int a = 0; a < 3; ++a) p->b[a] += wr * jv[a];
  }
}

#ifdef MMLFW_WIDE_REFINE_SUMS
// The same with the ten sums in three vectors (lanes: h00 h10 h11 h20 | h21 h22 b0 b1 | b2 sq): one
// vector multiply and add per lane group instead of ten scalar ones, each lane still the chain of
// products and sums of the scalar code (no fused multiply-add: separate IEEE multiply and add).
__attribute__((target("avx2"))) void add_batch_avx2(const DistanceBatch& batch, std::size_t m, double wd,
                                                    PassSums* p) {
  // The vectors continue the pass's chains from the batches before this one.
  __m256d s1 = _mm256_setr_pd(p->h[0], p->h[3], p->h[4], p->h[6]);
  __m256d s2 = _mm256_setr_pd(p->h[7], p->h[8], p->b[0], p->b[1]);
  __m128d s3 = _mm_setr_pd(p->b[2], p->sq);
  const __m256d w = _mm256_set1_pd(wd);
  std::size_t inl = 0;
  for (std::size_t j = 0; j < m; ++j) {
    if (!batch.use[j]) continue;
    ++inl;
    // j4 = (gx, gy, jt, d) as doubles; wj4 = wd·j4 = (wj0, wj1, wj2, wr).
    const __m256d j4 = _mm256_cvtps_pd(_mm_setr_ps(batch.gx[j], batch.gy[j], batch.jt[j], batch.d[j]));
    const __m256d wj4 = _mm256_mul_pd(w, j4);
    // h00 = wj0·j0, h10 = wj1·j0, h11 = wj1·j1, h20 = wj2·j0
    s1 = _mm256_add_pd(s1, _mm256_mul_pd(_mm256_permute4x64_pd(wj4, _MM_SHUFFLE(2, 1, 1, 0)),
                                         _mm256_permute4x64_pd(j4, _MM_SHUFFLE(0, 1, 0, 0))));
    // h21 = wj2·j1, h22 = wj2·j2, b0 = wr·j0, b1 = wr·j1
    s2 = _mm256_add_pd(s2, _mm256_mul_pd(_mm256_permute4x64_pd(wj4, _MM_SHUFFLE(3, 3, 2, 2)),
                                         _mm256_permute4x64_pd(j4, _MM_SHUFFLE(1, 0, 2, 1))));
    // b2 = wr·j2, sq: d·d
    const __m256d a3 = _mm256_blend_pd(_mm256_permute4x64_pd(wj4, _MM_SHUFFLE(3, 3, 3, 3)), j4, 0x8);
    const __m256d b3 = _mm256_permute4x64_pd(j4, _MM_SHUFFLE(3, 3, 3, 2));
    const __m256d p3 = _mm256_mul_pd(a3, b3);  // lanes 0 and 3: wr·j2, d·d
    s3 = _mm_add_pd(s3, _mm_blend_pd(_mm256_castpd256_pd128(p3), _mm256_extractf128_pd(p3, 1), 0x2));
  }
  alignas(32) double v1[4], v2[4], v3[2];
  _mm256_store_pd(v1, s1);
  _mm256_store_pd(v2, s2);
  _mm_store_pd(v3, s3);
  p->h[0] = v1[0];
  p->h[3] = v1[1];
  p->h[4] = v1[2];
  p->h[6] = v1[3];
  p->h[7] = v2[0];
  p->h[8] = v2[1];
  p->b[0] = v2[2];
  p->b[1] = v2[3];
  p->b[2] = v3[0];
  p->sq = v3[1];
  p->inl += inl;
}
#endif

}  // namespace

RefineResult refine_pose(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& initial,
                         const RefineOptions& o, DistanceBatchBuild build) {
  RefineResult r;
  r.pose = initial;
  if (!map.valid() || n == 0) return r;
  Se2f t = initial;
  DistanceBatch batch;  // the samples of one pass, kDistanceBatch end-points at a time
  std::size_t inl = 0;
  double sq = 0.0;
  PointToLineSystem sys;  // the shared 2-D solver (firmware/scan/point_to_line.h)
  // The truncated cost (RefineResult::cost) of the first pass (at `initial`) and of the latest one
  // (at t): the pass's clip is clip_m or 2·clip_m, and d ≤ clip_m implies d ≤ 2·clip_m, so every
  // sample truncated_scan_cost would count at clip_m is among this pass's used ones.
  // Counted only on the first pass and on the final one (it == iterations: no step follows it), the
  // two poses RefineResult::pose can be; a loop cut short (too few inliers, a degenerate step) leaves
  // an accepted result without it (cost_valid false).
  const double clip2 = static_cast<double>(o.clip_m) * o.clip_m;
  double first_cost = 0.0, last_cost = 0.0;
  bool have_last = false;
#ifdef MMLFW_WIDE_REFINE_SUMS
  const bool wide = build == DistanceBatchBuild::kBest && wide_distance_batch_available();  // the sums' AVX2 build
#endif
  for (std::uint32_t it = 0; it <= o.iterations; ++it) {
    sys.clear();
    const float c = std::cos(t.theta), s = std::sin(t.theta);
    inl = 0;
    sq = 0.0;
    double cost = 0.0;
    const float clip = (it < o.iterations / 2) ? 2.0f * o.clip_m : o.clip_m;
    const double wd = 1.0 / (static_cast<double>(o.sigma_m) * o.sigma_m);
    // The last pass only counts (no step follows it): the alias check refines ~36 rivals per scan.
    const bool last = it == o.iterations;
    const bool count_cost = it == 0 || last;
    if (!count_cost) {
      // A middle pass: only the normal equations, the inlier count and Σ d² (PassSums).
      PassSums ps;
      for (std::size_t i0 = 0; i0 < n; i0 += kDistanceBatch) {
        const std::size_t m = n - i0 < kDistanceBatch ? n - i0 : kDistanceBatch;
        sample_distance_batch(map, points + i0, m, t.x, t.y, c, s, clip, &batch, build);
#ifdef MMLFW_WIDE_REFINE_SUMS
        if (wide) {
          add_batch_avx2(batch, m, wd, &ps);
          continue;
        }
#endif
        add_batch_scalar(batch, m, wd, &ps);
      }
      inl = ps.inl;
      sq = ps.sq;
      for (int k = 0; k < 9; ++k) sys.h[k] = ps.h[k];
      for (int k = 0; k < 3; ++k) sys.b[k] = ps.b[k];
    }
    for (std::size_t i0 = 0; count_cost && i0 < n; i0 += kDistanceBatch) {  // the first and last pass
      const std::size_t m = n - i0 < kDistanceBatch ? n - i0 : kDistanceBatch;
      sample_distance_batch(map, points + i0, m, t.x, t.y, c, s, clip, &batch, build);
      for (std::size_t j = 0; j < m; ++j) {
        if (!batch.use[j]) {
          if (count_cost) cost += 1.0;  // off the map or beyond the clip: the full cost (truncated_scan_cost)
          continue;
        }
        const float d = batch.d[j];
        ++inl;
        const double dd = static_cast<double>(d) * d;
        sq += dd;
        if (count_cost) cost += d > o.clip_m ? 1.0 : dd / clip2;
        // On the distance field: residual d, normal ∇d.
        if (!last) sys.add_jacobian(batch.gx[j], batch.gy[j], batch.jt[j], d, wd);
      }
    }
    if (it == 0) first_cost = cost;
    if (last) {
      last_cost = cost;
      have_last = true;
    }
    if (it == o.iterations || inl < 3) break;
    // Prior N(initial, diag(σ_xy², σ_xy², σ_θ²)) and a Levenberg damping of 1e-6 of the scale.
    const double pxy = 1.0 / (static_cast<double>(o.prior_sigma_xy_m) * o.prior_sigma_xy_m);
    const double pth = 1.0 / (static_cast<double>(o.prior_sigma_theta_rad) * o.prior_sigma_theta_rad);
    const Eigen::Vector3d offset(t.x - initial.x, t.y - initial.y, wrap_angle(t.theta - initial.theta));
    Eigen::Vector3d dx;
    if (!sys.solve(&dx, pxy, pth, offset, 1e-6)) break;
    t = Se2f(t.x + static_cast<float>(dx(0)), t.y + static_cast<float>(dx(1)), wrap_angle(t.theta + static_cast<float>(dx(2))));
    if (dx.head<2>().norm() < 1e-4 && std::fabs(dx(2)) < 1e-4) {
      // Converged: one more pass computes the final statistics.
      it = o.iterations - 1;
    }
  }
  r.inlier_ratio = static_cast<float>(inl) / static_cast<float>(n);
  r.rms_m = inl ? static_cast<float>(std::sqrt(sq / inl)) : 0.0f;
  const float shift = std::hypot(t.x - initial.x, t.y - initial.y);
  r.accepted = r.inlier_ratio >= o.min_inlier_ratio && shift <= o.max_shift_m;
  r.pose = r.accepted ? t : initial;
  // t is the pose of the last pass (the loop ends with a pass, never with a step).
  r.cost_valid = o.clip_m > 0.0f && (!r.accepted || have_last);
  if (r.cost_valid) r.cost = static_cast<float>((r.accepted ? last_cost : first_cost) / static_cast<double>(n));
  return r;
}

}  // namespace mml
}  // namespace fw
