// PCD (Point Cloud Library point cloud file, format v0.7) reader for the host tools: the x/y/z of
// every point; other fields are checked for shape but not kept. Supported: DATA ascii, binary and
// binary_compressed (LZF, fields stored one after another), plain or gzip (detected by magic, as the
// CARMEN reader), organized (HEIGHT > 1) or not. Points with a non-finite x, y or z (an RGB-D pixel
// without a return is NaN) are dropped and counted; `index` keeps each kept point's position in
// the file (row-major pixel index of an organized cloud).
//
// Strict: a malformed header (unknown or repeated keyword, FIELDS/SIZE/TYPE/COUNT of different
// lengths, a size that does not fit its type, no x/y/z, WIDTH·HEIGHT ≠ POINTS, …), a data line with
// the wrong number of values or a non-number, fewer or more points than declared, a truncated or
// over-long binary block and a corrupt compressed block are errors "path:line: problem" (line = the
// header line, or the data line; binary problems name the byte offset). Nothing is allocated for
// the points before the file is known to hold them.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sim {

struct PcdCloud {
  std::string path;
  std::vector<std::string> fields;        // FIELDS as declared
  std::string data;                        // "ascii", "binary" or "binary_compressed"
  std::uint32_t width = 0, height = 0;     // height > 1: organized
  std::size_t declared_points = 0;         // POINTS (= width·height)
  std::size_t dropped_nonfinite = 0;       // points whose x, y or z is NaN / inf (not in `points`)
  std::vector<Eigen::Vector3f> points;     // finite points in file order
  std::vector<std::uint32_t> index;        // file position of each kept point
  bool organized() const { return height > 1; }
};

// Caps: the inflated / plain file (default 1 GiB) and the declared point count (2^28).
struct PcdReadOptions {
  std::uint64_t max_bytes = std::uint64_t(1) << 30;
  std::size_t max_points = std::size_t(1) << 28;
};

// Reads `path` (plain or .gz). False with *error = "path:line: problem" on any malformed input.
bool read_pcd(const std::string& path, const PcdReadOptions& options, PcdCloud* out, std::string* error);
bool read_pcd(const std::string& path, PcdCloud* out, std::string* error);
// Parses an in-memory (already inflated) PCD file; `name` is used in the messages.
bool parse_pcd(const std::string& name, const std::string& bytes, const PcdReadOptions& options, PcdCloud* out,
               std::string* error);

// LZF decompression (the format of DATA binary_compressed, liblzf's lzf_decompress): false when the
// stream is corrupt (a back reference before the start, a run past either end) or does not inflate
// to exactly `out_size` bytes.
bool lzf_decompress(const std::uint8_t* in, std::size_t in_size, std::uint8_t* out, std::size_t out_size);

}  // namespace sim
