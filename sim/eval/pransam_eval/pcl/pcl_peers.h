// The PCL peers of pRANSAM 3-D (issue 17), run on exactly the same CloudDraws and scored by the same
// refinement and criterion (cloud_outcome.h). Host evaluation only; never linked into firmware/.
//  - FPFH + SampleConsensusPrerejective, set up as PCL's "Robust pose estimation of rigid objects"
//    tutorial scales it with the leaf (voxel) size: normals within 2 voxels, FPFH within 5 voxels,
//    50,000 iterations, 3 samples, 5 nearest features, edge similarity 0.9, inlier distance
//    2.5 voxels, inlier fraction 0.25; reported = hasConverged() (the inlier fraction was reached).
//  - K-4PCS (pcl::registration::KFPCSInitialAlignment) as its documentation says: delta = the point
//    accuracy (absolute, one voxel), approximate overlap = the smallest drawn overlap (0.6), score
//    threshold and iterations left to their overlap-derived defaults, the OpenMP thread count;
//    reported = hasConverged() (fitness below the score threshold). Reproducible per seed on one
//    thread without a time bound (pcl_peers.cpp: PCL's time() seeding is wrapped); optionally a
//    source sample bound (setNumberOfSamples) to make it fit the time.
// Time: everything the method needs from the two clouds (normals, features, alignment).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim/eval/pransam_eval/cloud_outcome.h"

namespace sim::pransam_eval {

enum class PclMethod { kFpfhPrerejective, kK4pcs };
const char* pcl_method_name(PclMethod m);

// `threads`: OpenMP threads of the OMP normal / FPFH estimators and of K-4PCS (1 = one thread).
// max_seconds bounds one K-4PCS run (PCL's setMaxComputationTime; 0 = PCL's default, unbounded).
// seed: each draw's run is seeded from (seed, draw index) like pRANSAM's — FPFH + prerejective by
// std::srand before align(), K-4PCS through the wrapped time() (pcl_peers.cpp). Reproducible with
// threads = 1 for K-4PCS and max_seconds = 0 (a wall-clock bound cuts runs at different points).
// k4pcs_samples > 0: K-4PCS uses about that many source points (setNumberOfSamples; 0 = all).
bool run_pcl(PclMethod method, const std::vector<CloudDraw>& draws, int threads, MethodRun* out, std::string* error,
             bool verbose = false, int max_seconds = 0, std::uint64_t seed = 1, int k4pcs_samples = 0);

}  // namespace sim::pransam_eval
