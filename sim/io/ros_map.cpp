#include "sim/io/ros_map.h"

#include "sim/common/fail.h"
#include "sim/io/file_io.h"

#include <cerrno>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <yaml-cpp/yaml.h>

namespace sim {
namespace {

std::string trim(const std::string& s) {
  std::size_t b = 0, e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return s.substr(b, e - b);
}

bool parse_double(const std::string& text, double* out) {
  const std::string t = trim(text);
  if (t.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(t.c_str(), &end);
  if (errno != 0 || end != t.c_str() + t.size()) return false;
  *out = v;
  return true;
}

// Shortest representation that reads back to the same double (bit-exact YAML round trip).
std::string format_double(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof(buf), v);
  std::string s(buf, r.ptr);
  // Keep it recognisably a float for YAML readers ("1" -> "1.0").
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

// PGM pixel budget: 2^28 cells (16384 × 16384; a 0.05 m map of 819 m square). The firmware holds 5
// bytes per cell in its arena, so this is already more than any robot loads; it keeps a forged header
// from making the host tools allocate gigabytes.
constexpr long long kMaxPgmCells = 1LL << 28;

// PGM header tokenizer: whitespace and '#' comments between tokens.
struct PgmCursor {
  const std::string& d;
  std::size_t pos = 0;
  void skip_space_and_comments() {
    while (pos < d.size()) {
      if (d[pos] == '#') {
        while (pos < d.size() && d[pos] != '\n' && d[pos] != '\r') ++pos;
      } else if (std::isspace(static_cast<unsigned char>(d[pos]))) {
        ++pos;
      } else {
        break;
      }
    }
  }
  // Reads an unsigned decimal; false at end of data or on a non-digit.
  bool read_uint(long long* v) {
    skip_space_and_comments();
    if (pos >= d.size() || !std::isdigit(static_cast<unsigned char>(d[pos]))) return false;
    long long x = 0;
    while (pos < d.size() && std::isdigit(static_cast<unsigned char>(d[pos]))) {
      x = x * 10 + (d[pos] - '0');
      if (x > (1LL << 40)) return false;
      ++pos;
    }
    *v = x;
    return true;
  }
};

std::string resolve_image_path(const std::string& yaml_path, const std::string& image) {
  std::filesystem::path p(image);
  if (p.is_absolute()) return image;
  return (std::filesystem::path(yaml_path).parent_path() / p).string();
}

}  // namespace

bool read_pgm(const std::string& path, RosMap* out, std::string* error) {
  std::string d;
  if (!read_regular_file(path, kMaxMapFileBytes, &d, error)) return false;
  if (d.size() < 2 || d[0] != 'P' || (d[1] != '2' && d[1] != '5')) {
    return fail(error, path + ": bad magic (expected PGM 'P2' or 'P5')");
  }
  const bool ascii = d[1] == '2';
  PgmCursor c{d, 2};
  long long w = 0, h = 0, maxval = 0;
  if (!c.read_uint(&w)) return fail(error, path + ": PGM header: missing or invalid width");
  if (!c.read_uint(&h)) return fail(error, path + ": PGM header: missing or invalid height");
  if (!c.read_uint(&maxval)) return fail(error, path + ": PGM header: missing or invalid maxval");
  if (w <= 0 || h <= 0 || w > 100000 || h > 100000) {
    return fail(error, path + ": PGM header: size " + std::to_string(w) + "x" + std::to_string(h) +
                           " out of range (1..100000)");
  }
  if (maxval < 1 || maxval > 255) {
    return fail(error, path + ": PGM header: maxval " + std::to_string(maxval) +
                           " not supported (8-bit PGM only, 1..255)");
  }
  if (w * h > kMaxPgmCells) {
    return fail(error, path + ": PGM header: size " + std::to_string(w) + "x" + std::to_string(h) + " is " +
                           std::to_string(w * h) + " pixels, more than the limit of " + std::to_string(kMaxPgmCells));
  }
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  // The declared size must fit the data actually there before anything is allocated for it: P5 holds
  // one byte per pixel after exactly one whitespace byte, P2 at least a digit and a separator each.
  const std::size_t rest = d.size() - std::min(d.size(), c.pos);
  if (!ascii) {
    if (rest == 0 || !std::isspace(static_cast<unsigned char>(d[c.pos]))) {
      return fail(error, path + ": PGM header: no whitespace after maxval");
    }
    if (rest - 1 < n) {
      return fail(error, path + ": truncated P5 data: " + std::to_string(rest - 1) + " of " + std::to_string(n) +
                             " pixel bytes (header says " + std::to_string(w) + "x" + std::to_string(h) + ")");
    }
  }
  if (ascii && rest < 2 * n) {
    return fail(error, path + ": truncated or malformed P2 data: " + std::to_string(rest) + " bytes cannot hold " +
                           std::to_string(n) + " pixels (header says " + std::to_string(w) + "x" + std::to_string(h) +
                           ")");
  }
  std::vector<std::uint8_t> pixels(n);
  if (ascii) {
    for (std::size_t i = 0; i < n; ++i) {
      long long v = 0;
      if (!c.read_uint(&v)) {
        return fail(error, path + ": truncated or malformed P2 data: pixel " + std::to_string(i) + " of " +
                               std::to_string(n) + " missing");
      }
      if (v > maxval) {
        return fail(error, path + ": pixel " + std::to_string(i) + " value " + std::to_string(v) + " exceeds maxval " +
                               std::to_string(maxval));
      }
      pixels[i] = static_cast<std::uint8_t>(v);
    }
  } else {
    ++c.pos;  // exactly one whitespace byte separates maxval from the raster (checked above)
    std::memcpy(pixels.data(), d.data() + c.pos, n);
    for (std::size_t i = 0; i < n; ++i) {
      if (pixels[i] > maxval) {
        return fail(error, path + ": pixel " + std::to_string(i) + " value " + std::to_string(pixels[i]) +
                               " exceeds maxval " + std::to_string(maxval));
      }
    }
  }
  out->width = static_cast<int>(w);
  out->height = static_cast<int>(h);
  out->maxval = static_cast<int>(maxval);
  out->pgm_ascii = ascii;
  out->pixels = std::move(pixels);
  return true;
}

bool write_pgm(const std::string& path, const RosMap& map, std::string* error) {
  if (map.width <= 0 || map.height <= 0 ||
      map.pixels.size() != static_cast<std::size_t>(map.width) * static_cast<std::size_t>(map.height)) {
    return fail(error, path + ": cannot write PGM: pixel buffer does not match " + std::to_string(map.width) + "x" +
                           std::to_string(map.height));
  }
  if (map.maxval < 1 || map.maxval > 255) return fail(error, path + ": cannot write PGM: maxval out of 1..255");
  std::ostringstream o;
  o << (map.pgm_ascii ? "P2" : "P5") << "\n" << map.width << " " << map.height << "\n" << map.maxval << "\n";
  if (map.pgm_ascii) {
    for (int y = 0; y < map.height; ++y) {
      for (int x = 0; x < map.width; ++x) {
        o << static_cast<int>(map.pixels[static_cast<std::size_t>(y) * map.width + x]);
        o << ((x + 1 == map.width || (x + 1) % 16 == 0) ? '\n' : ' ');
      }
    }
  } else {
    o.write(reinterpret_cast<const char*>(map.pixels.data()), static_cast<std::streamsize>(map.pixels.size()));
  }
  return write_file_atomic(path, o.str(), error);
}

bool validate_ros_map(const RosMap& m, const std::string& name, std::string* error) {
  if (m.image.empty()) return fail(error, name + ": field 'image': empty");
  if (!std::isfinite(m.resolution) || !(m.resolution > 0.0)) {
    return fail(error, name + ": field 'resolution': must be a positive number (got " + format_double(m.resolution) + ")");
  }
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(m.origin[i])) return fail(error, name + ": field 'origin': component " + std::to_string(i) + " not finite");
  }
  // Float world coordinates must still resolve the cells (firmware/map/grid_geometry.h): an origin of
  // -1e38 or a 1e-30 m resolution would compile into a map whose points all collapse onto one.
  const double cells_w = std::max(m.width, 1), cells_h = std::max(m.height, 1);
  switch (fw::check_grid_extent(m.resolution, m.origin[0], m.origin[1], cells_w, cells_h)) {
    case fw::GridExtentProblem::kNone:
      break;
    case fw::GridExtentProblem::kResolution:
      return fail(error, name + ": field 'resolution': " + format_double(m.resolution) +
                             " m is outside the supported [" + format_double(fw::kMinGridResolutionM) + ", " +
                             format_double(fw::kMaxGridResolutionM) + "] m");
    case fw::GridExtentProblem::kOrigin:
    case fw::GridExtentProblem::kReach: {
      const double reach = fw::grid_reach_m(m.resolution, m.origin[0], m.origin[1], cells_w, cells_h);
      return fail(error, name + ": field 'origin': [" + format_double(m.origin[0]) + ", " + format_double(m.origin[1]) +
                             "] with " + std::to_string(static_cast<long long>(cells_w)) + "x" +
                             std::to_string(static_cast<long long>(cells_h)) + " cells of " +
                             format_double(m.resolution) + " m reaches " + format_double(reach) +
                             " m from the world origin; float coordinates resolve 1/16 of a cell only up to " +
                             format_double(fw::kMaxGridReachCells * m.resolution) +
                             " m (2^19 cells) — every point would collapse onto its neighbours");
    }
  }
  if (!(m.occupied_thresh >= 0.0 && m.occupied_thresh <= 1.0)) {
    return fail(error, name + ": field 'occupied_thresh': must be in [0, 1] (got " + format_double(m.occupied_thresh) + ")");
  }
  if (!(m.free_thresh >= 0.0 && m.free_thresh <= 1.0)) {
    return fail(error, name + ": field 'free_thresh': must be in [0, 1] (got " + format_double(m.free_thresh) + ")");
  }
  if (!(m.free_thresh < m.occupied_thresh)) {
    return fail(error, name + ": fields 'free_thresh' (" + format_double(m.free_thresh) +
                           ") must be below 'occupied_thresh' (" + format_double(m.occupied_thresh) + ")");
  }
  if (m.mode != "trinary" && m.mode != "scale" && m.mode != "raw") {
    return fail(error, name + ": field 'mode': '" + m.mode + "' is not trinary, scale or raw");
  }
  if (m.width <= 0 || m.height <= 0 ||
      m.pixels.size() != static_cast<std::size_t>(m.width) * static_cast<std::size_t>(m.height)) {
    return fail(error, name + ": image: pixel buffer does not match " + std::to_string(m.width) + "x" +
                           std::to_string(m.height));
  }
  return true;
}

