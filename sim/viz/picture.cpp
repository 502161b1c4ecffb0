#include "sim/viz/picture.h"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "firmware/map/global_map.h"
#include "sim/viz/font5x7.h"

namespace sim {

namespace {

constexpr Rgb kFree{255, 255, 255}, kOccupied{30, 30, 30}, kUnknown{212, 214, 222}, kBackground{245, 245, 245};
constexpr int kLineHeight = 18;   // px per text line (PNG font at scale 2: 14 px glyphs)
constexpr int kMargin = 12;

Rgb cell_colour(std::uint8_t c) {
  if (c == fw::kCellOccupied) return kOccupied;
  if (c == fw::kCellFree) return kFree;
  if (c == fw::kCellUnknown) return kUnknown;
  const auto v = static_cast<std::uint8_t>(255 - c * 255 / 100);  // scaled occupancy
  return {v, v, v};
}

// Where things go: header (title, notes), the map area, legend below.
struct Layout {
  double x0 = 0, y0 = 0, x1 = 1, y1 = 1, ppm = 1;
  int header = 0, map_w = 0, map_h = 0, legend = 0, width = 0, height = 0;
  double px(double x) const { return kMargin + (x - x0) * ppm; }
  double py(double y) const { return header + (y1 - y) * ppm; }
};

int legend_entries(const Picture& pic) {
  int n = 0;
  for (const auto& l : pic.lines) n += !l.label.empty();
  for (const auto& p : pic.point_sets) n += !p.label.empty();
  for (const auto& c : pic.circle_sets) n += !c.label.empty();
  for (const auto& b : pic.boxes) n += !b.label.empty();
  return n;
}

bool make_layout(const Picture& pic, Layout* L, std::string* err) {
  double x0 = pic.x_min, y0 = pic.y_min, x1 = pic.x_max, y1 = pic.y_max;
  if (x0 == 0 && y0 == 0 && x1 == 0 && y1 == 0) {
    if (pic.map != nullptr && pic.map->geometry.width > 0) {
      const auto& g = pic.map->geometry;
      x0 = g.origin_x;
      y0 = g.origin_y;
      x1 = g.origin_x + g.size_x();
      y1 = g.origin_y + g.size_y();
    } else {
      bool any = false;
      auto grow = [&](double x, double y) {
        if (!std::isfinite(x) || !std::isfinite(y)) return;
        if (!any) { x0 = x1 = x; y0 = y1 = y; any = true; }
        x0 = std::min(x0, x); x1 = std::max(x1, x); y0 = std::min(y0, y); y1 = std::max(y1, y);
      };
      for (const auto& l : pic.lines) for (const auto& p : l.points) grow(p.x, p.y);
      for (const auto& s : pic.point_sets) for (const auto& p : s.points) grow(p.x, p.y);
      for (const auto& m : pic.markers) grow(m.x, m.y);
      if (!any) {
        if (err) *err = "picture: nothing to draw (no map, no points: empty extent)";
        return false;
      }
      x0 -= 1; y0 -= 1; x1 += 1; y1 += 1;
    }
  }
  if (!(x1 > x0 && y1 > y0) || !std::isfinite(x1 - x0) || !std::isfinite(y1 - y0) || (x1 - x0) > 1e5 || (y1 - y0) > 1e5) {
    if (err) *err = "picture: empty or invalid extent";
    return false;
  }
  L->x0 = x0; L->y0 = y0; L->x1 = x1; L->y1 = y1;
  L->ppm = pic.pixels_per_metre > 0 ? pic.pixels_per_metre : 1600.0 / std::max(x1 - x0, y1 - y0);
  L->map_w = static_cast<int>(std::ceil((x1 - x0) * L->ppm));
  L->map_h = static_cast<int>(std::ceil((y1 - y0) * L->ppm));
  L->header = kMargin + kLineHeight * (1 + static_cast<int>(pic.notes.size())) + 6;
  L->legend = kMargin + kLineHeight * ((legend_entries(pic) + 2) / 3);
  L->width = std::max(L->map_w + 2 * kMargin, 640);
  L->height = L->header + L->map_h + L->legend + kMargin;
  return true;
}

std::string hex(const Rgb& c) {
  char b[8];
  std::snprintf(b, sizeof(b), "#%02x%02x%02x", c.r, c.g, c.b);
  return b;
}

std::string xml_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

// Map at native resolution, row 0 = top.
std::vector<std::uint8_t> map_rgb(const OccupancyGrid& m) {
  const auto& g = m.geometry;
  std::vector<std::uint8_t> rgb(g.cell_count() * 3);
  for (std::uint32_t r = 0; r < g.height; ++r) {
    const std::uint32_t cy = g.height - 1 - r;
    for (std::uint32_t cx = 0; cx < g.width; ++cx) {
      const Rgb c = cell_colour(m.cells[g.index(static_cast<std::int32_t>(cx), static_cast<std::int32_t>(cy))]);
      std::uint8_t* p = &rgb[(static_cast<size_t>(r) * g.width + cx) * 3];
      p[0] = c.r; p[1] = c.g; p[2] = c.b;
    }
  }
  return rgb;
}

void png_write_to_vector(png_structp png, png_bytep data, png_size_t len) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + len);
}
void png_flush_noop(png_structp) {}

