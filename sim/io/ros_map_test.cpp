#include "sim/io/ros_map.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/alloc_counter.h"

namespace sim {
namespace {

namespace fs = std::filesystem;

class RosMapTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("ros_map_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void write_text(const std::string& name, const std::string& text) const {
    std::ofstream o(path(name), std::ios::binary);
    o << text;
  }
  std::string read_text(const std::string& name) const {
    std::ifstream in(path(name), std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  static RosMap sample() {
    RosMap m;
    m.image = "sample.pgm";
    m.resolution = 0.05;
    m.origin[0] = -12.345678901234;
    m.origin[1] = 3.1;
    m.origin[2] = 0.0;
    m.width = 7;
    m.height = 4;
    for (int i = 0; i < 28; ++i) m.pixels.push_back(static_cast<std::uint8_t>((i * 37) % 256));
    return m;
  }
  fs::path dir_;
};

void expect_same(const RosMap& a, const RosMap& b) {
  EXPECT_EQ(a.image, b.image);
  EXPECT_EQ(a.resolution, b.resolution);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(a.origin[i], b.origin[i]);
  EXPECT_EQ(a.negate, b.negate);
  EXPECT_EQ(a.occupied_thresh, b.occupied_thresh);
  EXPECT_EQ(a.free_thresh, b.free_thresh);
  EXPECT_EQ(a.mode, b.mode);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.maxval, b.maxval);
  EXPECT_EQ(a.pgm_ascii, b.pgm_ascii);
  EXPECT_EQ(a.pixels, b.pixels);
}

TEST_F(RosMapTest, RoundTripIsBitExactP5AndP2) {
  for (bool ascii : {false, true}) {
    RosMap m = sample();
    m.pgm_ascii = ascii;
    std::string err;
    ASSERT_TRUE(write_ros_map(path("a.yaml"), m, &err)) << err;
    RosMap r;
    ASSERT_TRUE(read_ros_map(path("a.yaml"), &r, &err)) << err;
    expect_same(m, r);
    const std::string yaml1 = read_text("a.yaml"), pgm1 = read_text("sample.pgm");
    ASSERT_TRUE(write_ros_map(path("a.yaml"), r, &err)) << err;
    EXPECT_EQ(read_text("a.yaml"), yaml1);
    EXPECT_EQ(read_text("sample.pgm"), pgm1);
    EXPECT_EQ(pgm1.substr(0, 2), ascii ? "P2" : "P5");
  }
}

TEST_F(RosMapTest, ReadsForeignYamlWithCommentsQuotesAndMaxval) {
  // Hand-written like a map_server file: quotes, comments, true/false, P2 with comments, maxval 15.
  write_text("m.pgm", "P2\n# CREATOR: test\n3 2\n15\n0 15 7\n# mid comment\n15 0 8\n");
  write_text("m.yaml",
             "# a map\nimage: \"m.pgm\"\nresolution: 0.1\norigin: [ -1.5, 2, 0.0 ]  # corner\n"
             "negate: false\noccupied_thresh: 0.65\nfree_thresh: 0.196\n");
  RosMap m;
  std::string err;
  ASSERT_TRUE(read_ros_map(path("m.yaml"), &m, &err)) << err;
  EXPECT_EQ(m.image, "m.pgm");
  EXPECT_EQ(m.mode, "trinary");  // default
  EXPECT_EQ(m.maxval, 15);
  EXPECT_TRUE(m.pgm_ascii);
  EXPECT_EQ(m.origin[0], -1.5);
  EXPECT_EQ(m.origin[1], 2.0);
  EXPECT_EQ(m.pixels, (std::vector<std::uint8_t>{0, 15, 7, 15, 0, 8}));
  OccupancyGrid g;
  ASSERT_TRUE(ros_map_to_grid(m, &g, &err)) << err;
  // Top image row is the highest y: grid row 1. p = (15 - v)/15.
  EXPECT_EQ(g.cells[g.geometry.index(0, 1)], 100);  // v 0 -> p 1
  EXPECT_EQ(g.cells[g.geometry.index(1, 1)], 0);    // v 15 -> p 0
  EXPECT_EQ(g.cells[g.geometry.index(2, 1)], 255);  // v 7 -> p 0.53 unknown
  EXPECT_EQ(g.cells[g.geometry.index(0, 0)], 0);
  EXPECT_EQ(g.cells[g.geometry.index(1, 0)], 100);
  EXPECT_EQ(g.cells[g.geometry.index(2, 0)], 255);  // v 8 -> p 0.47
  std::vector<fw::Point2f> pts;
  ASSERT_TRUE(ros_map_occupied_points(m, &pts, &err)) << err;
  ASSERT_EQ(pts.size(), 2u);
  // Lowest row first: cell (1,0) centre = (-1.5 + 0.15, 2 + 0.05).
  EXPECT_NEAR(pts[0].x(), -1.35f, 1e-6f);
  EXPECT_NEAR(pts[0].y(), 2.05f, 1e-6f);
  EXPECT_NEAR(pts[1].x(), -1.45f, 1e-6f);
  EXPECT_NEAR(pts[1].y(), 2.15f, 1e-6f);
}

TEST_F(RosMapTest, NegateScaleAndRawModes) {
  RosMap m = sample();
  m.width = 4;
  m.height = 1;
  m.pixels = {0, 255, 128, 60};
  std::string err;
  OccupancyGrid g;
  m.negate = true;  // p = v / 255
  ASSERT_TRUE(ros_map_to_grid(m, &g, &err)) << err;
  EXPECT_EQ(g.cells, (std::vector<std::uint8_t>{0, 100, 255, 255}));
  m.negate = false;
  m.mode = "scale";  // p(128) = 0.498 -> 1 + 98 * (0.498 - 0.196) / 0.454
  ASSERT_TRUE(ros_map_to_grid(m, &g, &err)) << err;
  EXPECT_EQ(g.cells[0], 100);
  EXPECT_EQ(g.cells[1], 0);
  EXPECT_EQ(g.cells[2], 66);
  m.mode = "raw";
  m.pixels = {0, 100, 255, 42};
  ASSERT_TRUE(ros_map_to_grid(m, &g, &err)) << err;
  EXPECT_EQ(g.cells, (std::vector<std::uint8_t>{0, 100, 255, 42}));
  m.pixels[3] = 150;
  EXPECT_FALSE(ros_map_to_grid(m, &g, &err));
  EXPECT_NE(err.find("150"), std::string::npos) << err;
}

TEST_F(RosMapTest, GridToRosMapAndBackPreservesClasses) {
  OccupancyGrid g;
  g.geometry.resolution = 0.05f;
  g.geometry.origin_x = -1.0f;
  g.geometry.origin_y = 2.0f;
  g.geometry.width = 3;
  g.geometry.height = 2;
  g.cells = {0, 100, 255, 100, 255, 0};
  const RosMap m = grid_to_ros_map(g, "g.pgm");
  EXPECT_EQ(m.pixels, (std::vector<std::uint8_t>{0, 205, 254, 254, 0, 205}));  // top row = grid row 1
  OccupancyGrid back;
  std::string err;
  ASSERT_TRUE(ros_map_to_grid(m, &back, &err)) << err;
  EXPECT_EQ(back.cells, g.cells);
}

// Issue 60: what the hand-written line parser refused and map_server accepts: a block-style origin
// list, quoted keys, a document marker, comments everywhere.
TEST_F(RosMapTest, ReadsEveryValidMapServerYaml) {
  write_text("m.pgm", "P5\n2 1\n255\n\x01\x02");
  write_text("m.yaml",
             "%YAML 1.1\n---\n# a map\n'image': m.pgm\n\"resolution\": 0.1  # m\norigin:\n  - -1.5\n  - 2\n  # no yaw\n"
             "  - 0.0\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n");
  RosMap m;
  std::string err;
  ASSERT_TRUE(read_ros_map(path("m.yaml"), &m, &err)) << err;
  EXPECT_EQ(m.image, "m.pgm");
  EXPECT_EQ(m.resolution, 0.1);
  EXPECT_EQ(m.origin[0], -1.5);
  EXPECT_EQ(m.origin[1], 2.0);
}

struct BadYamlCase {
  const char* yaml;
  const char* expect;  // substring of the error
};

TEST_F(RosMapTest, MalformedYamlNamesFileAndField) {
  write_text("ok.pgm", "P5\n2 1\n255\n\x01\x02");
  const std::string good_tail = "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
  const BadYamlCase cases[] = {
      {"resolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
       "missing field 'image'"},
      {"image: ok.pgm\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
       "missing field 'resolution'"},
      {"image: ok.pgm\nresolution: 0.05\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
       "missing field 'origin'"},
      {"image: ok.pgm\nresolution: 0.05\norigin: [0, 0, 0]\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
       "missing field 'negate'"},
      {"image: ok.pgm\nresolution: -0.05\norigin: [0, 0, 0]\n", "field 'resolution'"},
      {"image: ok.pgm\nresolution: 0\norigin: [0, 0, 0]\n", "field 'resolution'"},
      {"image: ok.pgm\nresolution: abc\norigin: [0, 0, 0]\n", "field 'resolution'"},
      {"image: ok.pgm\nresolution: 0.05\norigin: [0, 0]\n", "field 'origin'"},
      {"image: ok.pgm\nresolution: 0.05\norigin: 0, 0, 0\n", "field 'origin'"},
      {"image: ok.pgm\nresolution: 0.05\norigin: [0, x, 0]\n", "field 'origin'"},
      {"image: missing.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n", "does not exist"},
      {"image: ok.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nmode: fuzzy\n", "field 'mode'"},
      {"image: ok.pgm\nresolution: 0.05\nresolution: 0.1\norigin: [0, 0, 0]\n", "duplicate field 'resolution'"},
      {"image: ok.pgm\nresolution 0.05\norigin: [0, 0, 0]\n", "bad.yaml:3:7: YAML: illegal map value"},
      {"image: ok.pgm\nresolution: [0.05\norigin: [0, 0, 0]\n", "bad.yaml:3:"},  // the library's line:column
      {"- image: ok.pgm\n", "expected 'key: value'"},
  };
  for (const BadYamlCase& c : cases) {
    std::string text = c.yaml;
    if (text.find("negate") == std::string::npos && text.find("occupied_thresh") == std::string::npos) text += good_tail;
    write_text("bad.yaml", text);
    RosMap m;
    std::string err;
    EXPECT_FALSE(read_ros_map(path("bad.yaml"), &m, &err)) << text;
    EXPECT_NE(err.find("bad.yaml"), std::string::npos) << err;
    EXPECT_NE(err.find(c.expect), std::string::npos) << "error '" << err << "' lacks '" << c.expect << "'";
  }
  // Threshold validation.
  write_text("t.yaml", "image: ok.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 2\noccupied_thresh: 0.65\nfree_thresh: 0.196\n");
  RosMap m;
  std::string err;
  EXPECT_FALSE(read_ros_map(path("t.yaml"), &m, &err));
  EXPECT_NE(err.find("field 'negate'"), std::string::npos) << err;
  write_text("t.yaml", "image: ok.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.1\nfree_thresh: 0.5\n");
  EXPECT_FALSE(read_ros_map(path("t.yaml"), &m, &err));
  EXPECT_NE(err.find("free_thresh"), std::string::npos) << err;
  EXPECT_FALSE(read_ros_map(path("nonexistent.yaml"), &m, &err));
  EXPECT_NE(err.find("nonexistent.yaml"), std::string::npos) << err;
}

TEST_F(RosMapTest, MalformedPgmIsRejectedWithReason) {
  struct Case {
    std::string data;
    const char* expect;
  };
  const Case cases[] = {
      {"P6\n2 2\n255\nxxxxxxxxxxxx", "bad magic"},
      {"", "bad magic"},
      {"P5\n2 2\n255\n\x01\x02\x03", "truncated P5"},
      {"P5\n2 2\n", "maxval"},
      {"P5\n2\n", "height"},
      {"P5\n0 2\n255\n", "out of range"},
      {"P5\n2 2\n65535\n\x01\x02\x03\x04\x05\x06\x07\x08", "maxval 65535 not supported"},
      {"P5\n2 2\n255", "no whitespace after maxval"},
      {"P2\n2 2\n255\n1 2 3\n", "truncated or malformed P2"},
      {"P2\n2 2\n10\n1 2 3 11\n", "exceeds maxval"},
      {"P5\n2 1\n10\n\x01\x0b", "exceeds maxval"},
  };
  for (const Case& c : cases) {
    write_text("x.pgm", c.data);
    RosMap m;
    std::string err;
    EXPECT_FALSE(read_pgm(path("x.pgm"), &m, &err)) << c.data;
    EXPECT_NE(err.find("x.pgm"), std::string::npos) << err;
    EXPECT_NE(err.find(c.expect), std::string::npos) << "error '" << err << "' lacks '" << c.expect << "'";
  }
  // Through the YAML: the PGM error surfaces with the image path.
  write_text("x.pgm", "P5\n4 4\n255\n\x01");
  write_text("x.yaml", "image: x.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n");
  RosMap m;
  std::string err;
  EXPECT_FALSE(read_ros_map(path("x.yaml"), &m, &err));
  EXPECT_NE(err.find("truncated"), std::string::npos) << err;
}

// Issue 13: a 16000x16000 header over 1 KB of data made read_pgm allocate the 256 MB raster before
// finding the data missing (100000x100000: 10 GB). The declared size is now checked against the
// bytes actually there, and against a cap, before anything is allocated for it.
TEST_F(RosMapTest, PgmHeaderBombIsRejectedBeforeAllocating) {
  struct Case {
    std::string data;
    const char* expect;
  };
  const std::string kilobyte(1024, '\x7f');
  const Case cases[] = {
      {"P5\n16000 16000\n255\n" + kilobyte, "truncated P5 data: 1024 of 256000000 pixel bytes"},
      {"P2\n16000 16000\n255\n" + std::string(1024, '1'), "truncated or malformed P2 data"},
      {"P5\n100000 100000\n255\n" + kilobyte, "more than the limit of 268435456"},
      {"P2\n100000 100000\n255\n" + kilobyte, "more than the limit of 268435456"},
  };
  for (const Case& c : cases) {
    write_text("bomb.pgm", c.data);
    RosMap m;
    std::string err;
    const bool counting = mmlfw_test::AllocCounter::available();
    if (counting) mmlfw_test::AllocCounter::begin();
    const bool ok = read_pgm(path("bomb.pgm"), &m, &err);
    const long bytes = counting ? (mmlfw_test::AllocCounter::end(), mmlfw_test::AllocCounter::bytes()) : 0;
    EXPECT_FALSE(ok);
    EXPECT_NE(err.find("bomb.pgm"), std::string::npos) << err;
    EXPECT_NE(err.find(c.expect), std::string::npos) << "error '" << err << "' lacks '" << c.expect << "'";
    EXPECT_LT(bytes, 1 << 20) << "allocated before checking the data: " << c.data.substr(0, 20);
  }
}

// Issue 13: `origin: [-1e38, -1e38, 0]` compiled (every cell centre rounds to the same float);
// resolutions and origins that float coordinates cannot resolve are refused naming the field.
TEST_F(RosMapTest, AbsurdOriginOrResolutionIsRejectedNamingTheField) {
  write_text("ok.pgm", "P5\n2 1\n255\n\x01\x02");
  const std::string tail = "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
  struct Case {
    const char* head;
    const char* expect;
  };
  const Case bad[] = {
      {"resolution: 0.05\norigin: [-1e38, -1e38, 0]\n", "field 'origin'"},
      {"resolution: 0.05\norigin: [1e39, 0, 0]\n", "field 'origin'"},  // finite double, infinite float
      {"resolution: 0.05\norigin: [0, 30000, 0]\n", "2^19 cells"},      // ±26 km at 5 cm
      {"resolution: 1e-30\norigin: [0, 0, 0]\n", "field 'resolution'"},
      {"resolution: 1e30\norigin: [0, 0, 0]\n", "field 'resolution'"},
      {"resolution: 0.05\norigin: [0, 0, nan]\n", "field 'origin'"},
  };
  for (const Case& c : bad) {
    write_text("m.yaml", std::string("image: ok.pgm\n") + c.head + tail);
    RosMap m;
    std::string err;
    EXPECT_FALSE(read_ros_map(path("m.yaml"), &m, &err)) << c.head;
    EXPECT_NE(err.find("m.yaml: "), std::string::npos) << err;
    EXPECT_NE(err.find(c.expect), std::string::npos) << "error '" << err << "' lacks '" << c.expect << "'";
  }
  // Large but representable: a 5 cm map 20 km from the world origin still loads.
  write_text("m.yaml", "image: ok.pgm\nresolution: 0.05\norigin: [-20000, 20000, 0]\n" + tail);
  RosMap m;
  std::string err;
  EXPECT_TRUE(read_ros_map(path("m.yaml"), &m, &err)) << err;
  // The extent depends on the image size too: the same origin with a wide image is refused.
  RosMap wide = sample();  // 7x4 cells of 0.05 m
  wide.origin[0] = 26214.1;  // + 7 cells = 26214.45 m > 2^19 cells = 26214.4 m
  EXPECT_FALSE(validate_ros_map(wide, "w.yaml", &err));
  EXPECT_NE(err.find("w.yaml: field 'origin'"), std::string::npos) << err;
  EXPECT_NE(err.find("7x4 cells"), std::string::npos) << err;
  wide.width = 1;  // + 1 cell = 26214.15 m
  wide.pixels.resize(4);
  EXPECT_TRUE(validate_ros_map(wide, "w.yaml", &err)) << err;
}

// Issue 13: `image: /dev/zero` read forever, a FIFO as YAML or image blocked forever, a directory
// threw from the stream. Only regular files are opened (checked with stat first).
TEST_F(RosMapTest, ImageOrYamlThatIsNotARegularFileIsAnError) {
  const std::string tail = "resolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
  ASSERT_EQ(::mkfifo(path("fifo.pgm").c_str(), 0600), 0);
  fs::create_directory(path("dir.pgm"));
  struct Case {
    std::string image;
    const char* expect;
  };
  const Case cases[] = {
      {"/dev/zero", "field 'image': /dev/zero: not a regular file (a character device)"},
      {path("fifo.pgm"), "not a regular file (a FIFO)"},
      {"dir.pgm", "not a regular file (a directory)"},
  };
  for (const Case& c : cases) {
    write_text("m.yaml", "image: " + c.image + "\n" + tail);
    RosMap m;
    std::string err;
    EXPECT_FALSE(read_ros_map(path("m.yaml"), &m, &err)) << c.image;
    EXPECT_NE(err.find("m.yaml: "), std::string::npos) << err;
    EXPECT_NE(err.find(c.expect), std::string::npos) << "error '" << err << "' lacks '" << c.expect << "'";
  }
  RosMap m;
  std::string err;
  ASSERT_EQ(::mkfifo(path("fifo.yaml").c_str(), 0600), 0);
  EXPECT_FALSE(read_ros_map(path("fifo.yaml"), &m, &err));
  EXPECT_NE(err.find("fifo.yaml: not a regular file (a FIFO)"), std::string::npos) << err;
  EXPECT_FALSE(read_ros_map(dir_.string(), &m, &err));
  EXPECT_NE(err.find("a directory"), std::string::npos) << err;
  EXPECT_FALSE(read_pgm("/dev/zero", &m, &err));
  EXPECT_NE(err.find("character device"), std::string::npos) << err;
  // A YAML larger than any map description (1 MiB) is not read whole.
  write_text("huge.yaml", "image: ok.pgm\n" + std::string((1 << 20) + 1, '#'));
  EXPECT_FALSE(read_ros_map(path("huge.yaml"), &m, &err));
  EXPECT_NE(err.find("more than the limit"), std::string::npos) << err;
}

TEST_F(RosMapTest, NonZeroYawRejectedForGrids) {
  RosMap m = sample();
  m.origin[2] = 0.3;
  OccupancyGrid g;
  std::string err;
  EXPECT_FALSE(ros_map_to_grid(m, &g, &err));
  EXPECT_NE(err.find("yaw"), std::string::npos) << err;
}

}  // namespace
}  // namespace sim
