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

bool parse_pcd(const std::string& name, const std::string& bytes, const PcdReadOptions& options, PcdCloud* out,
               std::string* error) {
  *out = PcdCloud();
  out->path = name;
  std::vector<Field> fields;
  bool seen[9] = {};
  const char* keys[9] = {"VERSION", "FIELDS", "SIZE", "TYPE", "COUNT", "WIDTH", "HEIGHT", "VIEWPOINT", "POINTS"};
  std::vector<std::uint64_t> sizes, counts;
  std::vector<char> types;
  std::uint64_t width = 0, height = 0, points = 0;
  std::size_t pos = 0, line = 0;
  std::size_t fields_line = 0;
  bool have_data = false;
  std::size_t data_line = 0;
  while (pos < bytes.size() && !have_data) {
    std::size_t eol = bytes.find('\n', pos);
    if (eol == std::string::npos) eol = bytes.size();
    std::string_view l(bytes.data() + pos, eol - pos);
    pos = eol + 1;
    ++line;
    if (l.size() > 4096) {
      *error = at(name, line) + "header line longer than 4096 bytes (not a PCD file?)";
      return false;
    }
    const auto t = split(l);
    if (t.empty() || t[0][0] == '#') continue;
    const std::string key(t[0]);
    if (key == "DATA") {
      if (t.size() != 2 || (t[1] != "ascii" && t[1] != "binary" && t[1] != "binary_compressed")) {
        *error = at(name, line) + "DATA must be one of ascii, binary, binary_compressed";
        return false;
      }
      out->data = std::string(t[1]);
      have_data = true;
      data_line = line;
      break;
    }
    int k = -1;
    for (int i = 0; i < 9; ++i) if (key == keys[i]) k = i;
    if (k < 0) {
      *error = at(name, line) + "unknown header keyword '" + key + "'";
      return false;
    }
    if (seen[k]) {
      *error = at(name, line) + "repeated header keyword " + key;
      return false;
    }
    seen[k] = true;
    const std::size_t nv = t.size() - 1;
    if (key == "VERSION") continue;
    if (key == "FIELDS") {
      if (nv == 0) { *error = at(name, line) + "FIELDS lists no field"; return false; }
      for (std::size_t i = 1; i < t.size(); ++i) {
        Field f;
        f.name = std::string(t[i]);
        fields.push_back(f);
      }
      fields_line = line;
      continue;
    }
    if (key == "SIZE" || key == "COUNT") {
      auto& v = key == "SIZE" ? sizes : counts;
      for (std::size_t i = 1; i < t.size(); ++i) {
        std::uint64_t x;
        if (!to_u64(t[i], &x) || x == 0 || x > 1024) {
          *error = at(name, line) + key + " value '" + std::string(t[i]) + "' is not an integer in [1, 1024]";
          return false;
        }
        v.push_back(x);
      }
      continue;
    }
    if (key == "TYPE") {
      for (std::size_t i = 1; i < t.size(); ++i) {
        if (t[i].size() != 1 || (t[i][0] != 'F' && t[i][0] != 'I' && t[i][0] != 'U')) {
          *error = at(name, line) + "TYPE value '" + std::string(t[i]) + "' is not F, I or U";
          return false;
        }
        types.push_back(t[i][0]);
      }
      continue;
    }
    if (key == "VIEWPOINT") {
      double d;
      for (std::size_t i = 1; i < t.size(); ++i) {
        if (!to_double(t[i], &d) || !std::isfinite(d)) {
          *error = at(name, line) + "VIEWPOINT value '" + std::string(t[i]) + "' is not a finite number";
          return false;
        }
      }
      if (nv != 7) { *error = at(name, line) + "VIEWPOINT needs 7 values (tx ty tz qw qx qy qz)"; return false; }
      continue;
    }
    // WIDTH, HEIGHT, POINTS: one integer each.
    std::uint64_t x;
    if (nv != 1 || !to_u64(t[1], &x)) {
      *error = at(name, line) + key + " needs one non-negative integer";
      return false;
    }
    (key == "WIDTH" ? width : key == "HEIGHT" ? height : points) = x;
  }
  if (!have_data) {
    *error = at(name, line) + "header ends without a DATA line (not a PCD file, or truncated)";
    return false;
  }
  const std::size_t hl = data_line;
  if (fields.empty()) { *error = at(name, hl) + "no FIELDS before DATA"; return false; }
  if (sizes.size() != fields.size() || types.size() != fields.size()) {
    *error = at(name, hl) + "FIELDS lists " + std::to_string(fields.size()) + " fields but SIZE has " +
             std::to_string(sizes.size()) + " and TYPE " + std::to_string(types.size()) + " values";
    return false;
  }
  if (!counts.empty() && counts.size() != fields.size()) {
    *error = at(name, hl) + "FIELDS lists " + std::to_string(fields.size()) + " fields but COUNT has " +
             std::to_string(counts.size()) + " values";
    return false;
  }
  if (!seen[5] || !seen[6]) { *error = at(name, hl) + "WIDTH and HEIGHT are required"; return false; }
  if (width == 0 || height == 0) { *error = at(name, hl) + "WIDTH and HEIGHT must be positive"; return false; }
  if (width > options.max_points || height > options.max_points || width * height > options.max_points) {
    *error = at(name, hl) + "WIDTH x HEIGHT = " + std::to_string(width) + " x " + std::to_string(height) +
             " exceeds the cap of " + std::to_string(options.max_points) + " points";
    return false;
  }
  if (seen[8] && points != width * height) {
    *error = at(name, hl) + "POINTS " + std::to_string(points) + " != WIDTH x HEIGHT " + std::to_string(width * height);
    return false;
  }
  const std::size_t n = static_cast<std::size_t>(width * height);
  int ix = -1, iy = -1, iz = -1;
  std::size_t step = 0, values = 0;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    Field& f = fields[i];
    f.size = static_cast<std::uint32_t>(sizes[i]);
    f.type = types[i];
    f.count = counts.empty() ? 1 : static_cast<std::uint32_t>(counts[i]);
    const bool ok = f.type == 'F' ? (f.size == 4 || f.size == 8)
                                  : (f.size == 1 || f.size == 2 || f.size == 4 || f.size == 8);
    if (!ok) {
      *error = at(name, hl) + "field '" + f.name + "' has TYPE " + f.type + " with SIZE " + std::to_string(f.size) +
               " (F: 4 or 8; I/U: 1, 2, 4 or 8)";
      return false;
    }
    f.offset = step;
    f.value_offset = values;
    step += static_cast<std::size_t>(f.size) * f.count;
    values += f.count;
    int* slot = f.name == "x" ? &ix : f.name == "y" ? &iy : f.name == "z" ? &iz : nullptr;
    if (slot != nullptr) {
      if (*slot >= 0) { *error = at(name, fields_line) + "field '" + f.name + "' listed twice"; return false; }
      *slot = static_cast<int>(i);
    }
  }
  if (ix < 0 || iy < 0 || iz < 0) {
    *error = at(name, fields_line) + "FIELDS must include x, y and z";
    return false;
  }
  for (int i : {ix, iy, iz}) {
    if (fields[i].type != 'F') {
      *error = at(name, hl) + "field '" + fields[i].name + "' must be of TYPE F (float coordinates)";
      return false;
    }
  }
  for (const Field& f : fields) out->fields.push_back(f.name);
  out->width = static_cast<std::uint32_t>(width);
  out->height = static_cast<std::uint32_t>(height);
  out->declared_points = n;
  const Field& fx = fields[ix];
  const Field& fy = fields[iy];
  const Field& fz = fields[iz];
  auto keep = [&](double x, double y, double z, std::size_t i) {
    if (!(std::isfinite(x) && std::isfinite(y) && std::isfinite(z))) {
      ++out->dropped_nonfinite;
      return;
    }
    out->points.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
    out->index.push_back(static_cast<std::uint32_t>(i));
  };

  if (out->data == "ascii") {
    // Every point is one line of `values` numbers; the vectors grow with the lines actually present.
    std::size_t i = 0;
    std::vector<std::string_view> t;
    while (pos < bytes.size()) {
      std::size_t eol = bytes.find('\n', pos);
      if (eol == std::string::npos) eol = bytes.size();
      std::string_view l(bytes.data() + pos, eol - pos);
      pos = eol + 1;
      ++line;
      t = split(l);
      if (t.empty()) continue;
      if (i >= n) {
        *error = at(name, line) + "more data lines than the " + std::to_string(n) + " points declared";
        return false;
      }
      if (t.size() != values) {
        *error = at(name, line) + std::to_string(t.size()) + " values, expected " + std::to_string(values);
        return false;
      }
      double xyz[3] = {0, 0, 0};
      for (std::size_t k = 0; k < t.size(); ++k) {
        double v;
        if (!to_double(t[k], &v)) {
          *error = at(name, line) + "value " + std::to_string(k + 1) + " '" + std::string(t[k]) + "' is not a number";
          return false;
        }
        if (k == fx.value_offset) xyz[0] = v;
        if (k == fy.value_offset) xyz[1] = v;
        if (k == fz.value_offset) xyz[2] = v;
      }
      keep(xyz[0], xyz[1], xyz[2], i);
      ++i;
    }
    if (i != n) {
      *error = at(name, line) + "file ends after " + std::to_string(i) + " of " + std::to_string(n) + " points";
      return false;
    }
    return true;
  }

  const std::size_t need = n * step;
  const std::size_t have = pos <= bytes.size() ? bytes.size() - pos : 0;
  const auto* base = reinterpret_cast<const std::uint8_t*>(bytes.data()) + (pos <= bytes.size() ? pos : bytes.size());
  if (out->data == "binary") {
    if (have != need) {
      *error = at(name, hl) + "binary data of " + std::to_string(have) + " bytes after the header (byte " +
               std::to_string(pos) + "), expected " + std::to_string(n) + " points x " + std::to_string(step) +
               " bytes = " + std::to_string(need);
      return false;
    }
    out->points.reserve(n);
    out->index.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint8_t* p = base + i * step;
      keep(load_value(fx, p + fx.offset), load_value(fy, p + fy.offset), load_value(fz, p + fz.offset), i);
    }
    return true;
  }
  // binary_compressed: uint32 compressed size, uint32 uncompressed size, LZF block; inflated, the
  // fields follow one another (all x, then all y, …: PCL's column layout compresses better).
  if (have < 8) {
    *error = at(name, hl) + "binary_compressed block truncated: " + std::to_string(have) + " bytes after the header";
    return false;
  }
  std::uint32_t csize, usize;
  std::memcpy(&csize, base, 4);
  std::memcpy(&usize, base + 4, 4);
  if (usize != need) {
    *error = at(name, hl) + "binary_compressed block inflates to " + std::to_string(usize) + " bytes, expected " +
             std::to_string(need) + " (" + std::to_string(n) + " points x " + std::to_string(step) + " bytes)";
    return false;
  }
  if (static_cast<std::size_t>(csize) + 8 != have) {
    *error = at(name, hl) + "binary_compressed block " + (csize + std::size_t(8) > have ? "truncated" : "followed by garbage") +
             ": " + std::to_string(csize) + " compressed bytes declared, " + std::to_string(have - 8) + " present";
    return false;
  }
  std::vector<std::uint8_t> raw(need);
  if (need > 0 && !lzf_decompress(base + 8, csize, raw.data(), raw.size())) {
    *error = at(name, hl) + "binary_compressed block is corrupt (LZF stream at byte " + std::to_string(pos + 8) +
             " does not inflate to " + std::to_string(need) + " bytes)";
    return false;
  }
  out->points.reserve(n);
  out->index.reserve(n);
  // Column layout: field f's values start at n · (its byte offset in a point).
  for (std::size_t i = 0; i < n; ++i) {
    auto col = [&](const Field& f) { return load_value(f, raw.data() + n * f.offset + i * f.size * f.count); };
    keep(col(fx), col(fy), col(fz), i);
  }
  return true;
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
