#include "firmware/antslam/ant_colony.h"

#include <algorithm>
#include <cmath>

namespace fw::antslam {

Status AntColonyOptions::validate() const {
  if (ants == 0 || ants > 1024) return Status::error(Errc::kInvalidArgument, "ant colony: ants %u not in 1..1024", ants);
  if (iterations == 0) return Status::error(Errc::kInvalidArgument, "ant colony: iterations must be > 0");
  if (glob_best_freq == 0) return Status::error(Errc::kInvalidArgument, "ant colony: glob_best_freq must be > 0");
  if (!(p0_start >= 0.0 && p0_start <= p0_max && p0_max <= 1.0)) {
    return Status::error(Errc::kInvalidArgument, "ant colony: need 0 <= p0_start <= p0_max <= 1");
  }
  if (!(delta > 0.0 && delta <= 1.0)) return Status::error(Errc::kInvalidArgument, "ant colony: delta not in (0, 1]");
  if (!(tau_min > 0.0 && tau_min < tau_max)) return Status::error(Errc::kInvalidArgument, "ant colony: need 0 < tau_min < tau_max");
  if (!(evaporation >= 0.0 && evaporation < 1.0)) {
    return Status::error(Errc::kInvalidArgument, "ant colony: evaporation not in [0, 1)");
  }
  return Status::ok();
}

std::size_t AntColony::required_arena_bytes(const AntColonyOptions& o, std::uint32_t max_steps,
                                            std::uint32_t max_options) {
  const std::size_t s = max_steps, a = o.ants;
  return s * max_options * sizeof(double) + (a + 1) * s * sizeof(std::uint16_t) + a * sizeof(double) +
         a * sizeof(RandomStream) + 6 * 64;
}

Status AntColony::init(const AntColonyOptions& options, std::uint32_t max_steps, std::uint32_t max_options,
                       StartupArena& arena, WorkerPool* pool) {
  FW_RETURN_IF_ERROR(options.validate());
  if (max_steps == 0 || max_options == 0 || max_options > 65535) {
    return Status::error(Errc::kInvalidArgument, "ant colony: max_steps %u / max_options %u out of range", max_steps,
                         max_options);
  }
  options_ = options;
  max_steps_ = max_steps;
  max_options_ = max_options;
  pool_ = pool;
  auto tau = arena.allocate_array<double>(static_cast<std::size_t>(max_steps) * max_options, "aco pheromones");
  if (!tau) return tau.status();
  auto choice = arena.allocate_array<std::uint16_t>(static_cast<std::size_t>(options.ants) * max_steps, "aco choices");
  if (!choice) return choice.status();
  auto best = arena.allocate_array<std::uint16_t>(max_steps, "aco best");
  if (!best) return best.status();
  auto cost = arena.allocate_array<double>(options.ants, "aco costs");
  if (!cost) return cost.status();
  auto streams = arena.allocate_array<RandomStream>(options.ants, "aco streams");
  if (!streams) return streams.status();
  tau_ = *tau;
  choice_ = *choice;
  best_ = *best;
  cost_ = *cost;
  streams_ = *streams;
  initialized_ = true;
  return Status::ok();
}

void AntColony::build_ant(std::uint32_t k) {
  const LoopProblem& p = *problem_;
  RandomStream& rng = streams_[k];
  std::uint16_t* choice = choice_ + static_cast<std::size_t>(k) * max_steps_;
  double w = 0.0;
  Se2d x;
  for (std::uint32_t i = 0; i < p.num_steps; ++i) {
    const SampledEdge& e = *p.steps[i].edge;
    if (e.frozen) {
      choice[i] = 0;
      x = x.compose(step_transform(p.steps[i], e.value));
      continue;
    }
    const double* tau = tau_ + static_cast<std::size_t>(i) * max_options_;
    std::uint32_t j = 0;
    if (rng.uniform01() < p0_) {
      j = rng.uniform_index(e.num_options);  // uniform exploration with probability p0
    } else {                                 // Eq. 3.14: p_j = τ_j / Σ τ
      double sum = 0.0;
      for (std::uint32_t m = 0; m < e.num_options; ++m) sum += tau[m];
      double r = rng.uniform01() * sum;
      j = e.num_options - 1;
      for (std::uint32_t m = 0; m < e.num_options; ++m) {
        r -= tau[m];
        if (r < 0.0) {
          j = m;
          break;
        }
      }
    }
    choice[i] = static_cast<std::uint16_t>(j);
    w += e.option_cost[j];  // Eq. 3.13, first sum
    x = x.compose(edge_option(e, j, p.steps[i].forward));
  }
  cost_[k] = w + closure_cost(p, x);  // Eq. 3.13, closure term
}

void AntColony::job_entry(void* context, int worker, int num_workers) {
  AntColony* self = static_cast<AntColony*>(context);
  std::size_t begin = 0, end = 0;
  WorkerPool::partition(self->options_.ants, worker, num_workers, &begin, &end);
  for (std::size_t k = begin; k < end; ++k) self->build_ant(static_cast<std::uint32_t>(k));
}

Status AntColony::solve(const LoopProblem& problem, std::uint64_t loop_index, Se2d* values, AntColonyReport* report) {
  if (!initialized_) return Status::error(Errc::kNotInitialized, "ant colony: init() not called");
  FW_RETURN_IF_ERROR(validate_loop(problem));
  if (problem.num_steps > max_steps_) {
    return Status::error(Errc::kCapacityExceeded, "ant colony: loop of %u edges exceeds max_steps %u", problem.num_steps,
                         max_steps_);
  }
  for (std::uint32_t i = 0; i < problem.num_steps; ++i) {
    const SampledEdge& e = *problem.steps[i].edge;
    if (!e.frozen && (e.num_options == 0 || e.num_options > max_options_)) {
      return Status::error(Errc::kCapacityExceeded, "ant colony: edge %u->%u has %u options (max %u)", e.from, e.to,
                           e.num_options, max_options_);
    }
  }
  problem_ = &problem;
  const std::uint32_t n = problem.num_steps;
  for (std::size_t i = 0; i < static_cast<std::size_t>(n) * max_options_; ++i) tau_[i] = options_.tau_max;
  for (std::uint32_t k = 0; k < options_.ants; ++k) {
    streams_[k].reseed(options_.seed, loop_index * 4096u + k);
  }
  // The uncorrected map (option 0 = μ everywhere) is the first global best.
  for (std::uint32_t i = 0; i < n; ++i) best_[i] = 0;
  double best_cost = 0.0;
  {
    Se2d x;
    for (std::uint32_t i = 0; i < n; ++i) {
      const SampledEdge& e = *problem.steps[i].edge;
      x = x.compose(step_transform(problem.steps[i], e.frozen ? e.value : e.options[0]));
      if (!e.frozen) best_cost += e.option_cost[0];
    }
    best_cost += closure_cost(problem, x);
  }
  if (report) report->initial_cost = best_cost;
  p0_ = options_.p0_start;
  std::uint32_t since_better = 0, it = 0;
  const bool parallel = pool_ != nullptr && pool_->size() > 1 && n >= 32;
  for (it = 0; it < options_.iterations; ++it) {
    if (parallel) {
      pool_->run(&AntColony::job_entry, this);
    } else {
      for (std::uint32_t k = 0; k < options_.ants; ++k) build_ant(k);
    }
    bool improved = false;
    for (std::uint32_t k = 0; k < options_.ants; ++k) {
      if (cost_[k] < best_cost) {
        best_cost = cost_[k];
        const std::uint16_t* c = choice_ + static_cast<std::size_t>(k) * max_steps_;
        for (std::uint32_t i = 0; i < n; ++i) best_[i] = c[i];
        improved = true;
      }
    }
    // MAX–MIN update: evaporation, then deposit Δτ = 1/W.
    const double keep = 1.0 - options_.evaporation;
    for (std::size_t i = 0; i < static_cast<std::size_t>(n) * max_options_; ++i) tau_[i] *= keep;
    auto deposit = [&](const std::uint16_t* c, double w) {
      const double d = 1.0 / std::max(w, 1e-12);
      for (std::uint32_t i = 0; i < n; ++i) tau_[static_cast<std::size_t>(i) * max_options_ + c[i]] += d;
    };
    if ((it + 1) % options_.glob_best_freq == 0) {
      for (std::uint32_t k = 0; k < options_.ants; ++k) deposit(choice_ + static_cast<std::size_t>(k) * max_steps_, cost_[k]);
    } else {
      deposit(best_, best_cost);
    }
    for (std::size_t i = 0; i < static_cast<std::size_t>(n) * max_options_; ++i) {
      tau_[i] = std::min(options_.tau_max, std::max(options_.tau_min, tau_[i]));
    }
    p0_ = std::min(options_.p0_max, p0_ / options_.delta);  // p0 schedule
    since_better = improved ? 0 : since_better + 1;
    if (options_.stall_iterations > 0 && since_better >= options_.stall_iterations) {
      ++it;
      break;
    }
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    const SampledEdge& e = *problem.steps[i].edge;
    values[i] = e.frozen ? e.value : e.options[best_[i]];
  }
  if (report) {
    report->iterations = it;
    report->best_cost = best_cost;
  }
  return Status::ok();
}

}  // namespace fw::antslam