namespace {

// map_server's YAML through yaml-cpp (Debian's libyaml-cpp-dev): every valid file loads (block-style
// `origin` lists, quoted keys, comments, flow or block style); a syntax error is the library's,
// with its line and column; a field given twice is an error too (the library keeps both).
bool load_yaml_fields(const std::string& yaml_path, const std::string& text, std::map<std::string, YAML::Node>* kv,
                      std::string* error) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    return fail(error, yaml_path + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                           ": YAML: " + e.msg);
  }
  if (!root.IsMap()) return fail(error, yaml_path + ": expected 'key: value' fields (a YAML mapping)");
  for (const auto& it : root) {
    if (!it.first.IsScalar()) {
      return fail(error, yaml_path + ":" + std::to_string(it.first.Mark().line + 1) + ": a key that is not a name");
    }
    const std::string key = it.first.Scalar();
    if (kv->count(key) != 0) {
      return fail(error, yaml_path + ":" + std::to_string(it.first.Mark().line + 1) + ": duplicate field '" + key + "'");
    }
    (*kv)[key] = it.second;
  }
  return true;
}

// A scalar field's text ("" for a list, a map or null: no scalar field accepts those).
std::string scalar_of(const YAML::Node& n) { return n.IsScalar() ? n.Scalar() : std::string(); }

