#include <gtest/gtest.h>

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
  double max_err = 0, sum = 0;
  for (const StepRecord& s : r.steps) {
    ASSERT_TRUE(s.has_truth);
    EXPECT_EQ(s.estimate.status, hal::LocalizationStatus::kSearching);
    max_err = std::max(max_err, s.err_m);
    sum += s.err_m;
  }
  EXPECT_LT(max_err, 0.05);
  EXPECT_LT(sum / r.steps.size(), 0.01);
  EXPECT_EQ(r.summary.scans_dropped, 0u);
  EXPECT_EQ(r.summary.ring_drops, 0u);
  EXPECT_EQ(r.summary.first_localized_step, -1);
  // With the default noise the same run drifts far more.
  cfg.synthetic.odometry = OdometryNoiseOptions();
  ASSERT_TRUE(run_simulation(cfg, &r, &err)) << err;
  EXPECT_GT(r.summary.final_err_m, 0.2);
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
