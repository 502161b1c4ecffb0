#include "sim/io/pcd.h"

#include <charconv>
#include <cmath>
#include <cstring>
#include <string_view>

#include "sim/io/carmen_log.h"  // read_file_maybe_gz

namespace sim {

namespace {

std::vector<std::string_view> split(std::string_view s) {
  std::vector<std::string_view> t;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
    const std::size_t b = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t' && s[i] != '\r') ++i;
    if (i > b) t.push_back(s.substr(b, i - b));
  }
  return t;
}

bool to_u64(std::string_view s, std::uint64_t* v) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), *v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

// A number of any PCD type in ASCII data (from_chars accepts "nan" / "inf" as PCL writes them).
bool to_double(std::string_view s, double* v) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), *v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

struct Field {
  std::string name;
  std::uint32_t size = 4;
  char type = 'F';
  std::uint32_t count = 1;
  std::size_t offset = 0;  // byte offset inside one point (binary), value offset (ascii)
  std::size_t value_offset = 0;
};

// Reads the first value of field f at p (binary, little endian as PCL writes on x86 / ARM).
double load_value(const Field& f, const std::uint8_t* p) {
  switch (f.type) {
    case 'F':
      if (f.size == 4) { float v; std::memcpy(&v, p, 4); return v; }
      { double v; std::memcpy(&v, p, 8); return v; }
    case 'I':
      switch (f.size) {
        case 1: { std::int8_t v; std::memcpy(&v, p, 1); return v; }
        case 2: { std::int16_t v; std::memcpy(&v, p, 2); return v; }
        case 4: { std::int32_t v; std::memcpy(&v, p, 4); return v; }
        default: { std::int64_t v; std::memcpy(&v, p, 8); return static_cast<double>(v); }
      }
    default:
      switch (f.size) {
        case 1: return *p;
        case 2: { std::uint16_t v; std::memcpy(&v, p, 2); return v; }
        case 4: { std::uint32_t v; std::memcpy(&v, p, 4); return v; }
        default: { std::uint64_t v; std::memcpy(&v, p, 8); return static_cast<double>(v); }
      }
  }
}

std::string at(const std::string& name, std::size_t line) { return name + ":" + std::to_string(line) + ": "; }

}  // namespace

bool lzf_decompress(const std::uint8_t* in, std::size_t in_size, std::uint8_t* out, std::size_t out_size) {
  std::size_t ip = 0, op = 0;
  while (ip < in_size) {
    const unsigned ctrl = in[ip++];
    if (ctrl < 32) {  // literal run of ctrl + 1 bytes
      const std::size_t len = ctrl + 1;
      if (ip + len > in_size || op + len > out_size) return false;
      std::memcpy(out + op, in + ip, len);
      ip += len;
      op += len;
    } else {  // back reference: length (ctrl >> 5) + 2, distance ((ctrl & 31) << 8 | next) + 1
      std::size_t len = ctrl >> 5;
      if (len == 7) {
        if (ip >= in_size) return false;
        len += in[ip++];
      }
      if (ip >= in_size) return false;
      const std::size_t dist = ((static_cast<std::size_t>(ctrl & 31) << 8) | in[ip++]) + 1;
      len += 2;
      if (dist > op || op + len > out_size) return false;
      for (std::size_t k = 0; k < len; ++k, ++op) out[op] = out[op - dist];  // may overlap: byte by byte
    }
  }
  return op == out_size;
}

