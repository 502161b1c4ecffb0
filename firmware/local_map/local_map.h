// LocalMap: MML's local map as consecutive fragments (Sec. 5.4, and AntSLAM's fragments, Sec. 3):
// a new fragment starts every `fragment_length_m` metres of travelled path; each fragment holds its
// frame F_i (the robot pose where it started) and its points in that frame. Points live in one
// fixed ring, fragments in a fixed ring of descriptors, so dropping the oldest fragment is O(1)
// (advance two ring tails) and never fragments memory. keep_last = m keeps only the last m
// fragments (Sec. 5.4). A full point ring is a status (kCapacityExceeded naming the sizes) unless
// drop_oldest_when_full allows evicting older fragments.
// Each fragment also carries a correction T_i (identity unless a consumer sets one; MML's local
// map correction, Eq. 5.23–5.27): its points lie at F_i ⊕ T_i ⊕ x in the local map. Points keep
// being stored with F_i (the scan matcher's frame), so the scan matcher never sees the correction
// and later points of a corrected fragment get the same correction as the earlier ones.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/arena.h"
#include "firmware/base/se2.h"
#include "firmware/base/status.h"
#include "firmware/scan/scan_points.h"

namespace fw {

struct LocalMapOptions {
  static constexpr std::uint32_t kMaxFragments = 256;
  float fragment_length_m = 5.0f;       // N: new fragment every N metres of path
  std::uint32_t keep_last = 0;          // m: keep only the last m fragments (0 = as many as fit)
  std::uint32_t point_capacity = 65536; // points in the shared ring
  bool drop_oldest_when_full = true;

  Status validate() const;
};

// Points of one fragment: up to two contiguous spans (the ring may wrap), in the fragment frame.
struct FragmentView {
  std::uint32_t id = 0;     // running fragment number since reset
  Se2f frame;               // F_i ⊕ T_i: where the points lie in the local map (corrected)
  Se2f scan_matcher_frame;  // F_i in the world (scan-matcher) frame
  Se2f correction;          // T_i (fragment frame)
  float path_length = 0.0f; // path travelled inside this fragment (m)
  const Point2f* first = nullptr;
  std::size_t first_count = 0;
  const Point2f* second = nullptr;
  std::size_t second_count = 0;
  std::size_t size() const { return first_count + second_count; }
  const Point2f& operator[](std::size_t i) const { return i < first_count ? first[i] : second[i - first_count]; }
};

class LocalMap {
 public:
  Status init(const LocalMapOptions& options, StartupArena& arena);
  const LocalMapOptions& options() const { return options_; }
  void reset();

  // Reports the robot pose after each accepted scan; opens a new fragment (frame = pose) when the
  // path since the current fragment's start exceeds fragment_length_m (or when there is none).
  Status update_pose(const Se2f& pose);
  // Adds world points to the current fragment (stored in its frame).
  Status add_points(const Point2f* world_points, std::size_t count);

  std::size_t num_fragments() const { return count_; }
  // i = 0 is the oldest kept fragment.
  FragmentView fragment(std::size_t i) const;
  std::size_t total_points() const { return points_used_; }
  std::uint32_t dropped_fragments() const { return dropped_; }
  // Drops the oldest fragment in O(1); false when empty.
  bool drop_oldest();
  // Sets T_i of fragment i (0 = oldest kept); non-finite values are rejected.
  Status set_correction(std::size_t i, const Se2f& correction);
  // Index of the kept fragment with running number `id`; false when dropped or not yet opened.
  bool find_fragment(std::uint32_t id, std::size_t* index) const;

 private:
  struct Fragment {
    std::uint32_t id;
    Se2f frame;
    Se2f correction;
    float path_length;
    std::uint32_t start;  // ring index of the first point
    std::uint32_t count;
  };
  LocalMapOptions options_;
  Point2f* points_ = nullptr;
  std::uint32_t capacity_ = 0;
  std::uint32_t points_head_ = 0;  // ring index of the oldest point
  std::uint32_t points_used_ = 0;
  Fragment fragments_[LocalMapOptions::kMaxFragments] = {};
  std::uint32_t head_ = 0, count_ = 0;  // fragment ring
  std::uint32_t next_id_ = 0, dropped_ = 0;
  bool has_last_pose_ = false;
  Se2f last_pose_;
};

}  // namespace fw
