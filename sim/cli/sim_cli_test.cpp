#include <gtest/gtest.h>
#include <sys/stat.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "firmware/runtime/odometry_localizer.h"
#include "sim/cli/localizer_factory.h"
#include "sim/cli/sim_args.h"
#include "sim/cli/sim_runner.h"
#include "sim/cli/summary_text.h"
#include "sim/viz/picture.h"

namespace sim {
namespace {

std::string read_all(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

std::string temp_dir(const std::string& name) {
  const std::string d = std::filesystem::temp_directory_path().string() + "/mml_sim_test_" + std::to_string(getpid()) + "_" + name;
  std::filesystem::remove_all(d);
  return d;
}

std::string parse_error(const std::vector<std::string>& args) {
  SimConfig cfg;
  SimArgsAction action;
  std::string err;
  EXPECT_FALSE(parse_sim_args(args, &cfg, &action, &err)) << "accepted: " << ::testing::PrintToString(args);
  return err;
}

TEST(SimArgs, MalformedArgumentsGiveAClearError) {
  EXPECT_NE(parse_error({"--world"}).find("--world needs a value"), std::string::npos);
  EXPECT_NE(parse_error({"--world", "small-office", "--bogus"}).find("unknown argument '--bogus'"), std::string::npos);
  EXPECT_NE(parse_error({"--world", "small-office", "--seed", "abc"}).find("--seed: 'abc' is not"), std::string::npos);
  EXPECT_NE(parse_error({"--world", "small-office", "--seed", "-3"}).find("--seed"), std::string::npos);
  EXPECT_NE(parse_error({"--world", "small-office", "--steps", "12x"}).find("--steps"), std::string::npos);
  EXPECT_NE(parse_error({"--world", "small-office", "--dropout", "2"}).find("outside"), std::string::npos);
  EXPECT_NE(parse_error({"--world", "small-office", "--odom-noise", "0.04"}).find("T,R"), std::string::npos);
  EXPECT_NE(parse_error({"--world", "small-office", "--timing", "cpu"}).find("--timing"), std::string::npos);
  EXPECT_NE(parse_error({"--world", "small-office", "--opt", "novalue"}).find("KEY=VALUE"), std::string::npos);
  EXPECT_NE(parse_error({"--world", "small-office", "--log", "x.clf"}).find("exclude each other"), std::string::npos);
  EXPECT_NE(parse_error({"--seed", "1"}).find("no input"), std::string::npos);
  EXPECT_NE(parse_error({"--world", "small-office", "--reference", "p.txt"}).find("--reference needs --log"),
            std::string::npos);
  EXPECT_NE(parse_error({"--world", "small-office", "--beams", "1"}).find("--beams"), std::string::npos);
  EXPECT_NE(parse_error({"--world", "small-office", "--threads", "0"}).find("--threads"), std::string::npos);
  EXPECT_NE(parse_error({"--world", "small-office", "--kidnap-at", "0"}).find("--kidnap-at"), std::string::npos);
  EXPECT_NE(parse_error({"--dataset", "intel", "--world", "small-office"}).find("exclude each other"),
            std::string::npos);
  EXPECT_NE(parse_error({"--log", "x.clf", "--max-log-mib", "0"}).find("--max-log-mib"), std::string::npos);
  EXPECT_NE(parse_error({"--log", "x.clf", "--max-log-mib", "9999999"}).find("--max-log-mib"), std::string::npos);
}

TEST(SimArgs, MaxLogMibSetsTheReadCap) {
  SimConfig cfg;
  SimArgsAction action;
  std::string err;
  ASSERT_TRUE(parse_sim_args({"--log", "x.clf"}, &cfg, &action, &err)) << err;
  EXPECT_EQ(cfg.max_log_bytes, kDefaultMaxLogBytes);
  ASSERT_TRUE(parse_sim_args({"--log", "x.clf", "--max-log-mib", "3"}, &cfg, &action, &err)) << err;
  EXPECT_EQ(cfg.max_log_bytes, 3u << 20);
}

TEST(SimArgs, ParsesAFullCommandLine) {
  SimConfig cfg;
  SimArgsAction action;
  std::string err;
  ASSERT_TRUE(parse_sim_args({"--world", "large-office", "--seed", "7", "--steps", "50", "--out", "x", "--opt",
                              "anchor=truth", "--odom-noise", "0.02,2", "--beams", "181", "--max-range", "80",
                              "--paced", "--speed", "4", "--enter-unknown", "--timing", "none"},
                             &cfg, &action, &err))
      << err;
  EXPECT_EQ(action, SimArgsAction::kRun);
  EXPECT_EQ(cfg.world, "large-office");
  EXPECT_EQ(cfg.seed, 7u);
  EXPECT_EQ(cfg.steps, 50u);
  EXPECT_EQ(cfg.localizer_options.at("anchor"), "truth");
  EXPECT_DOUBLE_EQ(cfg.synthetic.odometry.sigma_trans, 0.02);
  EXPECT_DOUBLE_EQ(cfg.synthetic.odometry.sigma_rot_deg, 2.0);
  EXPECT_EQ(cfg.synthetic.laser.beams, 181);
  EXPECT_DOUBLE_EQ(cfg.synthetic.laser.max_range, 80.0);
  EXPECT_TRUE(cfg.paced);
  EXPECT_FALSE(cfg.synthetic.route.avoid_unknown);
  EXPECT_FALSE(cfg.wall_timing);
  ASSERT_TRUE(parse_sim_args({"--help"}, &cfg, &action, &err));
  EXPECT_EQ(action, SimArgsAction::kHelp);
}

// Issue 12 item 4: the log options and their errors (nothing silently ignored).
TEST(SimArgs, LogReplayOptions) {
  SimConfig cfg;
  SimArgsAction action;
  std::string err;
  ASSERT_TRUE(parse_sim_args({"--log", "x.clf", "--map", "m.mmap", "--start", "120", "--kidnap-at", "30",
                              "--odom-noise", "0.01,1"},
                             &cfg, &action, &err))
      << err;
  EXPECT_EQ(cfg.log_start, 120u);
  EXPECT_EQ(cfg.log_kidnap_at, 30u);
  EXPECT_EQ(cfg.synthetic.kidnap_at_scan, 0u);  // not the synthetic world's kidnapping
  EXPECT_TRUE(cfg.log_odom_noise);
  EXPECT_DOUBLE_EQ(cfg.log_odom_sigma_m, 0.01);
  EXPECT_DOUBLE_EQ(cfg.log_odom_sigma_deg, 1.0);
  EXPECT_EQ(cfg.map_yaml, "m.mmap");
  EXPECT_EQ(cfg.threads, 2);  // the CLI's default, as mml-eval's
  SimConfig plain;
  ASSERT_TRUE(parse_sim_args({"--log", "x.clf"}, &plain, &action, &err)) << err;
  EXPECT_FALSE(plain.log_odom_noise);  // the world's default noise is not added to a log
  EXPECT_EQ(plain.log_kidnap_at, 0u);
  SimConfig world;
  ASSERT_TRUE(parse_sim_args({"--world", "corridor", "--kidnap-at", "40"}, &world, &action, &err)) << err;
  EXPECT_EQ(world.synthetic.kidnap_at_scan, 40u);
  EXPECT_EQ(world.log_kidnap_at, 0u);
  EXPECT_NE(parse_error({"--log", "x.clf", "--start", "abc"}).find("--start: 'abc'"), std::string::npos);
  EXPECT_NE(parse_error({"--world", "corridor", "--start", "3"}).find("--start is for --log"), std::string::npos);
  for (const char* opt : {"--people", "--beams", "--max-range", "--route-length", "--scan-period"}) {
    EXPECT_NE(parse_error({"--log", "x.clf", opt, "3"}).find(std::string(opt) + " is an option of synthetic worlds"),
              std::string::npos)
        << opt;
  }
  EXPECT_NE(parse_error({"--log", "x.clf", "--resolution", "0.1"}).find("--resolution is an option of synthetic"),
            std::string::npos);
  EXPECT_NE(parse_error({"--dataset", "intel", "--via-unknown"}).find("--via-unknown is an option of synthetic"),
            std::string::npos);
}

SimConfig small_run(const std::string& out, std::uint64_t seed) {
  SimConfig cfg;
  cfg.world = "small-office";
  cfg.localizer = "odom";
  cfg.seed = seed;
  cfg.steps = 60;
  cfg.out_dir = out;
  cfg.wall_timing = false;
  cfg.progress = false;
  return cfg;
}

// mml-sim hands mml-track the simulated wheels' per-step σ on the axes its α model does not cover
// on the nominal straight step (0.75 m/s × 0.4 s = 0.3 m): translation 0.2 × 0.3 = 6 cm ≥ 4 cm is
// covered, rotation 0.2 × 0.3 rad = 3.4° < 4° is not. Nothing for another localizer, a log, or
// when the option is given.
TEST(SimRunner, TrackerIsToldTheWheelNoiseItsModelMisses) {
  SimConfig cfg = small_run("", 1);
  cfg.localizer = "mml-track";
  EXPECT_EQ(wheel_noise_beyond_alpha(cfg), "0,4");
  cfg.localizer_options["odom_noise"] = "0.1,0.2,0.2,0.3";  // TT·0.3 = 3 cm < 4 cm; RT·0.3 = 5.2° ≥ 4°
  EXPECT_EQ(wheel_noise_beyond_alpha(cfg), "0.04,0");
  cfg.localizer_options["odom_noise"] = "0.3,0.2,0.2,0.3";  // both covered
  EXPECT_EQ(wheel_noise_beyond_alpha(cfg), "");
  cfg.localizer_options.erase("odom_noise");
  cfg.synthetic.odometry.sigma_rot_deg = 2.0;  // wheels better than the α model on both axes
  EXPECT_EQ(wheel_noise_beyond_alpha(cfg), "");
  cfg.synthetic.odometry.sigma_rot_deg = 4.0;
  cfg.localizer_options["odom_noise_per_step"] = "0,0";
  EXPECT_EQ(wheel_noise_beyond_alpha(cfg), "");
  cfg.localizer_options.clear();
  cfg.localizer = "odom";
  EXPECT_EQ(wheel_noise_beyond_alpha(cfg), "");
  cfg.localizer = "mml-track";
  cfg.world.clear();
  cfg.log_path = "run.clf";
  EXPECT_EQ(wheel_noise_beyond_alpha(cfg), "");
}

TEST(SimRunner, SameSeedGivesIdenticalCsv) {
  const std::string a = temp_dir("a"), b = temp_dir("b"), c = temp_dir("c");
  SimResult r;
  std::string err;
  ASSERT_TRUE(run_simulation(small_run(a, 4), &r, &err)) << err;
  EXPECT_EQ(r.steps.size(), 60u);
  ASSERT_TRUE(run_simulation(small_run(b, 4), &r, &err)) << err;
  ASSERT_TRUE(run_simulation(small_run(c, 5), &r, &err)) << err;
  const std::string csv_a = read_all(a + "/steps.csv");
  EXPECT_GT(csv_a.size(), 1000u);
  EXPECT_EQ(csv_a, read_all(b + "/steps.csv"));
  EXPECT_NE(csv_a, read_all(c + "/steps.csv"));
  // Every output is there and looks like what it claims to be.
  EXPECT_EQ(read_all(a + "/run.png").substr(1, 3), "PNG");
  EXPECT_NE(read_all(a + "/run.svg").find("data:image/png;base64,"), std::string::npos);
  EXPECT_NE(read_all(a + "/summary.json").find("\"steps\": 60"), std::string::npos);
  EXPECT_EQ(read_all(a + "/map.pgm").substr(0, 2), "P5");
  for (const auto& d : {a, b, c}) std::filesystem::remove_all(d);
}

// End to end through hal/sim: with noiseless odometry and the pass-through anchored at the true start,
// the estimate must reproduce the ground truth — any error in pairing (timestamps, interpolation,
// frames) shows up here. The residual comes only from interpolating across a turn→drive corner.
TEST(SimRunner, NoiselessOdometryPassThroughReproducesGroundTruth) {
  SimConfig cfg = small_run("", 2);
  cfg.steps = 0;
  cfg.synthetic.odometry.sigma_trans = 0;
  cfg.synthetic.odometry.sigma_rot_deg = 0;
  cfg.synthetic.odometry.odom_origin = fw::Se2d(-20, 7, 2.0);  // odometry frame ≠ map frame
  cfg.localizer_options["anchor"] = "truth";
  SimResult r;
  std::string err;
  ASSERT_TRUE(run_simulation(cfg, &r, &err)) << err;
  ASSERT_GT(r.steps.size(), 100u);
  // The pass-through is always `searching`, so the simulator scores none of its poses (err_m is
  // NaN): the pairing is checked on the raw estimate here.
  auto dist = [](const StepRecord& s) { return std::hypot(s.estimate.x - s.truth.x, s.estimate.y - s.truth.y); };
  double max_err = 0, sum = 0;
  for (const StepRecord& s : r.steps) {
    ASSERT_TRUE(s.has_truth);
    EXPECT_EQ(s.estimate.status, hal::LocalizationStatus::kSearching);
    EXPECT_FALSE(s.has_pose);
    EXPECT_TRUE(std::isnan(s.err_m));
    max_err = std::max(max_err, dist(s));
    sum += dist(s);
  }
  EXPECT_LT(max_err, 0.05);
  EXPECT_LT(sum / r.steps.size(), 0.01);
  EXPECT_EQ(r.summary.scans_dropped, 0u);
  EXPECT_EQ(r.summary.ring_drops, 0u);
  EXPECT_EQ(r.summary.first_localized_step, -1);
  EXPECT_EQ(r.summary.final_pose_step, -1);
  EXPECT_TRUE(std::isnan(r.summary.final_err_m));
  // With the default noise the same run drifts far more.
  cfg.synthetic.odometry = OdometryNoiseOptions();
  ASSERT_TRUE(run_simulation(cfg, &r, &err)) << err;
  EXPECT_GT(dist(r.steps.back()), 0.2);
}

TEST(SimRunner, BadInputsAreClearErrors) {
  SimResult r;
  std::string err;
  SimConfig cfg = small_run("", 1);
  cfg.localizer = "magic";
  EXPECT_FALSE(run_simulation(cfg, &r, &err));
  EXPECT_NE(err.find("unknown localizer 'magic'"), std::string::npos) << err;
  EXPECT_NE(err.find("odom"), std::string::npos) << err;
  cfg = small_run("", 1);
  cfg.localizer_options["colour"] = "blue";
  EXPECT_FALSE(run_simulation(cfg, &r, &err));
  EXPECT_NE(err.find("unknown option(s) colour"), std::string::npos) << err;
  cfg = small_run("", 1);
  cfg.localizer_options["anchor"] = "moon";
  EXPECT_FALSE(run_simulation(cfg, &r, &err));
  EXPECT_NE(err.find("anchor='moon'"), std::string::npos) << err;
  cfg = small_run("", 1);
  cfg.localizer = "mml-track";
  cfg.localizer_options["odom_noise"] = "0.2,0.2";
  EXPECT_FALSE(run_simulation(cfg, &r, &err));
  EXPECT_NE(err.find("odom_noise='0.2,0.2' (expected four numbers TT,TR,RR,RT in 0..10)"), std::string::npos) << err;
  cfg = small_run("", 1);
  cfg.world = "atlantis";
  EXPECT_FALSE(run_simulation(cfg, &r, &err));
  EXPECT_NE(err.find("atlantis"), std::string::npos);
  cfg = small_run("", 1);
  cfg.world.clear();
  cfg.log_path = "/nonexistent/dir/run.clf";
  EXPECT_FALSE(run_simulation(cfg, &r, &err));
  EXPECT_NE(err.find("/nonexistent/dir/run.clf"), std::string::npos) << err;
  // A truncated / garbage log names the file and line.
  const std::string d = temp_dir("badlog");
  std::filesystem::create_directories(d);
  {
    std::ofstream f(d + "/bad.clf");
    f << "FLASER 3 1.0 2.0 3.0\n";
  }
  cfg.log_path = d + "/bad.clf";
  EXPECT_FALSE(run_simulation(cfg, &r, &err));
  EXPECT_NE(err.find("bad.clf"), std::string::npos) << err;
  // Issue 13: a map whose origin float coordinates cannot resolve, a FIFO as map image (blocked).
  {
    std::ofstream f(d + "/good.clf");
    f << "FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 1.0 host 1.0\n";
    std::ofstream p(d + "/m.pgm", std::ios::binary);
    p << "P5\n2 1\n255\n" << '\0' << '\xfe';
    std::ofstream y(d + "/far.yaml");
    y << "image: m.pgm\nresolution: 0.05\norigin: [-1e38, -1e38, 0]\nnegate: 0\noccupied_thresh: 0.65\n"
         "free_thresh: 0.196\n";
    std::ofstream z(d + "/fifo.yaml");
    z << "image: fifo.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\n"
         "free_thresh: 0.196\n";
  }
  cfg.log_path = d + "/good.clf";
  cfg.map_yaml = d + "/far.yaml";
  EXPECT_FALSE(run_simulation(cfg, &r, &err));
  EXPECT_NE(err.find("far.yaml: field 'origin'"), std::string::npos) << err;
  ASSERT_EQ(::mkfifo((d + "/fifo.pgm").c_str(), 0600), 0);
  cfg.map_yaml = d + "/fifo.yaml";
  EXPECT_FALSE(run_simulation(cfg, &r, &err));
  EXPECT_NE(err.find("not a regular file (a FIFO)"), std::string::npos) << err;
  std::filesystem::remove_all(d);
}

// A localizer that exposes hypotheses through the factory hook: the simulator collects and draws them.
class HypothesisOdom final : public fw::Localizer {
 public:
  const char* name() const override { return "test-hyps"; }
  void reset() override { inner_.reset(); }
  fw::Status step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) override {
    ++steps_;
    return inner_.step(scan, odom, out);
  }
  int steps_ = 0;

 private:
  fw::OdometryLocalizer inner_;
};

TEST(LocalizerFactory, RegisteredLocalizerAndHypothesisHook) {
  register_localizer("test-hyps", "test: odometry with fake hypotheses", [](const LocalizerContext& ctx, std::string* err) {
    const std::string bad = unknown_option_keys("test-hyps", ctx.options, {});
    if (!bad.empty()) {
      *err = bad;
      return std::unique_ptr<fw::Localizer>();
    }
    EXPECT_NE(ctx.global_map, nullptr);  // worlds bring a compiled, loaded map
    EXPECT_TRUE(ctx.global_map->valid());
    EXPECT_GT(ctx.global_map->num_points, 100u);
    auto loc = std::make_unique<HypothesisOdom>();
    HypothesisOdom* raw = loc.get();
    ctx.hooks->hypotheses = [raw](std::vector<HypothesisPoint>* out) {
      for (int i = 0; i < 3; ++i) out->push_back({1.0 + i, 2.0, 0.0, 1.0 / (1 + raw->steps_)});
    };
    return std::unique_ptr<fw::Localizer>(std::move(loc));
  });
  bool listed = false;
  for (const auto& l : localizer_names()) listed |= l.name == "test-hyps";
  EXPECT_TRUE(listed);
  const std::string d = temp_dir("hyps");
  SimConfig cfg = small_run(d, 1);
  cfg.steps = 10;
  cfg.localizer = "test-hyps";
  SimResult r;
  std::string err;
  ASSERT_TRUE(run_simulation(cfg, &r, &err)) << err;
  ASSERT_EQ(r.last_hypotheses.size(), 3u);
  EXPECT_DOUBLE_EQ(r.last_hypotheses[0].weight, 1.0 / 11);
  EXPECT_EQ(r.last_hypotheses_step, 9);
  EXPECT_NE(read_all(d + "/run.svg").find("hypotheses (step 9)"), std::string::npos);
  const std::string hyps = read_all(d + "/hypotheses.csv");
  EXPECT_EQ(std::count(hyps.begin(), hyps.end(), '\n'), 1 + 10 * 3);  // header + 3 per step
  std::filesystem::remove_all(d);
}

TEST(SimRunner, CustomWorldAndPacing) {
  World w;
  w.name = "box-room";
  w.bounds = {Vec2(0, 0), Vec2(6, 4)};
  add_rect(&w, 0, 0, 6, 4);
  const int a = w.route.add_node(Vec2(1, 2)), b = w.route.add_node(Vec2(5, 2));
  w.route.connect(a, b);
  SimConfig cfg;
  cfg.localizer = "odom";
  cfg.custom_world = &w;
  cfg.progress = false;
  cfg.steps = 6;
  cfg.paced = true;
  cfg.synthetic.scan_period_s = 0.05;
  cfg.synthetic.people = 0;
  SimResult r;
  std::string err;
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(run_simulation(cfg, &r, &err)) << err;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.steps.size(), 6u);
  EXPECT_EQ(r.summary.source, "world:box-room");
  EXPECT_GE(wall, 0.25 - 0.01);  // scans at 0, 0.05, ..., 0.25 s, paced at real time
  cfg.pace_speed = 100;           // paced 100× faster
  ASSERT_TRUE(run_simulation(cfg, &r, &err)) << err;
}

// A localizer whose published pose is a scripted mix of placeholders and real poses: the pose of
// a dead-reckoning pass-through anchored at the true start (noiseless odometry: ≈ the truth), or
// the (0, 0, 0) placeholder with no covariance, under a scripted status and protection level.
class ScriptedLocalizer final : public fw::Localizer {
 public:
  explicit ScriptedLocalizer(const fw::OdometryLocalizerOptions& o) : inner_(o) {}
  const char* name() const override { return "test-scripted"; }
  void reset() override { inner_.reset(); }
  fw::Status step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) override {
    const fw::Status st = inner_.step(scan, odom, out);
    const int k = n_++;
    // 0-4 searching, 5-9 ambiguous, 10-14 outside-map: all without a pose; 15-29 localized with a
    // pose and a protection level; 30-34 fault; 35-39 outside-map without a pose.
    const bool pose = k >= 15 && k < 30;
    out->status = k < 5    ? hal::LocalizationStatus::kSearching
                  : k < 10 ? hal::LocalizationStatus::kAmbiguous
                  : k < 15 ? hal::LocalizationStatus::kOutsideMap
                  : k < 30 ? hal::LocalizationStatus::kLocalized
                  : k < 35 ? hal::LocalizationStatus::kFault
                           : hal::LocalizationStatus::kOutsideMap;
    if (!pose) {
      out->x = out->y = out->theta = 0.0f;
      for (float& c : out->cov) c = 0.0f;
      out->protection_xy_m = out->protection_theta_rad = 0.0f;
      out->unsupported_steps = 0;
      out->mode = hal::LocalizationMode::kGlobal;
    } else {
      out->mode = hal::LocalizationMode::kTracking;
      out->protection_xy_m = 0.2f;
      out->protection_theta_rad = 0.05f;
      out->unsupported_steps = static_cast<std::uint16_t>(k % 3);
    }
    return st;
  }