// Raster canvas for the PNG renderer.
struct Canvas {
  int w, h;
  std::vector<std::uint8_t> rgb;
  int clip_x0 = 0, clip_y0 = 0, clip_x1 = 0, clip_y1 = 0;  // drawing limited to [x0, x1) × [y0, y1)
  Canvas(int w_, int h_, Rgb bg) : w(w_), h(h_), rgb(static_cast<size_t>(w_) * h_ * 3) {
    for (size_t i = 0; i < rgb.size(); i += 3) { rgb[i] = bg.r; rgb[i + 1] = bg.g; rgb[i + 2] = bg.b; }
    no_clip();
  }
  void no_clip() { clip_x0 = 0; clip_y0 = 0; clip_x1 = w; clip_y1 = h; }
  void set(int x, int y, Rgb c, double alpha = 1.0) {
    if (x < clip_x0 || y < clip_y0 || x >= clip_x1 || y >= clip_y1) return;
    std::uint8_t* p = &rgb[(static_cast<size_t>(y) * w + x) * 3];
    if (alpha >= 1.0) { p[0] = c.r; p[1] = c.g; p[2] = c.b; return; }
    p[0] = static_cast<std::uint8_t>(p[0] * (1 - alpha) + c.r * alpha);
    p[1] = static_cast<std::uint8_t>(p[1] * (1 - alpha) + c.g * alpha);
    p[2] = static_cast<std::uint8_t>(p[2] * (1 - alpha) + c.b * alpha);
  }
  void disc(double cx, double cy, double r, Rgb c) {
    const int x0 = static_cast<int>(std::floor(cx - r)), x1 = static_cast<int>(std::ceil(cx + r));
    const int y0 = static_cast<int>(std::floor(cy - r)), y1 = static_cast<int>(std::ceil(cy + r));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
        if (d <= r) set(x, y, c);
        else if (d <= r + 1) set(x, y, c, r + 1 - d);  // soft edge
      }
    }
  }
  void line(double xa, double ya, double xb, double yb, double width, Rgb c) {
    const double len = std::hypot(xb - xa, yb - ya);
    const int n = std::max(1, static_cast<int>(std::ceil(len / 0.5)));
    for (int i = 0; i <= n; ++i) {
      const double s = static_cast<double>(i) / n;
      disc(xa + s * (xb - xa), ya + s * (yb - ya), width / 2, c);
    }
  }
  // Circle outline (polygon fine enough for its size).
  void ring(double cx, double cy, double r, double width, Rgb c) {
    const int n = std::clamp(static_cast<int>(std::ceil(2 * M_PI * r / 3.0)), 12, 360);
    for (int k = 0; k < n; ++k) {
      const double a0 = 2 * M_PI * k / n, a1 = 2 * M_PI * (k + 1) / n;
      line(cx + r * std::cos(a0), cy + r * std::sin(a0), cx + r * std::cos(a1), cy + r * std::sin(a1), width, c);
    }
  }
  void cross(double cx, double cy, double r, double width, Rgb c) {
    line(cx - r, cy - r, cx + r, cy + r, width, c);
    line(cx - r, cy + r, cx + r, cy - r, width, c);
  }
  void rect_outline(double xa, double ya, double xb, double yb, Rgb c) {
    line(xa, ya, xb, ya, 2, c); line(xb, ya, xb, yb, 2, c); line(xb, yb, xa, yb, 2, c); line(xa, yb, xa, ya, 2, c);
  }
  void fill_rect(int xa, int ya, int xb, int yb, Rgb c, double alpha) {
    for (int y = std::max(0, ya); y < std::min(h, yb); ++y)
      for (int x = std::max(0, xa); x < std::min(w, xb); ++x) set(x, y, c, alpha);
  }
  // Text with the 5×7 font at integer scale; returns the advance in px.
  int text(int x, int y, const std::string& s, Rgb c, int scale = 2) {
    int cx = x;
    for (char ch : s) {
      const std::uint8_t* g = font5x7_glyph(ch);
      for (int col = 0; col < 5; ++col) {
        for (int row = 0; row < 7; ++row) {
          if (g[col] & (1u << row)) fill_rect(cx + col * scale, y + row * scale, cx + (col + 1) * scale, y + (row + 1) * scale, c, 1.0);
        }
      }
      cx += 6 * scale;
    }
    return cx - x;
  }
};