bool parse_origin(const std::string& yaml_path, const YAML::Node& o, double origin[3], std::string* error) {
  if (!o.IsSequence()) {
    return fail(error, yaml_path + ": field 'origin': expected [x, y, yaw], got '" + scalar_of(o) + "'");
  }
  if (o.size() != 3) {
    return fail(error, yaml_path + ": field 'origin': expected 3 numbers [x, y, yaw], got " + std::to_string(o.size()));
  }
  for (std::size_t i = 0; i < 3; ++i) {
    if (!parse_double(scalar_of(o[i]), &origin[i])) {
      return fail(error, yaml_path + ": field 'origin': component " + std::to_string(i) + " not a number: '" +
                             scalar_of(o[i]) + "'");
    }
  }
  return true;
}

}  // namespace

bool read_ros_map(const std::string& yaml_path, RosMap* out, std::string* error) {
  std::string text;
  if (!read_regular_file(yaml_path, kMaxTextConfigBytes, &text, error)) return false;
  std::map<std::string, YAML::Node> node;
  if (!load_yaml_fields(yaml_path, text, &node, error)) return false;
  RosMap m;
  m.yaml_path = yaml_path;
  for (const char* key : {"image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh"}) {
    if (node.count(key) == 0) return fail(error, yaml_path + ": missing field '" + std::string(key) + "'");
  }
  std::map<std::string, std::string> kv;
  for (const auto& [key, n] : node) kv[key] = scalar_of(n);
  m.image = kv["image"];
  if (m.image.empty()) return fail(error, yaml_path + ": field 'image': empty");
  if (!parse_double(kv["resolution"], &m.resolution)) {
    return fail(error, yaml_path + ": field 'resolution': not a number: '" + kv["resolution"] + "'");
  }
  if (!parse_origin(yaml_path, node["origin"], m.origin, error)) return false;
  {
    const std::string n = kv["negate"];
    if (n == "0" || n == "false" || n == "False") {
      m.negate = false;
    } else if (n == "1" || n == "true" || n == "True") {
      m.negate = true;
    } else {
      return fail(error, yaml_path + ": field 'negate': expected 0/1/true/false, got '" + n + "'");
    }
  }
  if (!parse_double(kv["occupied_thresh"], &m.occupied_thresh)) {
    return fail(error, yaml_path + ": field 'occupied_thresh': not a number: '" + kv["occupied_thresh"] + "'");
  }
  if (!parse_double(kv["free_thresh"], &m.free_thresh)) {
    return fail(error, yaml_path + ": field 'free_thresh': not a number: '" + kv["free_thresh"] + "'");
  }
  if (kv.count("mode") != 0) m.mode = kv["mode"];
  // Validate fields before touching the image, so the message is about the YAML.
  m.width = 1;
  m.height = 1;
  m.pixels.assign(1, 0);
  if (!validate_ros_map(m, yaml_path, error)) return false;
  const std::string image_path = resolve_image_path(yaml_path, m.image);
  std::error_code ec;
  if (!std::filesystem::exists(image_path, ec)) {
    return fail(error, yaml_path + ": field 'image': file '" + image_path + "' does not exist");
  }
  std::string why;
  if (!check_regular_file(image_path, kMaxMapFileBytes, nullptr, &why)) {
    return fail(error, yaml_path + ": field 'image': " + why);
  }
  if (!read_pgm(image_path, &m, error)) return false;
  // Again with the image's size: the extent depends on it.
  if (!validate_ros_map(m, yaml_path, error)) return false;
  *out = std::move(m);
  return true;
}

