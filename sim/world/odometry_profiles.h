// Odometry profiles (issue 55): the wheels of the bases robots are built on — a calibrated
// differential drive, a poorly calibrated one (systematic wheel-radius and track-width errors), a
// skid-steer base (heading slip on every turn, lateral slip), rare wheel-slip events, and the
// dissertation's white model (Sec. 5.7.1: 4 cm / 4° per step). Each profile also states what an
// integrator would configure the tracker with from the base's spec sheet (the α model and the
// per-step noise of track_options.h), which need not match the wheels (poor calibration, slips are
// what a spec does not know).
#pragma once

#include <string>
#include <vector>

#include "sim/world/odometry_model.h"

namespace sim {

struct OdometryProfile {
  std::string name;         // "diff-calibrated", "diff-poor", "skid-steer", "slip-events", "white", "turn-spin"
  std::string description;
  OdometryNoiseOptions wheels;
  // mml-track's odometry keys as an integrator sets them for this base ("TT,TR,RR,RT", "M,DEG" and
  // the declared slips "RATE,MAX_M"; empty = the defaults).
  std::string tracker_odom_noise, tracker_odom_noise_per_step, tracker_odom_slip;
};

const std::vector<OdometryProfile>& odometry_profiles();
const OdometryProfile* find_odometry_profile(const std::string& name);

}  // namespace sim