namespace {

// The file read line by line: `pos` is the byte after the last line read (one past the end when
// the file does not end in '\n'; the binary readers start at `pos`), `line` its 1-based number.
struct LineCursor {
  std::size_t pos = 0, line = 0;
  // The next line without its '\n'; only while pos < bytes.size().
  std::string_view next(const std::string& bytes) {
    std::size_t eol = bytes.find('\n', pos);
    if (eol == std::string::npos) eol = bytes.size();
    std::string_view l(bytes.data() + pos, eol - pos);
    pos = eol + 1;
    ++line;
    return l;
  }
};

// Header keywords other than DATA, in the order of `seen`.
const char* const kKeys[9] = {"VERSION", "FIELDS", "SIZE", "TYPE", "COUNT", "WIDTH", "HEIGHT", "VIEWPOINT", "POINTS"};
constexpr int kWidthKey = 5, kHeightKey = 6, kPointsKey = 8;

// The header as declared, before its lines are checked against one another.
struct PcdHeader {
  std::vector<Field> fields;
  bool seen[9] = {};
  std::vector<std::uint64_t> sizes, counts;
  std::vector<char> types;
  std::uint64_t width = 0, height = 0, points = 0;
  std::size_t fields_line = 0;  // a field listed twice or a missing x/y/z is reported here
  std::size_t data_line = 0;    // every other whole-header problem is reported here
};

using Tokens = std::vector<std::string_view>;

bool fail_at(const std::string& name, std::size_t line, const std::string& problem, std::string* error) {
  *error = at(name, line) + problem;
  return false;
}

bool parse_field_names(const std::string& name, std::size_t line, const Tokens& t, PcdHeader* h, std::string* error) {
  if (t.size() == 1) return fail_at(name, line, "FIELDS lists no field", error);
  for (std::size_t i = 1; i < t.size(); ++i) {
    Field f;
    f.name = std::string(t[i]);
    h->fields.push_back(f);
  }
  h->fields_line = line;
  return true;
}

// SIZE or COUNT: one integer in [1, 1024] per field.
bool parse_field_integers(const std::string& name, std::size_t line, const std::string& key, const Tokens& t,
                          std::vector<std::uint64_t>* v, std::string* error) {
  for (std::size_t i = 1; i < t.size(); ++i) {
    std::uint64_t x;
    if (!to_u64(t[i], &x) || x == 0 || x > 1024)
      return fail_at(name, line, key + " value '" + std::string(t[i]) + "' is not an integer in [1, 1024]", error);
    v->push_back(x);
  }
  return true;
}

bool parse_field_types(const std::string& name, std::size_t line, const Tokens& t, PcdHeader* h, std::string* error) {
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (t[i].size() != 1 || (t[i][0] != 'F' && t[i][0] != 'I' && t[i][0] != 'U'))
      return fail_at(name, line, "TYPE value '" + std::string(t[i]) + "' is not F, I or U", error);
    h->types.push_back(t[i][0]);
  }
  return true;
}

// VIEWPOINT is checked but not kept: the points are returned as stored, the viewpoint is not applied.
bool check_viewpoint(const std::string& name, std::size_t line, const Tokens& t, std::string* error) {
  double d;
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (!to_double(t[i], &d) || !std::isfinite(d))
      return fail_at(name, line, "VIEWPOINT value '" + std::string(t[i]) + "' is not a finite number", error);
  }
  if (t.size() - 1 != 7) return fail_at(name, line, "VIEWPOINT needs 7 values (tx ty tz qw qx qy qz)", error);
  return true;
}

// The values of one header line whose keyword is known and not repeated.
bool parse_header_values(const std::string& name, std::size_t line, const std::string& key, const Tokens& t,
                         PcdHeader* h, std::string* error) {
  if (key == "VERSION") return true;
  if (key == "FIELDS") return parse_field_names(name, line, t, h, error);
  if (key == "SIZE" || key == "COUNT")
    return parse_field_integers(name, line, key, t, key == "SIZE" ? &h->sizes : &h->counts, error);
  if (key == "TYPE") return parse_field_types(name, line, t, h, error);
  if (key == "VIEWPOINT") return check_viewpoint(name, line, t, error);
  // WIDTH, HEIGHT, POINTS: one integer each.
  std::uint64_t x;
  if (t.size() - 1 != 1 || !to_u64(t[1], &x))
    return fail_at(name, line, key + " needs one non-negative integer", error);
  (key == "WIDTH" ? h->width : key == "HEIGHT" ? h->height : h->points) = x;
  return true;
}