bool write_ros_map(const std::string& yaml_path, const RosMap& map, std::string* error) {
  RosMap m = map;
  if (m.image.empty()) m.image = std::filesystem::path(yaml_path).stem().string() + ".pgm";
  if (!validate_ros_map(m, yaml_path, error)) return false;
  if (!write_pgm(resolve_image_path(yaml_path, m.image), m, error)) return false;
  std::ostringstream o;
  o << "image: " << m.image << "\n"
    << "resolution: " << format_double(m.resolution) << "\n"
    << "origin: [" << format_double(m.origin[0]) << ", " << format_double(m.origin[1]) << ", "
    << format_double(m.origin[2]) << "]\n"
    << "negate: " << (m.negate ? 1 : 0) << "\n"
    << "occupied_thresh: " << format_double(m.occupied_thresh) << "\n"
    << "free_thresh: " << format_double(m.free_thresh) << "\n"
    << "mode: " << m.mode << "\n";
  return write_file_atomic(yaml_path, o.str(), error);
}

bool ros_map_to_grid(const RosMap& m, OccupancyGrid* out, std::string* error) {
  const std::string name = m.yaml_path.empty() ? std::string("map") : m.yaml_path;
  if (!validate_ros_map(m, name, error)) return false;
  if (m.origin[2] != 0.0) {
    return fail(error, name + ": field 'origin': yaw " + format_double(m.origin[2]) +
                           " is not supported (grids are axis-aligned; rotate the image instead)");
  }
  OccupancyGrid g;
  g.geometry.resolution = static_cast<float>(m.resolution);
  g.geometry.origin_x = static_cast<float>(m.origin[0]);
  g.geometry.origin_y = static_cast<float>(m.origin[1]);
  g.geometry.width = static_cast<std::uint32_t>(m.width);
  g.geometry.height = static_cast<std::uint32_t>(m.height);
  g.cells.assign(g.geometry.cell_count(), 255);
  const double maxval = m.maxval;
  for (int row = 0; row < m.height; ++row) {
    const int gy = m.height - 1 - row;  // PGM top row = highest y
    for (int x = 0; x < m.width; ++x) {
      const int raw = m.pixels[static_cast<std::size_t>(row) * m.width + x];
      const int v = m.negate ? m.maxval - raw : raw;
      std::uint8_t cell = 255;
      if (m.mode == "raw") {
        if (v <= 100) {
          cell = static_cast<std::uint8_t>(v);
        } else if (v == 255) {
          cell = 255;
        } else {
          return fail(error, name + ": mode raw: pixel (" + std::to_string(x) + ", " + std::to_string(row) +
                                 ") value " + std::to_string(v) + " is neither 0..100 nor 255");
        }
      } else {
        const double p = (maxval - v) / maxval;  // darker = more likely occupied
        if (p > m.occupied_thresh) {
          cell = 100;
        } else if (p < m.free_thresh) {
          cell = 0;
        } else if (m.mode == "trinary") {
          cell = 255;
        } else {
          const double ratio = (p - m.free_thresh) / (m.occupied_thresh - m.free_thresh);
          cell = static_cast<std::uint8_t>(std::lround(1.0 + 98.0 * ratio));
        }
      }
      g.cells[g.geometry.index(x, gy)] = cell;
    }
  }
  *out = std::move(g);
  return true;
}

