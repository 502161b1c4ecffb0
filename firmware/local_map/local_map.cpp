#include "firmware/local_map/local_map.h"

#include "firmware/base/memory_report.h"

#include <cmath>

namespace fw {

Status LocalMapOptions::validate() const {
  if (!(fragment_length_m > 0.0f) || !std::isfinite(fragment_length_m)) {
    return Status::error(Errc::kInvalidArgument, "local map: fragment_length_m %g must be positive",
                         static_cast<double>(fragment_length_m));
  }
  if (keep_last > kMaxFragments) {
    return Status::error(Errc::kInvalidArgument, "local map: keep_last %u exceeds %u fragments", keep_last, kMaxFragments);
  }
  if (point_capacity < 16) {
    return Status::error(Errc::kInvalidArgument, "local map: point_capacity %u below 16", point_capacity);
  }
  return Status::ok();
}

Status LocalMap::init(const LocalMapOptions& options, StartupArena& arena) {
  FW_RETURN_IF_ERROR(options.validate());
  options_ = options;
  Result<Point2f*> r = arena.allocate_array<Point2f>(options.point_capacity, "local map points");
  if (!r) return r.status();
  points_ = *r;
  capacity_ = options.point_capacity;
  FW_RETURN_IF_ERROR(MemoryReport::instance().add(
      {"rbsm", "local map fragments' points", capacity_ * sizeof(Point2f), capacity_, nullptr}));
  reset();
  return Status::ok();
}

void LocalMap::reset() {
  points_head_ = points_used_ = 0;
  head_ = count_ = 0;
  next_id_ = dropped_ = 0;
  has_last_pose_ = false;
  last_pose_ = Se2f();
  for (Fragment& f : fragments_) f = Fragment{};
}

bool LocalMap::drop_oldest() {
  if (count_ == 0) return false;
  const Fragment& f = fragments_[head_];
  points_head_ = (points_head_ + f.count) % capacity_;
  points_used_ -= f.count;
  head_ = (head_ + 1) % LocalMapOptions::kMaxFragments;
  --count_;
  ++dropped_;
  return true;
}

Status LocalMap::update_pose(const Se2f& pose) {
  if (points_ == nullptr) return Status::error(Errc::kNotInitialized, "local map: update_pose() before init()");
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
    return Status::error(Errc::kInvalidArgument, "local map: non-finite pose");
  }
  float step = 0.0f;
  if (has_last_pose_) step = std::hypot(pose.x - last_pose_.x, pose.y - last_pose_.y);
  last_pose_ = pose;
  has_last_pose_ = true;
  if (count_ > 0) {
    Fragment& cur = fragments_[(head_ + count_ - 1) % LocalMapOptions::kMaxFragments];
    cur.path_length += step;
    if (cur.path_length < options_.fragment_length_m) return Status::ok();
  }
  // Open a new fragment; make room in the descriptor ring and honour keep_last.
  if (count_ == LocalMapOptions::kMaxFragments) {
    if (!options_.drop_oldest_when_full) {
      return Status::error(Errc::kCapacityExceeded, "local map: %u fragments full", LocalMapOptions::kMaxFragments);
    }
    drop_oldest();
  }
  Fragment& f = fragments_[(head_ + count_) % LocalMapOptions::kMaxFragments];
  f.id = next_id_++;
  f.frame = pose;
  f.correction = Se2f();
  f.path_length = 0.0f;
  f.start = (points_head_ + points_used_) % capacity_;
  f.count = 0;
  ++count_;
  if (options_.keep_last > 0) {
    while (count_ > options_.keep_last) drop_oldest();
  }
  return Status::ok();
}

Status LocalMap::add_points(const Point2f* world_points, std::size_t count) {
  if (points_ == nullptr) return Status::error(Errc::kNotInitialized, "local map: add_points() before init()");
  if (count == 0) return Status::ok();
  if (world_points == nullptr) return Status::error(Errc::kInvalidArgument, "local map: null points (count %zu)", count);
  if (count_ == 0) return Status::error(Errc::kNotInitialized, "local map: add_points() before the first update_pose()");
  if (count > capacity_) {
    return Status::error(Errc::kCapacityExceeded, "local map: %zu points exceed the ring capacity %u", count, capacity_);
  }
  // Evict older fragments (never the current one) until the points fit.
  while (points_used_ + count > capacity_) {
    if (!options_.drop_oldest_when_full || count_ <= 1) {
      return Status::error(Errc::kCapacityExceeded, "local map full: %u of %u points used, %zu more requested",
                           points_used_, capacity_, count);
    }
    drop_oldest();
  }
  Fragment& cur = fragments_[(head_ + count_ - 1) % LocalMapOptions::kMaxFragments];
  const Se2f inv = cur.frame.inverse();
  const float c = std::cos(inv.theta), s = std::sin(inv.theta);
  std::uint32_t idx = (points_head_ + points_used_) % capacity_;
  for (std::size_t i = 0; i < count; ++i) {
    const float x = world_points[i](0), y = world_points[i](1);
    points_[idx] = Point2f(inv.x + c * x - s * y, inv.y + s * x + c * y);
    idx = idx + 1 == capacity_ ? 0 : idx + 1;
  }
  cur.count += static_cast<std::uint32_t>(count);
  points_used_ += static_cast<std::uint32_t>(count);
  return Status::ok();
}

FragmentView LocalMap::fragment(std::size_t i) const {
  FragmentView v;
  if (i >= count_) {
    raise_fault(Fault::kIndexOutOfBounds);
    return v;
  }
  const Fragment& f = fragments_[(head_ + i) % LocalMapOptions::kMaxFragments];
  v.id = f.id;
  v.scan_matcher_frame = f.frame;
  v.correction = f.correction;
  v.frame = f.frame.compose(f.correction);
  v.path_length = f.path_length;
  const std::uint32_t until_end = capacity_ - f.start;
  v.first = points_ + f.start;
  v.first_count = f.count <= until_end ? f.count : until_end;
  v.second = points_;
  v.second_count = f.count - v.first_count;
  return v;
}

Status LocalMap::set_correction(std::size_t i, const Se2f& correction) {
  if (i >= count_) {
    return Status::error(Errc::kInvalidArgument, "local map: correction for fragment %zu of %u", i, count_);
  }
  if (!std::isfinite(correction.x) || !std::isfinite(correction.y) || !std::isfinite(correction.theta)) {
    return Status::error(Errc::kInvalidArgument, "local map: non-finite correction for fragment %zu", i);
  }
  fragments_[(head_ + i) % LocalMapOptions::kMaxFragments].correction = correction;
  return Status::ok();
}

bool LocalMap::find_fragment(std::uint32_t id, std::size_t* index) const {
  if (count_ == 0) return false;
  const std::uint32_t oldest = fragments_[head_].id;  // ids are consecutive in the ring
  if (id < oldest || id - oldest >= count_) return false;
  *index = id - oldest;
  return true;
}

}  // namespace fw
