// The ant-colony optimisation of AntSLAM (Ch. 3, Alg. 3, Eq. 3.13–3.14; SPEC §2). A hypothesis H
// picks one of the S options of every free edge of the loop L; its cost is W(H) of Eq. 3.13. Ant k
// builds H edge by edge: with probability p0 it picks an option uniformly, otherwise option j with
// p = τ_j / Σ τ (Eq. 3.14). p0 starts at p0_start and grows by the factor 1/δ per iteration up to
// p0_max (δ = 10/11). Pheromones are MAX–MIN (τ ∈ [τ_min, τ_max], all start at τ_max): every
// iteration they evaporate by ρ, then every glob_best_freq-th iteration all ants deposit Δτ = 1/W
// on their options, otherwise only the global best so far.
//
// Deterministic per seed: ant k owns RandomStream(seed, k); ants of one iteration are built and
// rated in parallel over the optional WorkerPool (whole ants per worker), pheromones are updated
// afterwards in ant order, so 1 or N workers give the same H. Storage from the arena in init().
#pragma once

#include <cstdint>

#include "firmware/antslam/loop_problem.h"
#include "firmware/base/arena.h"
#include "firmware/base/rng.h"
#include "firmware/base/status.h"
#include "firmware/base/worker_pool.h"

namespace fw::antslam {

struct AntColonyOptions {
  std::uint32_t ants = 20;              // thesis: 20
  std::uint32_t iterations = 5000;      // thesis: 5000
  std::uint32_t glob_best_freq = 10;    // GlobBestFreq: every n-th iteration all ants deposit
  double p0_start = 0.1;                // uniform-choice probability at the start …
  double p0_max = 0.3;                  // … growing by 1/δ per iteration up to this
  double delta = 10.0 / 11.0;           // δ
  double tau_min = 1e-6, tau_max = 1.0; // MAX–MIN bounds
  double evaporation = 0.02;            // ρ (not given in the digest; MAX–MIN needs one)
  std::uint32_t stall_iterations = 0;   // stop after this many iterations without a better H (0: never)
  std::uint64_t seed = 1;
  Status validate() const;
};

struct AntColonyReport {
  std::uint32_t iterations = 0;
  double initial_cost = 0.0;  // W of the uncorrected map (option 0 everywhere)
  double best_cost = 0.0;
};

class AntColony {
 public:
  static std::size_t required_arena_bytes(const AntColonyOptions& options, std::uint32_t max_steps,
                                          std::uint32_t max_options);
  Status init(const AntColonyOptions& options, std::uint32_t max_steps, std::uint32_t max_options,
              StartupArena& arena, WorkerPool* pool = nullptr);
  const AntColonyOptions& options() const { return options_; }
  AntColonyOptions& mutable_options() { return options_; }

  // Solves one loop; values[i] receives the forward-direction transform chosen for step i (a
  // frozen step: its value). `loop_index` varies the ants' streams between loops.
  Status solve(const LoopProblem& problem, std::uint64_t loop_index, Se2d* values, AntColonyReport* report);

 private:
  static void job_entry(void* context, int worker, int num_workers);
  void build_ant(std::uint32_t k);

  AntColonyOptions options_;
  WorkerPool* pool_ = nullptr;
  bool initialized_ = false;
  std::uint32_t max_steps_ = 0, max_options_ = 0;
  double* tau_ = nullptr;            // [step][option]
  std::uint16_t* choice_ = nullptr;  // [ant][step]
  std::uint16_t* best_ = nullptr;    // [step]
  double* cost_ = nullptr;           // [ant]
  RandomStream* streams_ = nullptr;  // [ant]
  // Per-solve state read by the workers.
  const LoopProblem* problem_ = nullptr;
  double p0_ = 0.0;
};

}  // namespace fw::antslam
