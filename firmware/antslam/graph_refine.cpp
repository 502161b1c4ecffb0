#include "firmware/antslam/graph_refine.h"

#include <cmath>

namespace fw::antslam {

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// Residual r = (P_i ⊖ P_j) − μ and its Jacobians A = ∂r/∂P_i, B = ∂r/∂P_j (P = x, y, θ):
// t = R_iᵀ (p_j − p_i), φ = θ_j − θ_i.
void linearise(const SampledEdge& e, const Se2d* poses, Vec3* r, Mat3* a, Mat3* b) {
  const Se2d& pi = poses[e.from];
  const Se2d& pj = poses[e.to];
  const double c = std::cos(pi.theta), s = std::sin(pi.theta);
  const double dx = pj.x - pi.x, dy = pj.y - pi.y;
  const Se2d t(c * dx + s * dy, -s * dx + c * dy, wrap_angle(pj.theta - pi.theta));
  *r = se2_difference(t, e.mean);
  *a << -c, -s, -s * dx + c * dy,  //
      s, -c, -c * dx - s * dy,     //
      0.0, 0.0, -1.0;
  *b << c, s, 0.0,  //
      -s, c, 0.0,   //
      0.0, 0.0, 1.0;
}

double dot(const Vec3* u, const Vec3* v, std::uint32_t n) {
  double d = 0.0;
  for (std::uint32_t i = 1; i < n; ++i) d += u[i].dot(v[i]);  // node 0 is held
  return d;
}

}  // namespace

Status GraphRefineOptions::validate() const {
  if (max_iterations == 0 || max_cg_iterations == 0 || !(cg_relative_tolerance > 0.0) ||
      !(min_relative_decrease >= 0.0)) {
    return Status::error(Errc::kInvalidArgument,
                         "graph refine: iterations must be > 0, tolerances > 0 (cg) and >= 0 (decrease)");
  }
  return Status::ok();
}

double graph_cost(const SampledEdge* edges, std::uint32_t num_edges, const Se2d* poses) {
  double w = 0.0;
  for (std::uint32_t k = 0; k < num_edges; ++k) {
    const SampledEdge& e = edges[k];
    w += mahalanobis2(poses[e.from].between(poses[e.to]), e.mean, e.info);
  }
  return w;
}

std::size_t GraphRefine::required_arena_bytes(std::uint32_t max_nodes, std::uint32_t max_edges) {
  return static_cast<std::size_t>(max_nodes) * (5 * sizeof(Vec3) + sizeof(Mat3) + sizeof(Se2d)) +
         static_cast<std::size_t>(max_edges) * 2 * sizeof(Mat3) + 8 * 64;
}

Status GraphRefine::init(const GraphRefineOptions& options, std::uint32_t max_nodes, std::uint32_t max_edges,
                         StartupArena& arena) {
  FW_RETURN_IF_ERROR(options.validate());
  options_ = options;
  max_nodes_ = max_nodes;
  max_edges_ = max_edges;
#define FW_GRAPH_ALLOC(ptr, T, count, what)          \
  do {                                               \
    auto r_ = arena.allocate_array<T>(count, what);  \
    if (!r_) return r_.status();                     \
    ptr = *r_;                                       \
  } while (0)
  FW_GRAPH_ALLOC(g_, Vec3, max_nodes, "graph refine gradient");
  FW_GRAPH_ALLOC(x_, Vec3, max_nodes, "graph refine step");
  FW_GRAPH_ALLOC(p_, Vec3, max_nodes, "graph refine direction");
  FW_GRAPH_ALLOC(q_, Vec3, max_nodes, "graph refine product");
  FW_GRAPH_ALLOC(z_, Vec3, max_nodes, "graph refine preconditioned");
  FW_GRAPH_ALLOC(dinv_, Mat3, max_nodes, "graph refine preconditioner");
  FW_GRAPH_ALLOC(trial_, Se2d, max_nodes, "graph refine trial");
  FW_GRAPH_ALLOC(jac_, Mat3, static_cast<std::size_t>(max_edges) * 2, "graph refine jacobians");
#undef FW_GRAPH_ALLOC
  return Status::ok();
}

void GraphRefine::apply_h(const SampledEdge* edges, std::uint32_t num_edges, const Vec3* v, Vec3* out,
                          std::uint32_t n) const {
  for (std::uint32_t i = 0; i < n; ++i) out[i].setZero();
  for (std::uint32_t k = 0; k < num_edges; ++k) {
    const SampledEdge& e = edges[k];
    const Mat3& a = jac_[2 * k];
    const Mat3& b = jac_[2 * k + 1];
    const Vec3 w = e.info * (a * v[e.from] + b * v[e.to]);
    out[e.from] += a.transpose() * w;
    out[e.to] += b.transpose() * w;
  }
  out[0].setZero();
}

