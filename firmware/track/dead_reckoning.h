// Dead reckoning from the last track: its pose carried by the wheels after the track is given up,
// with the covariance grown by the tracker's own odometry noise model (the prediction of
// pose_tracker.h, P⁻ = F P Fᵀ + G Q(Δ) Gᵀ, without the scans). Extension of the dissertation.
//
// Why it binds MML's fixes (TrackedLocalizer): a track given up because the robot drove out of the
// map (ScanVerdict::kOutsideMap) leaves the robot where the wheels say, in unmapped space. MML sees
// only the map, so a local map of an unmapped wing that resembles a mapped room turned round is
// "isolated" there (UnknownWorld: 4.5 m and 180° off, `localized` for 22 scans). The wheels are a
// rival MML cannot weigh; as long as the scans do not refute them, a fix outside their protection
// level is not believed. They are refuted when the scan at the dead-reckoned pose lies on the map
// and contradicts it for TrackOptions::max_faulty_steps scans in a row (the tracker's own rule for
// giving up a track); otherwise only their own growth (the noise model) loosens them.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

#include "firmware/base/se2.h"
#include "firmware/map/global_map.h"
#include "firmware/track/protection_level.h"
#include "firmware/track/track_options.h"

namespace fw {
namespace track {

// Q of one odometry increment, diagonal in the robot frame of the increment: the AMCL α model with
// the per-step part in quadrature (track_options.h).
Eigen::Matrix3f odometry_increment_noise(const Se2f& delta, const TrackOptions& o);

// What the scan at the dead-reckoned pose says about it.
enum class DeadReckoningVerdict : std::uint8_t {
  kOutside = 0,        // most end-points on unknown space: the robot is still off the map
  kFits = 1,           // on the map and explained by it
  kSaysNothing = 2,    // too few end-points on known cells
  kContradicts = 3,    // on the map and contradicting it (the tracker's fit tests)
};

class DeadReckoning {
 public:
  void clear();
  // From the track's last pose and covariance; `binding` = its fixes must agree (a track given up
  // outside the map). A non-binding chain only carries the pose (the outside-map status).
  // `trusted` = no scan of the track showed a sign of a carry (TrackedLocalizer: a scan that did not
  // continue the one before it): only then does the carried pose say where the robot is (outside-map).
  void start(const Se2f& pose, const Eigen::Matrix3f& cov, const Se2f& wheel, bool binding, bool trusted);
  // Carries the pose to the wheel pose `wheel` and grows the covariance.
  void advance(const Se2f& wheel, const TrackOptions& o);
  // The scan (sensor-frame end-points) at the carried pose; a chain refuted max_faulty_steps scans
  // in a row stops binding. Returns the verdict (a chain that binds nothing is only tested for
  // kOutside, else kSaysNothing).
  DeadReckoningVerdict judge(const GlobalMap& map, const Point2f* pts, std::size_t n, const TrackOptions& o);
  // A fix the wheels do not rule out: within their protection level (at the integrity risk) plus
  // the alert limits the fix itself may be off by. Always true when not binding.
  bool admits(const Se2f& fix, const ProtectionFactors& k, const TrackOptions& o) const;

  bool active() const { return active_; }
  bool binding() const { return binding_; }
  // The carried pose is where the robot is as far as the wheels know: started trusted and not
  // refuted by the scans since (a binding chain refuted stops binding and is no longer trusted).
  bool trusted() const { return active_ && trusted_; }
  const Se2f& pose() const { return pose_; }
  const Eigen::Matrix3f& cov() const { return cov_; }
  ProtectionLevel bound(const ProtectionFactors& k) const { return protection_level(cov_, k, 0.0f, 0.0f); }
  std::uint32_t contradicting_steps() const { return contradicting_; }
  // The last judge() found the scan fitting the map at the carried pose after a scan outside it:
  // by the wheels, confirmed by the scan, the robot has come back onto the map.
  bool reentered() const { return reentered_; }

 private:
  bool active_ = false, binding_ = false, trusted_ = false;
  Se2f pose_, wheel_;
  Eigen::Matrix3f cov_ = Eigen::Matrix3f::Zero();
  std::uint32_t contradicting_ = 0;
  bool outside_ = false, reentered_ = false;
};

}  // namespace track
}  // namespace fw
