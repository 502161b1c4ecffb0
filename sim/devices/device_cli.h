// What mml-hokuyodev and mml-rplidardev share: "--key value" arguments, the scans of a CARMEN log
// as polar scans, a monotonic clock and the device side of the serial port (a pty end).
#pragma once

#include <time.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "sim/devices/polar_scan.h"
#include "sim/io/carmen_log.h"
#include "sim/io/datasets.h"

namespace sim {

struct DeviceArgs {
  std::map<std::string, std::string> kv;
  // false with *err for an argument that is not "--key value".
  bool parse(int argc, char** argv, std::string* err) {
    for (int i = 1; i < argc; ++i) {
      std::string k = argv[i];
      if (k.rfind("--", 0) != 0 || i + 1 >= argc) {
        *err = "bad argument '" + k + "'";
        return false;
      }
      kv[k.substr(2)] = argv[++i];
    }
    return true;
  }
  double num(const char* k, double d) const {
    auto it = kv.find(k);
    return it == kv.end() ? d : std::strtod(it->second.c_str(), nullptr);
  }
  std::string str(const char* k, const std::string& d) const {
    auto it = kv.find(k);
    return it == kv.end() ? d : it->second;
  }
  bool has(const char* k) const { return kv.count(k) != 0; }
};

inline double device_now_s() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

// The scans [first, first + count) of --dataset NAME or --log PATH as polar scans.
inline bool load_device_scans(const DeviceArgs& a, std::vector<PolarScan>* out, std::string* err) {
  std::string path = a.str("log", "");
  if (a.has("dataset")) {
    const Dataset* ds = find_dataset(a.str("dataset", ""));
    if (!ds || ds->raw_log.empty()) {
      *err = "--dataset '" + a.str("dataset", "") + "' unknown or without raw log";
      return false;
    }
    path = data_path(ds->raw_log);
  }
  if (path.empty()) {
    *err = "need --dataset or --log";
    return false;
  }
  const size_t first = static_cast<size_t>(a.num("first", 0)), count = static_cast<size_t>(a.num("count", 100));
  CarmenLog log;
  CarmenReadOptions ro;
  ro.max_scans = first + count;
  if (!read_carmen_log(path, ro, &log, err)) return false;
  if (first >= log.scans.size()) {
    *err = "--first beyond the log";
    return false;
  }
  for (size_t i = first; i < log.scans.size() && out->size() < count; ++i) {
    const CarmenScan& s = log.scans[i];
    PolarScan p;
    p.angle_min = s.angle_min;
    p.angle_increment = s.angle_increment;
    p.max_range = s.max_range;
    p.ranges = s.ranges;
    out->push_back(std::move(p));
  }
  return true;
}

}  // namespace sim
