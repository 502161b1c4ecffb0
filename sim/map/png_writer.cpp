#include "sim/map/png_writer.h"

#include <png.h>

#include "sim/io/file_io.h"

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace sim {

bool write_png(const std::string& path, int width, int height, int channels, const std::vector<std::uint8_t>& pixels,
               std::string* error) {
  auto fail = [&](const std::string& m) {
    if (error != nullptr) *error = path + ": " + m;
    return false;
  };
  if (width <= 0 || height <= 0 || (channels != 1 && channels != 3) ||
      pixels.size() != static_cast<std::size_t>(width) * height * channels) {
    return fail("write_png: size/channels inconsistent with the pixel buffer");
  }
  // Encoded in memory, then written through a temporary file renamed over `path` (file_io.h): a
  // failure leaves no truncated picture behind.
  std::string encoded;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr) {
    png_destroy_write_struct(&png, &info);
    return fail("libpng initialisation failed");
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return fail("libpng write error");
  }
  png_set_write_fn(
      png, &encoded,
      [](png_structp p, png_bytep data, png_size_t n) {
        static_cast<std::string*>(png_get_io_ptr(p))->append(reinterpret_cast<const char*>(data), n);
      },
      [](png_structp) {});
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               channels == 1 ? PNG_COLOR_TYPE_GRAY : PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y) {
    png_write_row(png, const_cast<png_bytep>(pixels.data() + static_cast<std::size_t>(y) * width * channels));
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return write_file_atomic(path, encoded, error);
}

}  // namespace sim