struct LegendItem {
  std::string label;
  Rgb color;
  int kind;  // 0 line, 1 points, 2 box, 3 circle outline, 4 cross
};

std::vector<LegendItem> legend_items(const Picture& pic) {
  std::vector<LegendItem> items;
  for (const auto& l : pic.lines) if (!l.label.empty()) items.push_back({l.label, l.color, 0});
  for (const auto& c : pic.circle_sets) if (!c.label.empty()) items.push_back({c.label, c.color, 3});
  for (const auto& p : pic.point_sets) {
    if (!p.label.empty()) items.push_back({p.label, p.color, p.shape == PointShape::kCross ? 4 : 1});
  }
  for (const auto& b : pic.boxes) if (!b.label.empty()) items.push_back({b.label, b.color, 2});
  return items;
}

}  // namespace

std::string base64(const std::vector<std::uint8_t>& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const std::uint32_t v = (bytes[i] << 16) | (bytes[i + 1] << 8) | bytes[i + 2];
    out += kAlphabet[v >> 18]; out += kAlphabet[(v >> 12) & 63]; out += kAlphabet[(v >> 6) & 63]; out += kAlphabet[v & 63];
  }
  if (i + 1 == bytes.size()) {
    const std::uint32_t v = bytes[i] << 16;
    out += kAlphabet[v >> 18]; out += kAlphabet[(v >> 12) & 63]; out += "==";
  } else if (i + 2 == bytes.size()) {
    const std::uint32_t v = (bytes[i] << 16) | (bytes[i + 1] << 8);
    out += kAlphabet[v >> 18]; out += kAlphabet[(v >> 12) & 63]; out += kAlphabet[(v >> 6) & 63]; out += '=';
  }
  return out;
}

