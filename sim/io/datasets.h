// The datasets in ../shared/data (see its README.md): file paths and the record counts the README
// states, so tests and tools can iterate over them. Paths are relative to data_dir().
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace sim {

// MMLFW_DATA_DIR from the environment, else <source dir>/../shared/data.
std::string data_dir();
// data_dir() + "/" + relative (empty relative → empty string).
std::string data_path(const std::string& relative);

struct LogCounts {
  std::string path;       // relative to data_dir()
  std::string scan_type;  // "FLASER" or "ROBOTLASER1"
  size_t scans = 0, odom = 0, params = 0, comments = 0, neff = 0, lines = 0;
};

struct Dataset {
  std::string name;             // "intel", "fr079", "aces", "mit-killian", "fr-clinic", "fr101", "fr-campus"
  std::string raw_log;          // raw log with every scan ("" when not available)
  std::string relations;        // benchmark relations ("" when none)
  std::string corrected_log;    // GMapping-corrected log ("" when none)
  std::string corrected_poses;  // *.corrected-poses.txt ("" when none)
  size_t expected_scans = 0;    // scan records in raw_log (0 when no raw log)
  size_t expected_relations = 0;
  size_t expected_corrected = 0;  // scans in corrected_log = rows of corrected_poses
  bool relations_match_log = false;  // relation timestamps are scan ipc_timestamps of raw_log
};

const std::vector<Dataset>& datasets();
const Dataset* find_dataset(const std::string& name);  // nullptr when unknown
// Every log file of ../shared/data with the counts its README states.
const std::vector<LogCounts>& expected_log_counts();

}  // namespace sim
