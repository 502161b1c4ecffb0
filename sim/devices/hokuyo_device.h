// HokuyoDevice: a Hokuyo URG / UTM / UST as the host sees it on the wire (SCIP 2.0 answers made
// with the hal/serial encoder), for mml-hokuyodev and the pty round-trip tests. It answers SCIP2.0,
// QT, VV, PP, II, BM and MD/ME (continuous; the echo carries the remaining-scan count 00) with the
// geometry of a real unit's PP answer; scan_answer() makes one "99" answer from a polar scan: per
// cluster the smallest reading of its steps (what a Hokuyo reports), 1 (the "no object" error
// code, below DMIN) where the scan has no return. power_cycle() is a reset: MD forgotten, laser off.
#pragma once

#include <cstdint>
#include <string>

#include "sim/devices/polar_scan.h"

namespace sim {

struct HokuyoModel {
  const char* name;     // "utm-30lx", "urg-04lx", "ust-10lx"
  const char* product;  // VV PROD
  std::uint32_t dmin_mm, dmax_mm, ares, amin, amax, afrt, rpm;
};
// The PP answers of the units (data sheets: UTM-30LX C-42-3615, URG-04LX C-42-3320, UST-10LX).
const HokuyoModel* find_hokuyo_model(const std::string& name);
const char* hokuyo_model_names();  // for messages

class HokuyoDevice {
 public:
  explicit HokuyoDevice(const HokuyoModel& model) : model_(model) {}
  // Bytes from the host; the answers are appended to *out.
  void receive(const std::uint8_t* bytes, size_t n, std::string* out);
  bool streaming() const { return streaming_; }
  // One measurement answer for the current MD/ME request (empty if none).
  std::string scan_answer(const PolarScan& scan, std::uint32_t timestamp_ms) const;
  void power_cycle();
  const HokuyoModel& model() const { return model_; }
  size_t commands() const { return commands_; }

 private:
  void command(const std::string& line, std::string* out);
  HokuyoModel model_;
  std::string pending_;
  std::string scan_cmd_;  // "MD" or "ME"
  std::uint32_t start_ = 0, end_ = 0, cluster_ = 1;
  bool streaming_ = false;
  bool laser_on_ = false;
  size_t commands_ = 0;
};

}  // namespace sim