// Header lines up to and including DATA (its kind goes to out->data); the cursor is left on the
// first byte of the data.
bool read_header(const std::string& name, const std::string& bytes, LineCursor* c, PcdHeader* h, PcdCloud* out,
                 std::string* error) {
  while (c->pos < bytes.size()) {
    const std::string_view l = c->next(bytes);
    const std::size_t line = c->line;
    if (l.size() > 4096) return fail_at(name, line, "header line longer than 4096 bytes (not a PCD file?)", error);
    const auto t = split(l);
    if (t.empty() || t[0][0] == '#') continue;
    const std::string key(t[0]);
    if (key == "DATA") {
      if (t.size() != 2 || (t[1] != "ascii" && t[1] != "binary" && t[1] != "binary_compressed"))
        return fail_at(name, line, "DATA must be one of ascii, binary, binary_compressed", error);
      out->data = std::string(t[1]);
      h->data_line = line;
      return true;
    }
    int k = -1;
    for (int i = 0; i < 9; ++i) if (key == kKeys[i]) k = i;
    if (k < 0) return fail_at(name, line, "unknown header keyword '" + key + "'", error);
    if (h->seen[k]) return fail_at(name, line, "repeated header keyword " + key, error);
    h->seen[k] = true;
    if (!parse_header_values(name, line, key, t, h, error)) return false;
  }
  return fail_at(name, c->line, "header ends without a DATA line (not a PCD file, or truncated)", error);
}

// The header's lines agree with one another and the point count is within the cap.
bool check_header(const std::string& name, const PcdHeader& h, const PcdReadOptions& options, std::string* error) {
  const std::size_t hl = h.data_line;
  if (h.fields.empty()) return fail_at(name, hl, "no FIELDS before DATA", error);
  if (h.sizes.size() != h.fields.size() || h.types.size() != h.fields.size()) {
    return fail_at(name, hl,
                   "FIELDS lists " + std::to_string(h.fields.size()) + " fields but SIZE has " +
                       std::to_string(h.sizes.size()) + " and TYPE " + std::to_string(h.types.size()) + " values",
                   error);
  }
  if (!h.counts.empty() && h.counts.size() != h.fields.size()) {
    return fail_at(name, hl,
                   "FIELDS lists " + std::to_string(h.fields.size()) + " fields but COUNT has " +
                       std::to_string(h.counts.size()) + " values",
                   error);
  }
  if (!h.seen[kWidthKey] || !h.seen[kHeightKey]) return fail_at(name, hl, "WIDTH and HEIGHT are required", error);
  if (h.width == 0 || h.height == 0) return fail_at(name, hl, "WIDTH and HEIGHT must be positive", error);
  if (h.width > options.max_points || h.height > options.max_points || h.width * h.height > options.max_points) {
    return fail_at(name, hl,
                   "WIDTH x HEIGHT = " + std::to_string(h.width) + " x " + std::to_string(h.height) +
                       " exceeds the cap of " + std::to_string(options.max_points) + " points",
                   error);
  }
  if (h.seen[kPointsKey] && h.points != h.width * h.height) {
    return fail_at(name, hl,
                   "POINTS " + std::to_string(h.points) + " != WIDTH x HEIGHT " + std::to_string(h.width * h.height),
                   error);
  }
  return true;
}

// Where x, y and z are, and how big one point is.
struct PointLayout {
  int ix = -1, iy = -1, iz = -1;
  std::size_t step = 0;    // bytes per point (binary)
  std::size_t values = 0;  // numbers per point (ascii)
};

// Gives every field its size, type, count and offsets (sizes must fit their type) and finds x, y
// and z (each once, of TYPE F).
bool lay_out_fields(const std::string& name, PcdHeader* h, PointLayout* lay, std::string* error) {
  const std::size_t hl = h->data_line;
  for (std::size_t i = 0; i < h->fields.size(); ++i) {
    Field& f = h->fields[i];
    f.size = static_cast<std::uint32_t>(h->sizes[i]);
    f.type = h->types[i];
    f.count = h->counts.empty() ? 1 : static_cast<std::uint32_t>(h->counts[i]);
    const bool ok = f.type == 'F' ? (f.size == 4 || f.size == 8)
                                  : (f.size == 1 || f.size == 2 || f.size == 4 || f.size == 8);
    if (!ok) {
      return fail_at(name, hl,
                     "field '" + f.name + "' has TYPE " + f.type + " with SIZE " + std::to_string(f.size) +
                         " (F: 4 or 8; I/U: 1, 2, 4 or 8)",
                     error);
    }
    f.offset = lay->step;
    f.value_offset = lay->values;
    lay->step += static_cast<std::size_t>(f.size) * f.count;
    lay->values += f.count;
    int* slot = f.name == "x" ? &lay->ix : f.name == "y" ? &lay->iy : f.name == "z" ? &lay->iz : nullptr;
    if (slot != nullptr) {
      if (*slot >= 0) return fail_at(name, h->fields_line, "field '" + f.name + "' listed twice", error);
      *slot = static_cast<int>(i);
    }
  }
  if (lay->ix < 0 || lay->iy < 0 || lay->iz < 0)
    return fail_at(name, h->fields_line, "FIELDS must include x, y and z", error);
  for (int i : {lay->ix, lay->iy, lay->iz}) {
    if (h->fields[i].type != 'F')
      return fail_at(name, hl, "field '" + h->fields[i].name + "' must be of TYPE F (float coordinates)", error);
  }
  return true;
}

