// Trimmed ICP baseline (dissertation Sec. 2.4, after Chetverikov et al. [24]): point-to-point ICP
// against the same bounded end-point map RBSM uses (EndpointGrid), keeping only the best 80 % of
// the nearest-neighbour pairs in every iteration, closed-form 2D alignment (SVD-free: the optimal
// rotation is atan2 of the cross-covariance), stopping when the trimmed mean squared error changes
// by less than 1e-3 (the thesis's ε; error measured in cells², the thesis's "pix" units) or at the
// iteration cap. Implements ScanMatcher so experiments swap it with RBSM. No heap, no RNG.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/arena.h"
#include "firmware/base/status.h"
#include "firmware/rbsm/endpoint_grid.h"
#include "firmware/rbsm/scan_matcher.h"
#include "hal/msg/laser_scan.h"

namespace fw {

struct TrimmedIcpOptions {
  static constexpr std::uint32_t kMaxPoints = hal::LaserScan::kMaxBeams;
  float trim_fraction = 0.8f;          // keep this fraction of the closest pairs
  float min_error_change = 1e-3f;      // ε, cells²
  std::uint32_t max_iterations = 50;
  float max_correspondence_m = 0.5f;   // NN search radius
  std::uint32_t min_points = 10;
  float max_range = 0.0f;              // ignore points farther than this (m); 0 = keep all
  EndpointGridOptions grid;

  Status validate() const;
};

class TrimmedIcp final : public ScanMatcher {
 public:
  static std::size_t required_arena_bytes(const TrimmedIcpOptions& options) {
    return EndpointGrid::required_bytes(options.grid);
  }
  Status init(const TrimmedIcpOptions& options, StartupArena& arena);

  const char* name() const override { return "icp"; }
  void reset() override { grid_.clear(); }
  Status match(const Point2f* points, std::size_t count, const Se2f& initial_guess, ScanMatchResult* out) override;
  Status integrate(const Point2f* points, std::size_t count, const Se2f& pose, Point2f* new_cells = nullptr,
                   std::size_t capacity = 0, std::size_t* num_new = nullptr) override;

  const EndpointGrid& grid() const { return grid_; }

 private:
  TrimmedIcpOptions options_;
  EndpointGrid grid_;
  bool initialized_ = false;
  std::uint32_t n_ = 0;
  float px_[TrimmedIcpOptions::kMaxPoints] = {};
  float py_[TrimmedIcpOptions::kMaxPoints] = {};
  float mx_[TrimmedIcpOptions::kMaxPoints] = {};
  float my_[TrimmedIcpOptions::kMaxPoints] = {};
  float d2_[TrimmedIcpOptions::kMaxPoints] = {};
  std::uint32_t pair_point_[TrimmedIcpOptions::kMaxPoints] = {};
  std::uint32_t order_[TrimmedIcpOptions::kMaxPoints] = {};
};

}  // namespace fw
