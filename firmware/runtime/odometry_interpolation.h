// Odometry at a scan's timestamp. Scans and odometry come from different sensors at different
// rates, so the loop pairs every scan with the odometry pose interpolated to the scan time. The
// interpolation follows the SE(2) geodesic between the bracketing samples, a ⊕ exp(s·log(a⁻¹b)),
// i.e. constant forward and angular velocity between them (the unicycle arc the wheels drive),
// instead of interpolating x, y and θ independently, which cuts corners on turns.
#pragma once

#include <cstdint>

#include "firmware/base/se2.h"
#include "firmware/base/status.h"
#include "hal/msg/odometry.h"

namespace fw {

// Tangent vector (v_x, v_y, ω) of the SE(2) motion a⁻¹b (the "twist" over unit time).
Se2d se2_log(const Se2d& delta);
// Pose reached by following the twist for unit time.
Se2d se2_exp(const Se2d& twist);

// Pose at fraction s ∈ [0, 1] along the geodesic from a to b.
Se2d interpolate_se2(const Se2d& a, const Se2d& b, double s);

// Odometry at time t_ns between samples a (earlier) and b (later); requires a.t ≤ t ≤ b.t.
// Velocities are interpolated linearly. Returns an error naming the timestamps otherwise.
Status interpolate_odometry(const hal::Odometry& a, const hal::Odometry& b, std::uint64_t t_ns, hal::Odometry* out);

// True when every field is a finite number.
bool odometry_is_finite(const hal::Odometry& o);

}  // namespace fw