bool encode_png_rgb(int width, int height, const std::vector<std::uint8_t>& rgb, std::vector<std::uint8_t>* out,
                    std::string* err) {
  if (width <= 0 || height <= 0 || rgb.size() != static_cast<size_t>(width) * height * 3) {
    if (err) *err = "png: image size does not match the pixel buffer";
    return false;
  }
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    if (png) png_destroy_write_struct(&png, nullptr);
    if (err) *err = "png: cannot create libpng structures";
    return false;
  }
  out->clear();
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    if (err) *err = "png: libpng error while encoding";
    return false;
  }
  png_set_write_fn(png, out, png_write_to_vector, png_flush_noop);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y) {
    png_write_row(png, const_cast<png_bytep>(&rgb[static_cast<size_t>(y) * width * 3]));
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

bool write_svg(const Picture& pic, const std::string& path, std::string* err) {
  Layout L;
  if (!make_layout(pic, &L, err)) return false;
  std::ostringstream s;
  s.precision(6);
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" xmlns:xlink=\"http://www.w3.org/1999/xlink\" width=\"" << L.width << "\" height=\"" << L.height
    << "\" viewBox=\"0 0 " << L.width << ' ' << L.height << "\" font-family=\"sans-serif\">\n";
  s << "<rect width=\"100%\" height=\"100%\" fill=\"" << hex(kBackground) << "\"/>\n";
  s << "<text x=\"" << kMargin << "\" y=\"" << kMargin + 14 << "\" font-size=\"16\" font-weight=\"bold\">"
    << xml_escape(pic.title) << "</text>\n";
  for (size_t i = 0; i < pic.notes.size(); ++i) {
    s << "<text x=\"" << kMargin << "\" y=\"" << kMargin + 14 + kLineHeight * (i + 1) << "\" font-size=\"13\">"
      << xml_escape(pic.notes[i]) << "</text>\n";
  }
  if (pic.map != nullptr && pic.map->geometry.width > 0) {
    const auto& g = pic.map->geometry;
    std::vector<std::uint8_t> png;
    if (!encode_png_rgb(static_cast<int>(g.width), static_cast<int>(g.height), map_rgb(*pic.map), &png, err)) return false;
    const double mx = L.px(g.origin_x), my = L.py(g.origin_y + g.size_y());
    s << "<image x=\"" << mx << "\" y=\"" << my << "\" width=\"" << g.size_x() * L.ppm << "\" height=\""
      << g.size_y() * L.ppm << "\" preserveAspectRatio=\"none\" style=\"image-rendering:pixelated\" "
      << "xlink:href=\"data:image/png;base64," << base64(png) << "\"/>\n";
  }
  s << "<clipPath id=\"maparea\"><rect x=\"" << kMargin << "\" y=\"" << L.header << "\" width=\"" << L.map_w
    << "\" height=\"" << L.map_h << "\"/></clipPath>\n<g clip-path=\"url(#maparea)\">\n";
  for (const auto& b : pic.boxes) {
    s << "<rect x=\"" << L.px(b.x0) << "\" y=\"" << L.py(b.y1) << "\" width=\"" << (b.x1 - b.x0) * L.ppm
      << "\" height=\"" << (b.y1 - b.y0) * L.ppm << "\" fill=\"" << hex(b.color) << "\" fill-opacity=\"0.18\" stroke=\""
      << hex(b.color) << "\" stroke-width=\"2\" stroke-dasharray=\"6 4\"/>\n";
  }
  for (const auto& l : pic.lines) {
    s << "<polyline fill=\"none\" stroke=\"" << hex(l.color) << "\" stroke-width=\"" << l.width_px
      << "\" stroke-linejoin=\"round\" stroke-opacity=\"0.85\" points=\"";
    for (const auto& p : l.points) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
      s << L.px(p.x) << ',' << L.py(p.y) << ' ';
    }
    s << "\"/>\n";
  }
  for (const auto& cs : pic.circle_sets) {
    s << "<g fill=\"none\" stroke=\"" << hex(cs.color) << "\" stroke-width=\"" << cs.width_px
      << "\" stroke-opacity=\"0.8\">\n";
    for (const auto& c : cs.circles) {
      if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.radius_m) || c.radius_m <= 0) continue;
      s << "<circle cx=\"" << L.px(c.x) << "\" cy=\"" << L.py(c.y) << "\" r=\"" << c.radius_m * L.ppm << "\"/>\n";
    }
    s << "</g>\n";
  }
  for (const auto& ps : pic.point_sets) {
    if (ps.shape == PointShape::kCross) {
      s << "<g stroke=\"" << hex(ps.color) << "\" stroke-width=\"2.5\" fill=\"none\">\n";
      for (const auto& p : ps.points) {
        if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
        const double cx = L.px(p.x), cy = L.py(p.y), r = ps.radius_px;
        s << "<path d=\"M" << cx - r << ' ' << cy - r << 'L' << cx + r << ' ' << cy + r << 'M' << cx - r << ' '
          << cy + r << 'L' << cx + r << ' ' << cy - r << "\"/>\n";
      }
      s << "</g>\n";
      continue;
    }
    s << "<g fill=\"" << hex(ps.color) << "\" fill-opacity=\"0.8\">\n";
    for (const auto& p : ps.points) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
      s << "<circle cx=\"" << L.px(p.x) << "\" cy=\"" << L.py(p.y) << "\" r=\"" << ps.radius_px << "\"/>\n";
    }
    s << "</g>\n";
  }
  for (const auto& m : pic.markers) {
    const double cx = L.px(m.x), cy = L.py(m.y);
    s << "<circle cx=\"" << cx << "\" cy=\"" << cy << "\" r=\"" << m.radius_px << "\" fill=\"none\" stroke=\""
      << hex(m.color) << "\" stroke-width=\"2.5\"/>\n";
    s << "<line x1=\"" << cx << "\" y1=\"" << cy << "\" x2=\"" << cx + 2 * m.radius_px * std::cos(m.theta)
      << "\" y2=\"" << cy - 2 * m.radius_px * std::sin(m.theta) << "\" stroke=\"" << hex(m.color)
      << "\" stroke-width=\"2.5\"/>\n";
    if (!m.text.empty()) {
      s << "<text x=\"" << cx + m.radius_px + 4 << "\" y=\"" << cy - m.radius_px - 2 << "\" font-size=\"13\" fill=\""
        << hex(m.color) << "\" stroke=\"white\" stroke-width=\"3\" paint-order=\"stroke\">" << xml_escape(m.text)
        << "</text>\n";
    }
  }
  s << "</g>\n";
  const auto items = legend_items(pic);
  const int col_w = (L.width - 2 * kMargin) / 3;
  for (size_t i = 0; i < items.size(); ++i) {
    const int x = kMargin + static_cast<int>(i % 3) * col_w;
    const int y = L.header + L.map_h + kMargin + static_cast<int>(i / 3) * kLineHeight;
    if (items[i].kind == 0) {
      s << "<line x1=\"" << x << "\" y1=\"" << y + 6 << "\" x2=\"" << x + 24 << "\" y2=\"" << y + 6 << "\" stroke=\""
        << hex(items[i].color) << "\" stroke-width=\"3\"/>\n";
    } else if (items[i].kind == 1) {
      s << "<circle cx=\"" << x + 12 << "\" cy=\"" << y + 6 << "\" r=\"4\" fill=\"" << hex(items[i].color) << "\"/>\n";
    } else if (items[i].kind == 3) {
      s << "<circle cx=\"" << x + 12 << "\" cy=\"" << y + 6 << "\" r=\"6\" fill=\"none\" stroke=\"" << hex(items[i].color)
        << "\" stroke-width=\"1.5\"/>\n";
    } else if (items[i].kind == 4) {
      s << "<path d=\"M" << x + 7 << ' ' << y + 1 << 'L' << x + 17 << ' ' << y + 11 << 'M' << x + 7 << ' ' << y + 11
        << 'L' << x + 17 << ' ' << y + 1 << "\" stroke=\"" << hex(items[i].color) << "\" stroke-width=\"2.5\"/>\n";
    } else {
      s << "<rect x=\"" << x << "\" y=\"" << y << "\" width=\"24\" height=\"12\" fill=\"" << hex(items[i].color)
        << "\" fill-opacity=\"0.25\" stroke=\"" << hex(items[i].color) << "\"/>\n";
    }
    s << "<text x=\"" << x + 30 << "\" y=\"" << y + 11 << "\" font-size=\"13\">" << xml_escape(items[i].label)
      << "</text>\n";
  }
  s << "</svg>\n";
  std::ofstream f(path);
  if (!f) {
    if (err) *err = "cannot write '" + path + "'";
    return false;
  }
  f << s.str();
  if (!f) {
    if (err) *err = "error writing '" + path + "'";
    return false;
  }
  return true;
}

