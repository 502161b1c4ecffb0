// Loop closures confirmed in pairs (an extension of Alg. 3's closure gate, not in the dissertation).
//
// Alg. 3 accepts pRANSAM's closure h (F_a in F_c) when it lies within the gate of the prediction x,
// the path c → a compounded with the front end's Eq. 3.4 drift. Along aces's long corridors the front
// end drifts 1.6–5 m before a revisit, 2–13 σ of that model, so true closures fail the gate; a wider
// model does not help because the corridors' aliases (whole fragments matched 7–18 m along) then pass
// as well (README, AntSLAM section: true closures and aliases overlap in χ² against x).
//
// What does separate them is agreement between closures of *different* active fragments: when a and
// a later a' both match the old part of the map, the two closures and the two short chains between
// them form a cycle a → c → c' → a' → a,
//   x_cycle = h_a⁻¹ ⊕ T(c → c') ⊕ h_a' ⊖ T(a → a'),
// which is the identity when both closures are right. The chains are short (a few fragments), so
// their drift is small, and an alias of one fragment does not continue into the next fragment with
// the same shift unless the building repeats itself over both (a → a' spans up to 15 m of path). Two
// closures of the *same* active fragment (a against c and c+1) agree whenever the fragment aliases
// consistently, so they never pair (measured on aces: fragment 34 against 0, 1 and 2, all 14 m off).
// The heading is not given up: what the drift model misses is translation along a corridor (the
// scan's weak axis), while every wall holds the front end's heading, so both closures of a pair
// must pass the same gate in heading alone (1 dof). A corridor walked the other way matches its own
// walls turned by 180° (measured on aces with the RBSM front end: two successive fragments flipped
// alike, heading 177° off the prediction at σ 2°, 80 σ); true closures of every log stayed within
// 3.5 σ in heading.
// When the current fragment's closure pairs with an earlier one, the loop is closed with it even though
// it failed the single gate. If two of the current fragment's candidates pair but disagree with each
// other, nothing is closed (the revisit is ambiguous).
#pragma once

#include <cstdint>

#include "firmware/antslam/sampled_edge.h"

namespace fw::antslam {

// A pRANSAM closure that passed the quality threshold (gated out or not).
struct ClosureCandidate {
  std::uint32_t a = 0, c = 0;  // active fragment, candidate fragment
  Se2d h;                      // F_a in F_c
  Mat3 cov_h = Mat3::Identity();
  Vec3 dh = Vec3::Zero();      // h − x against the prediction when it was matched
  float quality = 0.0f;
  float gate_chi2 = 0.0f;      // against the prediction x
  float heading_chi2 = 0.0f;   // its heading alone: dθ² / (σ²_θ,x + σ²_θ,h)
};

// χ² of the cycle a → c → c' → a' → a for closures p (a, c) and q (a', c'): `cc` = F_c' in F_c with
// covariance cov_cc (identity, zero when c' = c), `aa` = F_a' in F_a with covariance cov_aa. First-order
// propagation of all four covariances (firmware/base/se2.h Jacobians).
double pair_cycle_chi2(const ClosureCandidate& p, const ClosureCandidate& q, const Se2d& cc, const Mat3& cov_cc,
                       const Se2d& aa, const Mat3& cov_aa);

// Gated-out candidates of the last few active fragments: a fixed ring, no heap.
class ClosureCandidateRing {
 public:
  static constexpr std::uint32_t kCapacity = 32;  // pair_window × max_candidates (defaults: 6) with room
  void clear() { size_ = 0; }
  // Drops candidates whose active fragment is more than `window` fragments before `a`.
  void expire(std::uint32_t a, std::uint32_t window);
  // Appends; the oldest is dropped when full.
  void push(const ClosureCandidate& c);
  std::uint32_t size() const { return size_; }
  const ClosureCandidate& operator[](std::uint32_t i) const { return items_[i]; }

 private:
  ClosureCandidate items_[kCapacity];
  std::uint32_t size_ = 0;
};

}  // namespace fw::antslam
