// A private scratch directory for harnesses whose parser reads a path (PGM, YAML, relations,
// gzip logs): the fuzz input is written to a file there and the real reader opens it, so the file
// checks (regular file, size caps) run too. One directory per process, removed at exit.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>
#include <unistd.h>

namespace fuzz {

class ScratchDir {
 public:
  ScratchDir() {
    const char* base = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    std::string tmpl = std::string(base) + "/mmlfw-fuzz-XXXXXX";
    if (mkdtemp(tmpl.data()) == nullptr) {
      std::perror("fuzz: mkdtemp");
      std::abort();
    }
    dir_ = tmpl;
  }
  ~ScratchDir() {
    const std::string cmd = "rm -rf '" + dir_ + "'";
    if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "fuzz: could not remove %s\n", dir_.c_str());
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  // Writes bytes to name (replacing it); returns the path.
  std::string write(const std::string& name, const void* data, std::size_t size) const {
    const std::string p = path(name);
    std::FILE* f = std::fopen(p.c_str(), "wb");
    if (f == nullptr || (size > 0 && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0) {
      std::perror(p.c_str());
      std::abort();
    }
    return p;
  }
  static ScratchDir& instance() {
    static ScratchDir d;
    return d;
  }

 private:
  std::string dir_;
};

}  // namespace fuzz