// What the data readers need of the checked header.
struct PointShape {
  const Field& fx;
  const Field& fy;
  const Field& fz;
  std::size_t n;            // points declared (WIDTH · HEIGHT)
  std::size_t step;         // bytes per point
  std::size_t values;       // numbers per ascii line
  std::size_t header_line;  // the DATA line, named by the binary problems
};

// Point i of the file: kept when x, y and z are all finite, counted as dropped otherwise.
void keep_point(double x, double y, double z, std::size_t i, PcdCloud* out) {
  if (!(std::isfinite(x) && std::isfinite(y) && std::isfinite(z))) {
    ++out->dropped_nonfinite;
    return;
  }
  out->points.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
  out->index.push_back(static_cast<std::uint32_t>(i));
}

// DATA ascii: every point is one line of `values` numbers; the vectors grow with the lines actually
// present (nothing is reserved for a count the file may not hold).
bool read_ascii(const std::string& name, const std::string& bytes, LineCursor c, const PointShape& s, PcdCloud* out,
                std::string* error) {
  std::size_t i = 0;
  std::vector<std::string_view> t;
  while (c.pos < bytes.size()) {
    t = split(c.next(bytes));
    if (t.empty()) continue;
    if (i >= s.n)
      return fail_at(name, c.line, "more data lines than the " + std::to_string(s.n) + " points declared", error);
    if (t.size() != s.values)
      return fail_at(name, c.line, std::to_string(t.size()) + " values, expected " + std::to_string(s.values), error);
    double xyz[3] = {0, 0, 0};
    for (std::size_t k = 0; k < t.size(); ++k) {
      double v;
      if (!to_double(t[k], &v)) {
        return fail_at(name, c.line,
                       "value " + std::to_string(k + 1) + " '" + std::string(t[k]) + "' is not a number", error);
      }
      if (k == s.fx.value_offset) xyz[0] = v;
      if (k == s.fy.value_offset) xyz[1] = v;
      if (k == s.fz.value_offset) xyz[2] = v;
    }
    keep_point(xyz[0], xyz[1], xyz[2], i, out);
    ++i;
  }
  if (i != s.n)
    return fail_at(name, c.line, "file ends after " + std::to_string(i) + " of " + std::to_string(s.n) + " points",
                   error);
  return true;
}

// The bytes after the header: `have` of them from `base`; `pos` is the header's end (may be one
// past the end of the file).
struct DataBlock {
  const std::uint8_t* base;
  std::size_t have;
  std::size_t pos;
};

// DATA binary: exactly n points of `step` bytes, fields interleaved.
bool read_binary(const std::string& name, const DataBlock& d, const PointShape& s, PcdCloud* out, std::string* error) {
  const std::size_t need = s.n * s.step;
  if (d.have != need) {
    return fail_at(name, s.header_line,
                   "binary data of " + std::to_string(d.have) + " bytes after the header (byte " +
                       std::to_string(d.pos) + "), expected " + std::to_string(s.n) + " points x " +
                       std::to_string(s.step) + " bytes = " + std::to_string(need),
                   error);
  }
  out->points.reserve(s.n);
  out->index.reserve(s.n);
  for (std::size_t i = 0; i < s.n; ++i) {
    const std::uint8_t* p = d.base + i * s.step;
    keep_point(load_value(s.fx, p + s.fx.offset), load_value(s.fy, p + s.fy.offset),
               load_value(s.fz, p + s.fz.offset), i, out);
  }
  return true;
}