 private:
  fw::OdometryLocalizer inner_;
  int n_ = 0;
};

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> f;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      f.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  f.push_back(cur);
  return f;
}

// The summary never reports an error computed from a placeholder pose, and steps.csv carries the
// protection level columns.
TEST(SimSummary, PlaceholderPosesAreNeverScored) {
  register_localizer("test-scripted", "test: scripted placeholders", [](const LocalizerContext& ctx, std::string*) {
    fw::OdometryLocalizerOptions o;
    o.initial_pose = ctx.true_start.cast<float>();
    return std::unique_ptr<fw::Localizer>(std::make_unique<ScriptedLocalizer>(o));
  });
  const std::string d = temp_dir("placeholder");
  SimConfig cfg = small_run(d, 3);
  cfg.steps = 40;
  cfg.localizer = "test-scripted";
  cfg.synthetic.odometry.sigma_trans = 0;
  cfg.synthetic.odometry.sigma_rot_deg = 0;
  SimResult r;
  std::string err;
  ASSERT_TRUE(run_simulation(cfg, &r, &err)) << err;
  ASSERT_EQ(r.steps.size(), 40u);
  // The start is far enough from the origin that a placeholder scored against the truth would show.
  ASSERT_GT(std::hypot(r.steps.front().truth.x, r.steps.front().truth.y), 1.0);
  for (const StepRecord& s : r.steps) {
    const bool pose = s.step >= 15 && s.step < 30;
    EXPECT_EQ(s.has_pose, pose) << "step " << s.step;
    EXPECT_EQ(estimate_has_pose(s.estimate), pose) << "step " << s.step;
    if (pose) {
      EXPECT_LT(s.err_m, 0.05) << "step " << s.step;
    } else {
      EXPECT_TRUE(std::isnan(s.err_m) && std::isnan(s.err_deg)) << "step " << s.step << ": error " << s.err_m;
    }
  }
  const SimSummary& sum = r.summary;
  EXPECT_EQ(sum.first_localized_step, 15);
  EXPECT_LT(sum.first_localized_err_m, 0.05);
  EXPECT_EQ(sum.final_pose_step, 29);  // not the outside-map placeholder at the end
  EXPECT_EQ(sum.final_pose_status, "localized");
  EXPECT_LT(sum.final_err_m, 0.05);
  EXPECT_LT(sum.max_err_localized_m, 0.05);
  EXPECT_EQ(sum.integrity_failures, 0u);
  EXPECT_EQ(sum.localized_steps, 15u);
  EXPECT_EQ(sum.pl_steps, 15u);
  EXPECT_EQ(sum.pl_exceeded, 0u);
  EXPECT_NEAR(sum.pl_xy_m_p50, 0.2, 1e-6);
  EXPECT_EQ(sum.availability_steps, 24u);  // steps 16..39
  EXPECT_EQ(sum.availability_localized, 14u);
  EXPECT_EQ(sum.tracking_steps, 15u);
  EXPECT_NE(summary_line(sum).find("(step 29, localized)"), std::string::npos) << summary_line(sum);

  // steps.csv: the new columns, empty errors where there is no pose, the PL where there is one.
  std::istringstream csv(read_all(d + "/steps.csv"));
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  const std::vector<std::string> head = split_csv_line(line);
  auto col = [&](const std::string& name) {
    const auto it = std::find(head.begin(), head.end(), name);
    EXPECT_NE(it, head.end()) << "steps.csv has no column " << name << ": " << line;
    return static_cast<size_t>(it - head.begin());
  };
  const size_t c_status = col("status"), c_err = col("err_m"), c_deg = col("err_deg"), c_pl = col("pl_xy_m"),
               c_plt = col("pl_theta_deg"), c_uns = col("unsupported_steps"), c_tx = col("truth_x");
  int rows = 0;
  while (std::getline(csv, line)) {
    const std::vector<std::string> f = split_csv_line(line);
    ASSERT_EQ(f.size(), head.size()) << line;
    const bool pose = rows >= 15 && rows < 30;
    EXPECT_FALSE(f[c_tx].empty()) << line;  // the truth is there either way
    if (pose) {
      EXPECT_EQ(f[c_status], "localized");
      EXPECT_LT(std::stod(f[c_err]), 0.05) << line;
      EXPECT_NEAR(std::stod(f[c_pl]), 0.2, 1e-4) << line;
      EXPECT_NEAR(std::stod(f[c_plt]), 0.05 * 180 / M_PI, 1e-2) << line;
      EXPECT_EQ(std::stoi(f[c_uns]), rows % 3) << line;
    } else {
      EXPECT_TRUE(f[c_err].empty() && f[c_deg].empty()) << line;
      EXPECT_TRUE(f[c_pl].empty() && f[c_plt].empty()) << line;
    }
    ++rows;
  }
  EXPECT_EQ(rows, 40);
  const std::string json = read_all(d + "/summary.json");
  EXPECT_NE(json.find("\"final_pose_step\": 29"), std::string::npos) << json;
  EXPECT_NE(json.find("\"availability\": "), std::string::npos);
  EXPECT_NE(json.find("\"integrity_failures\": 0"), std::string::npos);
  EXPECT_NE(json.find("\"pl_xy_m_max\": 0.2"), std::string::npos) << json;
  EXPECT_NE(read_all(d + "/run.svg").find("protection level (1 in 10 localized)"), std::string::npos);
  std::filesystem::remove_all(d);
}