// The double whose shortest decimal form is that of the float (0.05f -> 0.05, not 0.0500000007):
// readable YAML, and converting it back to float gives the same float.
static double float_to_clean_double(float f) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof(buf), f);
  double d = 0.0;
  std::from_chars(buf, r.ptr, d);
  return d;
}

RosMap grid_to_ros_map(const OccupancyGrid& grid, const std::string& image_name) {
  RosMap m;
  m.image = image_name;
  m.resolution = float_to_clean_double(grid.geometry.resolution);
  m.origin[0] = float_to_clean_double(grid.geometry.origin_x);
  m.origin[1] = float_to_clean_double(grid.geometry.origin_y);
  m.origin[2] = 0.0;
  m.negate = false;
  m.occupied_thresh = 0.65;
  m.free_thresh = 0.196;
  m.mode = "trinary";
  m.width = static_cast<int>(grid.geometry.width);
  m.height = static_cast<int>(grid.geometry.height);
  m.pixels.assign(grid.geometry.cell_count(), 205);
  for (int gy = 0; gy < m.height; ++gy) {
    const int row = m.height - 1 - gy;
    for (int x = 0; x < m.width; ++x) {
      const std::uint8_t c = grid.cells[grid.geometry.index(x, gy)];
      std::uint8_t px = 205;  // unknown (map_saver convention)
      if (c == 255) {
        px = 205;
      } else if (c >= 65) {
        px = 0;
      } else if (c <= 19) {
        px = 254;
      }
      m.pixels[static_cast<std::size_t>(row) * m.width + x] = px;
    }
  }
  return m;
}

std::vector<fw::Point2f> occupied_points(const OccupancyGrid& grid) {
  std::vector<fw::Point2f> pts;
  for (std::uint32_t y = 0; y < grid.geometry.height; ++y) {
    for (std::uint32_t x = 0; x < grid.geometry.width; ++x) {
      if (grid.cells[grid.geometry.index(static_cast<std::int32_t>(x), static_cast<std::int32_t>(y))] == 100) {
        pts.push_back(grid.geometry.cell_center(static_cast<std::int32_t>(x), static_cast<std::int32_t>(y)));
      }
    }
  }
  return pts;
}

bool ros_map_occupied_points(const RosMap& map, std::vector<fw::Point2f>* out, std::string* error) {
  OccupancyGrid g;
  if (!ros_map_to_grid(map, &g, error)) return false;
  *out = occupied_points(g);
  return true;
}

}  // namespace sim