// The binary_compressed block's two sizes agree with the header and with the bytes present.
bool check_compressed_block(const std::string& name, const DataBlock& d, const PointShape& s, std::uint32_t csize,
                            std::uint32_t usize, std::string* error) {
  const std::size_t need = s.n * s.step;
  if (usize != need) {
    return fail_at(name, s.header_line,
                   "binary_compressed block inflates to " + std::to_string(usize) + " bytes, expected " +
                       std::to_string(need) + " (" + std::to_string(s.n) + " points x " + std::to_string(s.step) +
                       " bytes)",
                   error);
  }
  if (static_cast<std::size_t>(csize) + 8 != d.have) {
    return fail_at(name, s.header_line,
                   std::string("binary_compressed block ") +
                       (csize + std::size_t(8) > d.have ? "truncated" : "followed by garbage") + ": " +
                       std::to_string(csize) + " compressed bytes declared, " + std::to_string(d.have - 8) +
                       " present",
                   error);
  }
  return true;
}

// DATA binary_compressed: uint32 compressed size, uint32 uncompressed size, LZF block; inflated, the
// fields follow one another (all x, then all y, …: PCL's column layout compresses better).
bool read_binary_compressed(const std::string& name, const DataBlock& d, const PointShape& s, PcdCloud* out,
                            std::string* error) {
  if (d.have < 8) {
    return fail_at(name, s.header_line,
                   "binary_compressed block truncated: " + std::to_string(d.have) + " bytes after the header", error);
  }
  std::uint32_t csize, usize;
  std::memcpy(&csize, d.base, 4);
  std::memcpy(&usize, d.base + 4, 4);
  if (!check_compressed_block(name, d, s, csize, usize, error)) return false;
  const std::size_t n = s.n, need = n * s.step;
  std::vector<std::uint8_t> raw(need);
  if (need > 0 && !lzf_decompress(d.base + 8, csize, raw.data(), raw.size())) {
    return fail_at(name, s.header_line,
                   "binary_compressed block is corrupt (LZF stream at byte " + std::to_string(d.pos + 8) +
                       " does not inflate to " + std::to_string(need) + " bytes)",
                   error);
  }
  out->points.reserve(n);
  out->index.reserve(n);
  // Column layout: field f's values start at n · (its byte offset in a point).
  for (std::size_t i = 0; i < n; ++i) {
    auto col = [&](const Field& f) { return load_value(f, raw.data() + n * f.offset + i * f.size * f.count); };
    keep_point(col(s.fx), col(s.fy), col(s.fz), i, out);
  }
  return true;
}

}  // namespace

bool parse_pcd(const std::string& name, const std::string& bytes, const PcdReadOptions& options, PcdCloud* out,
               std::string* error) {
  *out = PcdCloud();
  out->path = name;
  PcdHeader h;
  LineCursor c;
  PointLayout lay;
  if (!read_header(name, bytes, &c, &h, out, error) || !check_header(name, h, options, error) ||
      !lay_out_fields(name, &h, &lay, error))
    return false;
  const std::size_t n = static_cast<std::size_t>(h.width * h.height);
  for (const Field& f : h.fields) out->fields.push_back(f.name);
  out->width = static_cast<std::uint32_t>(h.width);
  out->height = static_cast<std::uint32_t>(h.height);
  out->declared_points = n;
  const PointShape s{h.fields[lay.ix], h.fields[lay.iy], h.fields[lay.iz], n, lay.step, lay.values, h.data_line};
  if (out->data == "ascii") return read_ascii(name, bytes, c, s, out, error);
  const std::size_t pos = c.pos;
  DataBlock d;
  d.have = pos <= bytes.size() ? bytes.size() - pos : 0;
  d.base = reinterpret_cast<const std::uint8_t*>(bytes.data()) + (pos <= bytes.size() ? pos : bytes.size());
  d.pos = pos;
  if (out->data == "binary") return read_binary(name, d, s, out, error);
  return read_binary_compressed(name, d, s, out, error);
}

bool read_pcd(const std::string& path, const PcdReadOptions& options, PcdCloud* out, std::string* error) {
  std::string bytes;
  if (!read_file_maybe_gz(path, options.max_bytes, &bytes, error)) {
    *out = PcdCloud();
    out->path = path;
    return false;
  }
  return parse_pcd(path, bytes, options, out, error);
}

bool read_pcd(const std::string& path, PcdCloud* out, std::string* error) {
  return read_pcd(path, PcdReadOptions(), out, error);
}

}  // namespace sim