StepRecord rec(std::uint32_t step, hal::LocalizationStatus st, double err_m, double err_deg = 0.1) {
  StepRecord r;
  r.step = step;
  r.t = 0.4 * step;
  r.travelled_m = 0.3 * step;
  r.has_truth = true;
  r.estimate.status = st;
  r.estimate.x = 1.0f;  // any pose but the placeholder
  r.has_pose = st != hal::LocalizationStatus::kSearching;
  if (r.has_pose) {
    r.err_m = err_m;
    r.err_deg = err_deg;
  }
  return r;
}

// A robot carried after its fix: the steps from the carry to the re-fix are left out of the
// availability, as the corpus leaves them out (a carry not noticed, `localized` on, ends it at once).
TEST(SimSummary, CarriedStepsAreLeftOutOfTheAvailability) {
  using S = hal::LocalizationStatus;
  std::vector<StepRecord> v;
  for (std::uint32_t i = 0; i < 5; ++i) v.push_back(rec(i, S::kLocalized, 0.01));  // 0-4
  v.push_back(rec(5, S::kAmbiguous, 9.0));  // 5: carried, noticed
  v.back().kidnapped = true;
  for (std::uint32_t i = 6; i < 9; ++i) v.push_back(rec(i, S::kSearching, 9.0));  // 6-8: searching
  v.push_back(rec(9, S::kLocalized, 0.02));  // 9: re-fix
  v.push_back(rec(10, S::kAmbiguous, 0.02));  // 10: withheld, counted
  SimSummary s;
  summarize_steps(v, &s);
  EXPECT_EQ(s.carried_steps, 4u);       // 5-8
  EXPECT_EQ(s.availability_steps, 6u);  // 1-4, 9, 10
  EXPECT_EQ(s.availability_localized, 5u);
  EXPECT_NE(availability_text(s).find("4 carried until the re-fix left out"), std::string::npos) << availability_text(s);
}