Status GraphRefine::refine(const SampledEdge* edges, std::uint32_t num_edges, Se2d* poses, std::uint32_t n,
                           GraphRefineReport* report) {
  if (g_ == nullptr) return Status::error(Errc::kNotInitialized, "graph refine: init() not called");
  if (n > max_nodes_) {
    return Status::error(Errc::kCapacityExceeded, "graph refine: %u frames, capacity %u", n, max_nodes_);
  }
  if (num_edges > max_edges_) {
    return Status::error(Errc::kCapacityExceeded, "graph refine: %u edges, capacity %u", num_edges, max_edges_);
  }
  for (std::uint32_t k = 0; k < num_edges; ++k) {
    if (edges[k].from >= n || edges[k].to >= n) {
      return Status::error(Errc::kInvalidArgument, "graph refine: edge %u joins frame %u and %u of %u", k,
                           edges[k].from, edges[k].to, n);
    }
  }
  GraphRefineReport rep;
  double cost = graph_cost(edges, num_edges, poses);
  rep.initial_cost = rep.final_cost = cost;
  if (!std::isfinite(cost)) return Status::error(Errc::kInvalidArgument, "graph refine: the start cost is not finite");
  for (std::uint32_t it = 0; it < options_.max_iterations && n > 1; ++it) {
    // Gradient g = Σ Jᵀ Ω r and the diagonal blocks of H = Σ Jᵀ Ω J; the Jacobians are kept for
    // the conjugate-gradient products of this step.
    for (std::uint32_t i = 0; i < n; ++i) {
      g_[i].setZero();
      dinv_[i].setZero();
    }
    for (std::uint32_t k = 0; k < num_edges; ++k) {
      const SampledEdge& e = edges[k];
      Vec3 r;
      Mat3& a = jac_[2 * k];
      Mat3& b = jac_[2 * k + 1];
      linearise(e, poses, &r, &a, &b);
      const Vec3 w = e.info * r;
      g_[e.from] += a.transpose() * w;
      g_[e.to] += b.transpose() * w;
      dinv_[e.from] += a.transpose() * e.info * a;
      dinv_[e.to] += b.transpose() * e.info * b;
    }
    g_[0].setZero();
    for (std::uint32_t i = 0; i < n; ++i) {
      // A frame without a well-posed block (no edge) is held like frame 0.
      const double det = dinv_[i].determinant();
      dinv_[i] = i > 0 && std::isfinite(det) && det > 0.0 ? Mat3(dinv_[i].inverse()) : Mat3(Mat3::Zero());
    }
    // Preconditioned conjugate gradients on H δ = −g (residual kept in g_).
    const double g_norm = std::sqrt(dot(g_, g_, n));
    if (!(g_norm > 0.0)) break;
    for (std::uint32_t i = 0; i < n; ++i) {
      g_[i] = -g_[i];
      x_[i].setZero();
      z_[i] = dinv_[i] * g_[i];
      p_[i] = z_[i];
    }
    double rz = dot(g_, z_, n);
    std::uint32_t cg = 0;
    while (cg < options_.max_cg_iterations && std::sqrt(dot(g_, g_, n)) > options_.cg_relative_tolerance * g_norm) {
      apply_h(edges, num_edges, p_, q_, n);
      const double pq = dot(p_, q_, n);
      if (!(pq > 0.0)) break;  // H not positive along p: stop with what is solved
      const double alpha = rz / pq;
      for (std::uint32_t i = 0; i < n; ++i) {
        x_[i] += alpha * p_[i];
        g_[i] -= alpha * q_[i];
        z_[i] = dinv_[i] * g_[i];
      }
      const double rz_next = dot(g_, z_, n);
      const double beta = rz_next / rz;
      rz = rz_next;
      for (std::uint32_t i = 0; i < n; ++i) p_[i] = z_[i] + beta * p_[i];
      ++cg;
    }
    rep.cg_iterations += cg;
    // The step, halved while it does not lower W.
    bool lowered = false;
    double next = cost;
    for (double step = 1.0; step >= 0.125 && !lowered; step *= 0.5) {
      for (std::uint32_t i = 0; i < n; ++i) {
        const Vec3 d = step * x_[i];
        trial_[i] = Se2d(poses[i].x + d(0), poses[i].y + d(1), wrap_angle(poses[i].theta + d(2)));
      }
      next = graph_cost(edges, num_edges, trial_);
      lowered = std::isfinite(next) && next < cost;
    }
    if (!lowered) break;
    for (std::uint32_t i = 1; i < n; ++i) poses[i] = trial_[i];
    ++rep.iterations;
    const double decrease = cost - next;
    cost = next;
    if (decrease <= options_.min_relative_decrease * cost) break;
  }
  rep.final_cost = cost;
  if (report != nullptr) *report = rep;
  return Status::ok();
}

}  // namespace fw::antslam