bool write_png(const Picture& pic, const std::string& path, std::string* err) {
  Layout L;
  if (!make_layout(pic, &L, err)) return false;
  Canvas c(L.width, L.height, kBackground);
  c.text(kMargin, kMargin, pic.title, {0, 0, 0});
  for (size_t i = 0; i < pic.notes.size(); ++i) {
    c.text(kMargin, kMargin + kLineHeight * static_cast<int>(i + 1), pic.notes[i], {50, 50, 50});
  }
  if (pic.map != nullptr && pic.map->geometry.width > 0) {
    const auto& g = pic.map->geometry;
    for (int y = 0; y < L.map_h; ++y) {
      for (int x = 0; x < L.map_w; ++x) {
        // Nearest cell, but let an occupied cell win inside the pixel so thin walls survive
        // downscaling.
        const double wx0 = L.x0 + x / L.ppm, wx1 = L.x0 + (x + 1) / L.ppm;
        const double wy1 = L.y1 - y / L.ppm, wy0 = L.y1 - (y + 1) / L.ppm;
        std::int32_t ax = 0, ay = 0, bx = 0, by = 0;
        const bool in_a = g.world_to_cell(static_cast<float>(wx0 + 1e-6), static_cast<float>(wy0 + 1e-6), &ax, &ay);
        const bool in_b = g.world_to_cell(static_cast<float>(wx1 - 1e-6), static_cast<float>(wy1 - 1e-6), &bx, &by);
        if (!in_a || !in_b) continue;
        std::uint8_t best = pic.map->cells[g.index((ax + bx) / 2, (ay + by) / 2)];
        for (std::int32_t cy = ay; cy <= by; ++cy)
          for (std::int32_t cx = ax; cx <= bx; ++cx)
            if (pic.map->cells[g.index(cx, cy)] == fw::kCellOccupied) best = fw::kCellOccupied;
        c.set(kMargin + x, L.header + y, cell_colour(best));
      }
    }
  }
  // Overlays stay inside the map area (a dead-reckoning estimate may leave the map far behind).
  c.clip_x0 = kMargin;
  c.clip_y0 = L.header;
  c.clip_x1 = kMargin + L.map_w;
  c.clip_y1 = L.header + L.map_h;
  for (const auto& b : pic.boxes) {
    c.fill_rect(static_cast<int>(L.px(b.x0)), static_cast<int>(L.py(b.y1)), static_cast<int>(L.px(b.x1)),
                static_cast<int>(L.py(b.y0)), b.color, 0.15);
    c.rect_outline(L.px(b.x0), L.py(b.y1), L.px(b.x1), L.py(b.y0), b.color);
  }
  for (const auto& l : pic.lines) {
    for (size_t i = 1; i < l.points.size(); ++i) {
      const auto& a = l.points[i - 1];
      const auto& b = l.points[i];
      if (!std::isfinite(a.x) || !std::isfinite(a.y) || !std::isfinite(b.x) || !std::isfinite(b.y)) continue;
      c.line(L.px(a.x), L.py(a.y), L.px(b.x), L.py(b.y), l.width_px, l.color);
    }
  }
  for (const auto& cs : pic.circle_sets) {
    for (const auto& ci : cs.circles) {
      if (!std::isfinite(ci.x) || !std::isfinite(ci.y) || !std::isfinite(ci.radius_m) || ci.radius_m <= 0) continue;
      c.ring(L.px(ci.x), L.py(ci.y), ci.radius_m * L.ppm, cs.width_px, cs.color);
    }
  }
  for (const auto& ps : pic.point_sets) {
    for (const auto& p : ps.points) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
      if (ps.shape == PointShape::kCross) c.cross(L.px(p.x), L.py(p.y), ps.radius_px, 2.5, ps.color);
      else c.disc(L.px(p.x), L.py(p.y), ps.radius_px, ps.color);
    }
  }
  for (const auto& m : pic.markers) {
    const double cx = L.px(m.x), cy = L.py(m.y);
    for (int k = 0; k < 72; ++k) {
      const double a0 = k * M_PI / 36, a1 = (k + 1) * M_PI / 36;
      c.line(cx + m.radius_px * std::cos(a0), cy + m.radius_px * std::sin(a0), cx + m.radius_px * std::cos(a1),
             cy + m.radius_px * std::sin(a1), 2.5, m.color);
    }
    c.line(cx, cy, cx + 2 * m.radius_px * std::cos(m.theta), cy - 2 * m.radius_px * std::sin(m.theta), 2.5, m.color);
    if (!m.text.empty()) {
      // Labels may leave the map area but not the picture: flip to the left near the right edge.
      c.no_clip();
      const int text_w = 12 * static_cast<int>(m.text.size());
      int tx = static_cast<int>(cx + m.radius_px + 4);
      if (tx + text_w > L.width - 2) tx = static_cast<int>(cx - m.radius_px - 4) - text_w;
      const int ty = static_cast<int>(cy - m.radius_px - 16);
      c.fill_rect(tx - 2, ty - 2, tx + 12 * static_cast<int>(m.text.size()) + 2, ty + 16, {255, 255, 255}, 0.8);
      c.text(tx, ty, m.text, m.color);
      c.clip_x0 = kMargin;
      c.clip_y0 = L.header;
      c.clip_x1 = kMargin + L.map_w;
      c.clip_y1 = L.header + L.map_h;
    }
  }
  c.no_clip();
  const auto items = legend_items(pic);
  const int col_w = (L.width - 2 * kMargin) / 3;
  for (size_t i = 0; i < items.size(); ++i) {
    const int x = kMargin + static_cast<int>(i % 3) * col_w;
    const int y = L.header + L.map_h + kMargin + static_cast<int>(i / 3) * kLineHeight;
    if (items[i].kind == 0) c.line(x, y + 7, x + 24, y + 7, 3, items[i].color);
    else if (items[i].kind == 1) c.disc(x + 12, y + 7, 4, items[i].color);
    else if (items[i].kind == 3) c.ring(x + 12, y + 7, 6, 1.5, items[i].color);
    else if (items[i].kind == 4) c.cross(x + 12, y + 7, 5, 2.5, items[i].color);
    else c.fill_rect(x, y + 1, x + 24, y + 13, items[i].color, 0.4);
    c.text(x + 30, y, items[i].label, {0, 0, 0});
  }
  std::vector<std::uint8_t> png;
  if (!encode_png_rgb(c.w, c.h, c.rgb, &png, err)) return false;
  std::ofstream f(path, std::ios::binary);
  if (!f) {
    if (err) *err = "cannot write '" + path + "'";
    return false;
  }
  f.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  if (!f) {
    if (err) *err = "error writing '" + path + "'";
    return false;
  }
  return true;
}

}  // namespace sim