// The figures of the summary from hand-made steps: first fix, availability (the unknown area left
// out), integrity failures (position or heading), protection level exceedances, kidnap detection
// and re-fix, final error.
TEST(SimSummary, FiguresFromSteps) {
  using S = hal::LocalizationStatus;
  std::vector<StepRecord> v;
  for (std::uint32_t i = 0; i < 5; ++i) v.push_back(rec(i, S::kSearching, 0));  // 0-4: no pose
  for (std::uint32_t i = 5; i < 15; ++i) {                                         // 5-14: tracked
    v.push_back(rec(i, S::kLocalized, 0.01 * (i - 4)));
    v.back().estimate.mode = hal::LocalizationMode::kTracking;
    v.back().estimate.protection_xy_m = 0.05f;  // exceeded from step 10 on (err 0.06 m)
    v.back().estimate.protection_theta_rad = 0.1f;
  }
  v.push_back(rec(15, S::kLocalized, 0.2, 7.0));  // heading off by 7°: integrity failure
  v.back().estimate.mode = hal::LocalizationMode::kTracking;
  v.push_back(rec(16, S::kAmbiguous, 0.3));
  v.back().in_unknown = true;  // left out of the availability
  v.push_back(rec(17, S::kLocalized, 40.0));  // 17: kidnapped, still `localized` (failure)
  v.back().kidnapped = true;
  v.back().estimate.mode = hal::LocalizationMode::kTracking;
  v.push_back(rec(18, S::kLocalized, 40.0));
  v.back().estimate.mode = hal::LocalizationMode::kTracking;
  v.push_back(rec(19, S::kAmbiguous, 40.0));   // detected: 2 steps after the kidnap
  v.back().estimate.reason = hal::StatusReason::kTrackFault;
  v.push_back(rec(20, S::kSearching, 0));
  v.back().estimate.reason = hal::StatusReason::kSearching;
  v.push_back(rec(21, S::kLocalized, 0.02));   // re-fix
  v.back().estimate.mode = hal::LocalizationMode::kTracking;
  v.push_back(rec(22, S::kOutsideMap, 0));
  v.back().has_pose = false;  // a placeholder: the final error is step 21's
  v.back().err_m = v.back().err_deg = NAN;
  v.back().estimate.reason = hal::StatusReason::kOutsideMap;
  SimSummary s;
  s.source = "test";
  summarize_steps(v, &s);
  // The 3 availability steps not `localized`, by the reason published with them.
  EXPECT_EQ(s.unavailable_by_reason[static_cast<int>(hal::StatusReason::kTrackFault)], 1u);
  EXPECT_EQ(s.unavailable_by_reason[static_cast<int>(hal::StatusReason::kSearching)], 1u);
  EXPECT_EQ(s.unavailable_by_reason[static_cast<int>(hal::StatusReason::kOutsideMap)], 1u);
  EXPECT_NE(availability_text(s).find("[not localized: "), std::string::npos) << availability_text(s);
  EXPECT_EQ(s.steps, 23u);
  EXPECT_EQ(s.first_localized_step, 5);
  EXPECT_DOUBLE_EQ(s.first_localized_err_m, 0.01);
  EXPECT_EQ(s.localized_steps, 14u);
  EXPECT_EQ(s.unknown_area_steps, 1u);
  EXPECT_EQ(s.availability_steps, 16u);  // steps 6..22 without 16
  EXPECT_EQ(s.availability_localized, 13u);  // 6-15, 17, 18, 21
  EXPECT_NEAR(s.availability, 13.0 / 16.0, 1e-12);
  EXPECT_EQ(s.integrity_failures, 3u);  // 15 (heading), 17 and 18 (kidnapped)
  EXPECT_EQ(s.integrity_failures_kidnap, 2u);
  EXPECT_EQ(s.first_integrity_failure_step, 15);
  EXPECT_EQ(s.wrong_localized_steps, 2u);  // the dissertation's 20° does not count step 15
  EXPECT_EQ(s.pl_steps, 10u);
  EXPECT_EQ(s.pl_exceeded, 5u);
  EXPECT_NEAR(s.pl_exceedance_rate, 0.5, 1e-12);
  EXPECT_NEAR(s.pl_xy_m_max, 0.05, 1e-6);
  EXPECT_EQ(s.kidnap_step, 17);
  EXPECT_EQ(s.kidnap_detected_step, 19);
  EXPECT_EQ(s.kidnap_detection_delay_steps, 2);
  EXPECT_EQ(s.relocalized_step, 21);
  EXPECT_NEAR(s.refix_travelled_m, 0.3 * 4, 1e-9);
  EXPECT_NEAR(s.refix_err_m, 0.02, 1e-12);
  EXPECT_EQ(s.final_pose_step, 21);
  EXPECT_EQ(s.final_pose_status, "localized");
  EXPECT_DOUBLE_EQ(s.final_err_m, 0.02);
  EXPECT_EQ(s.tracking_steps, 14u);
  EXPECT_EQ(s.source, "test");  // what the caller measured is kept
  const std::string line = summary_line(s);
  for (const char* part : {"first fix at step 5", "availability 81.2 %", "integrity failures 3",
                           "kidnap at step 17: detected after 2 steps", "(step 21, localized)"}) {
    EXPECT_NE(line.find(part), std::string::npos) << part << " not in: " << line;
  }
  // A log reference between corrected poses is itself off by up to its bound (reference_trajectory.h):
  // an error counts only beyond the limit plus that bound; the rest is counted apart, not judged.
  std::vector<StepRecord> w;
  for (std::uint32_t i = 0; i < 4; ++i) {
    w.push_back(rec(i, S::kLocalized, 0.05, i < 2 ? 7.0 : 2.0));  // 7° > 5°, or 2° > PL 1.15°
    w.back().estimate.mode = hal::LocalizationMode::kTracking;
    w.back().estimate.protection_xy_m = 0.2f;
    w.back().estimate.protection_theta_rad = 0.02f;
    w.back().truth_bound_deg = i % 2 == 0 ? 3.0 : 0.5;  // 0, 2: within the bound; 1, 3: beyond it
  }
  w.push_back(rec(4, S::kLocalized, 0.05, 7.0));
  w.back().truth_bound_deg = INFINITY;  // extrapolated beyond the last corrected pose: never judged
  SimSummary b;
  summarize_steps(w, &b);
  EXPECT_EQ(b.integrity_failures, 1u);           // step 1
  EXPECT_EQ(b.integrity_not_judged, 2u);  // steps 0 and 4
  EXPECT_EQ(b.pl_exceeded, 3u);                  // steps 0 (7° > 1.15° + 3°), 1 and 3
  EXPECT_EQ(b.pl_not_judged, 1u);         // step 2 (2° < 1.15° + 3°)
  EXPECT_NE(summary_line(b).find("integrity failures 1 (> 0.5 m or > 5 deg) + 2 not judged"),
            std::string::npos)
      << summary_line(b);
  // No steps with a pose: nothing to report, and nothing made up.
  SimSummary none;
  summarize_steps({rec(0, S::kSearching, 0), rec(1, S::kSearching, 0)}, &none);
  EXPECT_EQ(none.first_localized_step, -1);
  EXPECT_EQ(none.final_pose_step, -1);
  EXPECT_TRUE(std::isnan(none.final_err_m));
  EXPECT_TRUE(std::isnan(none.availability));
  EXPECT_NE(summary_line(none).find("no fix"), std::string::npos);
}

