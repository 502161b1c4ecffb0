#include "sim/eval/pransam_eval/pcl/pcl_peers.h"

#include <omp.h>  // PCL 1.13 ia_fpcs.hpp calls omp_get_thread_num() without including it

#include <pcl/features/fpfh_omp.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/ia_kfpcs.h>
#include <pcl/registration/sample_consensus_prerejective.h>
#include <pcl/search/kdtree.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>

// Reproducible K-4PCS (issue 17). PCL 1.13 seeds the C library's generator from the clock inside
// the algorithm: FPCSInitialAlignment::initCompute() calls std::srand(std::time(nullptr)) and
// computeTransformation() calls std::srand(std::time(NULL) ^ omp_get_thread_num()) in its OpenMP
// region, after any std::srand() of ours. Its templates are instantiated here (header-only in
// libpcl-dev: libpcl_registration.so exports no KFPCS symbol), so this object's calls of time() are
// redirected by the linker option --wrap=time (CMakeLists.txt, this tool only) to __wrap_time below:
// while a K-4PCS run is armed it returns a value derived from the draw's seed, otherwise the real
// clock (__real_time). Unlike defining time() in the executable, this affects no shared library and
// no other object. Deterministic only with one OpenMP thread: with more, the threads share rand()'s
// single state in an order the scheduler decides. The wall-clock bound (setMaxComputationTime) must
// be off too.
extern "C" std::time_t __real_time(std::time_t* t);
namespace {
std::atomic<bool> g_time_armed{false};
std::atomic<long long> g_time_value{0};
}  // namespace
extern "C" std::time_t __wrap_time(std::time_t* t) {
  if (g_time_armed.load()) {
    const auto v = static_cast<std::time_t>(g_time_value.load());
    if (t != nullptr) *t = v;
    return v;
  }
  return __real_time(t);
}

namespace sim::pransam_eval {

namespace {

double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

using PointNT = pcl::PointNormal;
using CloudNT = pcl::PointCloud<PointNT>;

CloudNT::Ptr to_pcl(const std::vector<Eigen::Vector3f>& pts) {
  CloudNT::Ptr c(new CloudNT);
  c->resize(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    (*c)[i].x = pts[i].x();
    (*c)[i].y = pts[i].y();
    (*c)[i].z = pts[i].z();
  }
  return c;
}

// Normals oriented toward the cloud's own sensor (each cloud knows where it was seen from).
void normals(const CloudNT::Ptr& c, float radius, int threads, const Eigen::Vector3f& viewpoint) {
  pcl::NormalEstimationOMP<PointNT, PointNT> ne(static_cast<unsigned>(threads));
  ne.setRadiusSearch(radius);
  ne.setViewPoint(viewpoint.x(), viewpoint.y(), viewpoint.z());
  ne.setInputCloud(c);
  ne.compute(*c);
}

// Seed of one draw's run (as pRANSAM's: seed·1000003 + draw), folded to the generator's width.
unsigned draw_seed(std::uint64_t seed, std::size_t index) {
  const std::uint64_t s = seed * 1000003ull + index;
  return static_cast<unsigned>(s ^ (s >> 32));
}

struct ArmedClock {  // time() returns `value` while alive
  explicit ArmedClock(unsigned value) {
    g_time_value.store(value);
    g_time_armed.store(true);
  }
  ~ArmedClock() { g_time_armed.store(false); }
};

bool fpfh_prerejective(const CloudDraw& d, int threads, unsigned seed, Eigen::Matrix4f* tf, bool* converged) {
  const float leaf = d.voxel;
  CloudNT::Ptr src = to_pcl(d.scene), tgt = to_pcl(d.model);
  normals(src, 2.0f * leaf, threads, d.scene_sensor);
  normals(tgt, 2.0f * leaf, threads, Eigen::Vector3f::Zero());
  pcl::PointCloud<pcl::FPFHSignature33>::Ptr fs(new pcl::PointCloud<pcl::FPFHSignature33>),
      ft(new pcl::PointCloud<pcl::FPFHSignature33>);
  pcl::FPFHEstimationOMP<PointNT, PointNT, pcl::FPFHSignature33> fe(static_cast<unsigned>(threads));
  fe.setRadiusSearch(5.0f * leaf);
  fe.setInputCloud(src);
  fe.setInputNormals(src);
  fe.compute(*fs);
  fe.setInputCloud(tgt);
  fe.setInputNormals(tgt);
  fe.compute(*ft);
  pcl::SampleConsensusPrerejective<PointNT, PointNT, pcl::FPFHSignature33> align;
  align.setInputSource(src);
  align.setSourceFeatures(fs);
  align.setInputTarget(tgt);
  align.setTargetFeatures(ft);
  align.setMaximumIterations(50000);
  align.setNumberOfSamples(3);
  align.setCorrespondenceRandomness(5);
  align.setSimilarityThreshold(0.9f);
  align.setMaxCorrespondenceDistance(2.5f * leaf);
  align.setInlierFraction(0.25f);
  CloudNT aligned;
  std::srand(seed);  // SampleConsensusPrerejective draws with rand() and never seeds it
  align.align(aligned);
  *converged = align.hasConverged();
  *tf = align.getFinalTransformation();
  return true;
}

bool k4pcs(const CloudDraw& d, int threads, int max_seconds, int samples, unsigned seed, Eigen::Matrix4f* tf,
           bool* converged) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr src(new pcl::PointCloud<pcl::PointXYZ>),
      tgt(new pcl::PointCloud<pcl::PointXYZ>);
  for (const auto& p : d.scene) src->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  for (const auto& p : d.model) tgt->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  pcl::registration::KFPCSInitialAlignment<pcl::PointXYZ, pcl::PointXYZ> ia;
  ia.setInputSource(src);
  ia.setInputTarget(tgt);
  ia.setNumberOfThreads(threads);
  ia.setDelta(d.voxel, false);  // "absolute value … the point accuracy"
  ia.setApproxOverlap(0.6f);
  if (max_seconds > 0) ia.setMaxComputationTime(max_seconds);
  // Cost bound (ours, not PCL's documentation): K-4PCS is meant for keypoints; on a whole voxelised
  // cloud its pair search is quadratic in the source size (> 5 min per milk draw on one thread).
  // setNumberOfSamples keeps a seeded random share of the source of about this many points.
  if (samples > 0) ia.setNumberOfSamples(samples);
  pcl::PointCloud<pcl::PointXYZ> aligned;
  const ArmedClock clock(seed);
  ia.align(aligned);
  *converged = ia.hasConverged();
  *tf = ia.getFinalTransformation();
  return true;
}

}  // namespace

