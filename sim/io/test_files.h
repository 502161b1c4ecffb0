// Scratch files of the sim/io tests: per-process names under GoogleTest's TempDir, so parallel CTest
// runs of the same test binary never share a file.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>

namespace sim {
namespace test_files {

inline std::string temp_path(const std::string& prefix, const std::string& name) {
  return std::string(::testing::TempDir()) + "/" + prefix + "_" + std::to_string(::getpid()) + "_" + name;
}

inline void write_text(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
}

}  // namespace test_files
}  // namespace sim
