#include "sim/io/datasets.h"

#include <cstdlib>

#ifndef MMLFW_SOURCE_DIR
#define MMLFW_SOURCE_DIR "."
#endif

namespace sim {

std::string data_dir() {
  const char* env = std::getenv("MMLFW_DATA_DIR");
  if (env && *env) return env;
  return std::string(MMLFW_SOURCE_DIR) + "/../shared/data";
}

std::string data_path(const std::string& relative) {
  if (relative.empty()) return std::string();
  return data_dir() + "/" + relative;
}

const std::vector<Dataset>& datasets() {
  static const std::vector<Dataset> kDatasets = {
      {"intel", "intel/intel.clf.gz", "intel/intel.relations", "intel/intel-corrected.log.gz",
       "intel/intel.corrected-poses.txt", 13631, 2984, 910, true},
      {"fr079", "fr079/fr079.clf.gz", "fr079/fr079.relations", "fr079/freiburg-079-corrected.log.gz",
       "fr079/fr079.corrected-poses.txt", 4934, 1685, 4791, true},
      {"aces", "aces/aces.clf.gz", "aces/aces.relations", "aces/aces-corrected.log.gz", "aces/aces.corrected-poses.txt",
       7374, 1279, 440, true},
      // Synthetic timestamps in the reconstructed log: the relations cannot be looked up in it.
      {"mit-killian", "mit-killian/mit-killian.reconstructed.clf.gz", "mit-killian/mit-killian.relations",
       "mit-killian/infinite-corridor-corrected.log.gz", "mit-killian/mit-killian.corrected-poses.txt", 17480, 4677,
       1941, false},
      {"fr-clinic", "fr-clinic/fr-clinic_robotlaser.clf.gz", "fr-clinic/fr-clinic.relations", "", "", 6917, 2820, 0,
       true},
      {"fr101", "", "", "fr101/freiburg-101-corrected.log.gz", "", 0, 0, 292, false},
      {"fr-campus", "", "", "fr-campus/freiburg-campus-corrected.log.gz", "", 0, 0, 2008, false},
  };
  return kDatasets;
}

const Dataset* find_dataset(const std::string& name) {
  for (const auto& d : datasets()) {
    if (d.name == name) return &d;
  }
  return nullptr;
}

const std::vector<LogCounts>& expected_log_counts() {
  // path, scan type, scans, ODOM, PARAM, '#' lines, NEFF, lines — from ../shared/data/README.md.
  static const std::vector<LogCounts> kCounts = {
      {"intel/intel.clf.gz", "FLASER", 13631, 26915, 2, 9, 0, 40557},
      {"intel/intel-corrected.log.gz", "FLASER", 910, 14541, 2, 2, 910, 16365},
      {"fr079/fr079.clf.gz", "FLASER", 4934, 8951, 187, 11, 0, 14083},
      {"fr079/freiburg-079-corrected.log.gz", "FLASER", 4791, 9725, 187, 2, 4791, 19496},
      {"aces/aces.clf.gz", "FLASER", 7374, 7375, 4, 9, 0, 14762},
      {"aces/aces-corrected.log.gz", "FLASER", 440, 7814, 4, 2, 440, 8700},
      {"mit-killian/mit-killian.reconstructed.clf.gz", "FLASER", 17480, 0, 0, 8, 0, 17488},
      {"mit-killian/infinite-corridor-corrected.log.gz", "FLASER", 1941, 18191, 0, 0, 1941, 22073},
      {"fr-clinic/fr-clinic_robotlaser.clf.gz", "ROBOTLASER1", 6917, 0, 0, 0, 0, 6917},
      {"fr101/freiburg-101-corrected.log.gz", "FLASER", 292, 4569, 168, 3, 292, 5324},
      {"fr-campus/freiburg-campus-corrected.log.gz", "FLASER", 2008, 17691, 245, 5, 2008, 21957},
  };
  return kCounts;
}

}  // namespace sim