// Protection circles (radius in metres) and failure crosses reach both renderers and the legend.
TEST(Picture, CirclesAndCrosses) {
  Picture pic;
  pic.title = "circles";
  pic.x_min = 0;
  pic.y_min = 0;
  pic.x_max = 10;
  pic.y_max = 5;
  pic.pixels_per_metre = 50;
  pic.circle_sets.push_back({{{2, 2, 0.5}, {5, 2, 1.0}, {7, 2, NAN}}, {0, 170, 190}, 1.2, "protection level"});
  pic.point_sets.push_back({{{5, 2}}, {255, 0, 40}, 7.0, "integrity failure (1)", PointShape::kCross});
  const std::string d = temp_dir("circles");
  std::filesystem::create_directories(d);
  std::string err;
  ASSERT_TRUE(write_svg(pic, d + "/c.svg", &err)) << err;
  ASSERT_TRUE(write_png(pic, d + "/c.png", &err)) << err;
  const std::string svg = read_all(d + "/c.svg");
  EXPECT_NE(svg.find("r=\"25\""), std::string::npos);  // 0.5 m at 50 px/m
  EXPECT_NE(svg.find("r=\"50\""), std::string::npos);
  EXPECT_EQ(svg.find("nan"), std::string::npos);       // the non-finite circle is skipped
  EXPECT_NE(svg.find("<path d=\"M"), std::string::npos);
  EXPECT_NE(svg.find("integrity failure (1)"), std::string::npos);
  EXPECT_NE(svg.find("protection level"), std::string::npos);
  EXPECT_EQ(read_all(d + "/c.png").substr(1, 3), "PNG");
  if (std::getenv("MML_SIM_TEST_KEEP") == nullptr) std::filesystem::remove_all(d);
}

TEST(Picture, Base64AndPngEncoding) {
  EXPECT_EQ(base64({'M', 'a', 'n'}), "TWFu");
  EXPECT_EQ(base64({'M', 'a'}), "TWE=");
  EXPECT_EQ(base64({'M'}), "TQ==");
  EXPECT_EQ(base64({}), "");
  std::vector<std::uint8_t> png;
  std::string err;
  ASSERT_TRUE(encode_png_rgb(2, 1, {255, 0, 0, 0, 0, 255}, &png, &err)) << err;
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png[1], 'P');
  EXPECT_FALSE(encode_png_rgb(2, 2, {1, 2, 3}, &png, &err));
  Picture empty;
  EXPECT_FALSE(write_svg(empty, "/tmp/never.svg", &err));
  EXPECT_NE(err.find("extent"), std::string::npos);
}

}  // namespace
}  // namespace sim