const char* pcl_method_name(PclMethod m) { return m == PclMethod::kFpfhPrerejective ? "pcl_fpfh" : "pcl_k4pcs"; }

bool run_pcl(PclMethod method, const std::vector<CloudDraw>& draws, int threads, MethodRun* out, std::string* error,
             bool verbose, int max_seconds, std::uint64_t seed, int k4pcs_samples) {
  out->method = pcl_method_name(method);
  out->outcomes.clear();
  if (threads < 1) {
    *error = "run_pcl: threads must be >= 1";
    return false;
  }
  for (const CloudDraw& d : draws) {
    Eigen::Matrix4f tf = Eigen::Matrix4f::Identity();
    bool converged = false;
    const double t0 = now_ms();
    const unsigned ds = draw_seed(seed, d.index);
    if (method == PclMethod::kFpfhPrerejective) fpfh_prerejective(d, threads, ds, &tf, &converged);
    else k4pcs(d, threads, max_seconds, k4pcs_samples, ds, &tf, &converged);
    const double ms = now_ms() - t0;
    if (!tf.allFinite()) {
      tf.setIdentity();
      converged = false;
    }
    PlaneModel pm;
    pm.build(&d.model, 3.0f * d.voxel);
    const CloudOutcome oc = score_answer(d, pm, tf.topLeftCorner<3, 3>(), tf.topRightCorner<3, 1>(), converged, ms);
    if (verbose) {
      std::printf("  %s %s #%zu: %.1f ms %s  err %.4f m %.2f°  rms %.4f  R|t %.5f %.5f %.5f %.5f\n",
                  out->method.c_str(), d.cloud.c_str(), d.index, ms,
                  converged ? (oc.correct || !d.has_truth ? "reported" : "REPORTED-WRONG")
                            : (oc.correct ? "missed(correct)" : "nothing"),
                  oc.trans_err, oc.rot_err_deg, oc.inlier_rms, tf(0, 0), tf(0, 3), tf(1, 3), tf(2, 3));
    }
    out->outcomes.push_back(oc);
  }
  return true;
}

}  // namespace sim::pransam_eval
