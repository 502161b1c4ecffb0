#include "firmware/map/unmapped_space.h"

#include <cmath>

namespace fw {

namespace {
constexpr std::uint32_t kMaxFlood = 1024;  // the largest min_area in blocks the bounded flood decides
}  // namespace

Status UnmappedSpace::build(const GlobalMap& map, const UnmappedSpaceOptions& options, StartupArena& arena) {
  const GridGeometry& g = map.geometry;
  if (!map.valid()) return Status::error(Errc::kInvalidArgument, "unmapped space: the map is empty");
  if (!(options.block_m > 0.0f) || !(options.min_area_m2 > 0.0f)) {
    return Status::error(Errc::kInvalidArgument, "unmapped space: block %.3f m and min area %.3f m² must be > 0",
                         static_cast<double>(options.block_m), static_cast<double>(options.min_area_m2));
  }
  const std::int32_t k = std::max<std::int32_t>(1, static_cast<std::int32_t>(std::lround(options.block_m / g.resolution)));
  block_m_ = static_cast<float>(k) * g.resolution;
  const float min_blocks_f = std::ceil(options.min_area_m2 / (block_m_ * block_m_));
  if (min_blocks_f > static_cast<float>(kMaxFlood)) {
    return Status::error(Errc::kInvalidArgument, "unmapped space: min area %.1f m² is over %u blocks of %.2f m",
                         static_cast<double>(options.min_area_m2), kMaxFlood, static_cast<double>(block_m_));
  }
  bw_ = (static_cast<std::int32_t>(g.width) + k - 1) / k;
  bh_ = (static_cast<std::int32_t>(g.height) + k - 1) / k;
  origin_x_ = g.origin_x;
  origin_y_ = g.origin_y;
  Result<std::uint8_t*> lab = arena.allocate_array<std::uint8_t>(static_cast<std::size_t>(bw_) * bh_, "unmapped space blocks");
  if (!lab) return lab.status();
  labels_ = *lab;
  for (std::int32_t by = 0; by < bh_; ++by) {
    for (std::int32_t bx = 0; bx < bw_; ++bx) {
      bool all_unknown = true;
      for (std::int32_t cy = by * k; cy < (by + 1) * k && all_unknown; ++cy) {
        for (std::int32_t cx = bx * k; cx < (bx + 1) * k && all_unknown; ++cx) {
          if (cx < static_cast<std::int32_t>(g.width) && cy < static_cast<std::int32_t>(g.height)) {
            all_unknown = map.cell(cx, cy) == kCellUnknown;
          }
        }
      }
      labels_[static_cast<std::size_t>(by) * bw_ + bx] = all_unknown ? kUnknown : kKnown;
    }
  }
  sweep_outside();
  classify_inner(static_cast<std::uint32_t>(min_blocks_f));
  return Status::ok();
}

// Unknown blocks connected to the image border are outside the map: alternate forward and backward
// sweeps until nothing changes (each sweep carries the outside along two directions).
void UnmappedSpace::sweep_outside() {
  auto idx = [this](std::int32_t bx, std::int32_t by) { return static_cast<std::size_t>(by) * bw_ + bx; };
  for (std::int32_t by = 0; by < bh_; ++by) {
    for (std::int32_t bx = 0; bx < bw_; ++bx) {
      const bool border = bx == 0 || by == 0 || bx == bw_ - 1 || by == bh_ - 1;
      if (border && labels_[idx(bx, by)] == kUnknown) labels_[idx(bx, by)] = kOutside;
    }
  }
  bool changed = true;
  while (changed) {
    changed = false;
    for (std::int32_t by = 1; by < bh_ - 1; ++by) {
      for (std::int32_t bx = 1; bx < bw_ - 1; ++bx) {
        std::uint8_t& l = labels_[idx(bx, by)];
        if (l == kUnknown && (labels_[idx(bx - 1, by)] == kOutside || labels_[idx(bx, by - 1)] == kOutside)) {
          l = kOutside;
          changed = true;
        }
      }
    }
    for (std::int32_t by = bh_ - 2; by >= 1; --by) {
      for (std::int32_t bx = bw_ - 2; bx >= 1; --bx) {
        std::uint8_t& l = labels_[idx(bx, by)];
        if (l == kUnknown && (labels_[idx(bx + 1, by)] == kOutside || labels_[idx(bx, by + 1)] == kOutside)) {
          l = kOutside;
          changed = true;
        }
      }
    }
  }
}

// Every inner unknown component: a flood from one of its blocks stops as soon as it holds
// min_blocks (or touches a block already known to be unmapped space): large, all it reached is
// unmapped space; a flood that runs out first has enumerated a small component.
void UnmappedSpace::classify_inner(std::uint32_t min_blocks) {
  std::int32_t fx[kMaxFlood], fy[kMaxFlood];
  const std::int32_t dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
  unmapped_blocks_ = 0;
  for (std::int32_t by = 0; by < bh_; ++by) {
    for (std::int32_t bx = 0; bx < bw_; ++bx) {
      if (at(bx, by) != kUnknown) continue;
      std::uint32_t n = 0;
      fx[n] = bx;
      fy[n] = by;
      ++n;
      bool large = n >= min_blocks;
      for (std::uint32_t head = 0; head < n && !large; ++head) {
        for (int d = 0; d < 4 && !large; ++d) {
          const std::int32_t x = fx[head] + dx[d], y = fy[head] + dy[d];
          if (x < 0 || y < 0 || x >= bw_ || y >= bh_) continue;
          const Label l = at(x, y);
          if (l == kUnmapped) large = true;
          if (l != kUnknown) continue;
          bool seen = false;
          for (std::uint32_t j = 0; j < n && !seen; ++j) seen = fx[j] == x && fy[j] == y;
          if (seen) continue;
          fx[n] = x;
          fy[n] = y;
          ++n;
          large = n >= min_blocks;
        }
      }
      for (std::uint32_t j = 0; j < n; ++j) {
        labels_[static_cast<std::size_t>(fy[j]) * bw_ + fx[j]] = large ? kUnmapped : kSmall;
      }
      if (large) unmapped_blocks_ += n;
    }
  }
}

bool UnmappedSpace::contains(float x, float y) const {
  if (labels_ == nullptr) return false;
  const float fx = (x - origin_x_) / block_m_, fy = (y - origin_y_) / block_m_;
  if (!(fx >= 0.0f && fy >= 0.0f && fx < static_cast<float>(bw_) && fy < static_cast<float>(bh_))) return false;
  return at(static_cast<std::int32_t>(fx), static_cast<std::int32_t>(fy)) == kUnmapped;
}

}  // namespace fw
