#include "sim/devices/hokuyo_device.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "hal_serial/scip.h"

namespace sim {

namespace {

const HokuyoModel kHokuyoModels[] = {
    // UTM-30LX: 270° in 1081 steps of 0.25°, 0.1-30 m guaranteed (DMIN 23, DMAX 60000 in its PP).
    {"utm-30lx", "SOKUIKI Sensor TOP-URG UTM-30LX", 23, 60000, 1440, 0, 1080, 540, 2400},
    // URG-04LX: 240° in steps 44..725 of 360/1024°, 20-5600 mm (the specification's PP example).
    {"urg-04lx", "SOKUIKI Sensor URG-04LX", 20, 5600, 1024, 44, 725, 384, 600},
    // UST-10LX: 270° in 1081 steps, 0.06-10 m (30 m max in PP).
    {"ust-10lx", "SOKUIKI Sensor UST-10LX", 20, 30000, 1440, 0, 1080, 540, 2400},
};

void append_status(const std::string& echo, const char* status, std::string* out) {
  char buf[160];
  const size_t n = hal_serial::encode_scip_status(echo.c_str(), status, buf, sizeof(buf));
  out->append(buf, n);
}

}  // namespace

const HokuyoModel* find_hokuyo_model(const std::string& name) {
  for (const HokuyoModel& m : kHokuyoModels)
    if (name == m.name) return &m;
  return nullptr;
}

const char* hokuyo_model_names() { return "utm-30lx, urg-04lx, ust-10lx"; }

void HokuyoDevice::power_cycle() {
  streaming_ = false;
  laser_on_ = false;
  scan_cmd_.clear();
  pending_.clear();
}

void HokuyoDevice::receive(const std::uint8_t* bytes, size_t n, std::string* out) {
  for (size_t i = 0; i < n; ++i) {
    const char c = static_cast<char>(bytes[i]);
    if (c == '\n' || c == '\r') {
      if (!pending_.empty()) command(pending_, out);
      pending_.clear();
    } else if (pending_.size() < 64) {
      pending_ += c;
    }
  }
}

void HokuyoDevice::command(const std::string& line, std::string* out) {
  ++commands_;
  const std::string cmd = line.substr(0, 2);
  if (line == "SCIP2.0") return append_status(line, "0E", out);  // already SCIP 2.0
  if (cmd == "QT") {
    streaming_ = false;
    laser_on_ = false;
    return append_status(line, "00", out);
  }
  if (cmd == "BM") {
    const bool was_on = laser_on_;
    laser_on_ = true;
    return append_status(line, was_on ? "02" : "00", out);
  }
  if (cmd == "VV" || cmd == "PP" || cmd == "II") {
    char l[8][96];
    size_t k = 0;
    if (cmd == "VV") {
      std::snprintf(l[k++], 96, "VEND:Hokuyo Automatic Co.,Ltd.");
      std::snprintf(l[k++], 96, "PROD:%s", model_.product);
      std::snprintf(l[k++], 96, "FIRM:mml-hokuyodev");
      std::snprintf(l[k++], 96, "PROT:SCIP 2.0");
      std::snprintf(l[k++], 96, "SERI:H0000059");
    } else if (cmd == "PP") {
      std::snprintf(l[k++], 96, "MODL:%s", model_.name);
      std::snprintf(l[k++], 96, "DMIN:%u", model_.dmin_mm);
      std::snprintf(l[k++], 96, "DMAX:%u", model_.dmax_mm);
      std::snprintf(l[k++], 96, "ARES:%u", model_.ares);
      std::snprintf(l[k++], 96, "AMIN:%u", model_.amin);
      std::snprintf(l[k++], 96, "AMAX:%u", model_.amax);
      std::snprintf(l[k++], 96, "AFRT:%u", model_.afrt);
      std::snprintf(l[k++], 96, "SCAN:%u", model_.rpm);
    } else {
      std::snprintf(l[k++], 96, "MODL:%s", model_.name);
      std::snprintf(l[k++], 96, "LASR:%s", laser_on_ ? "ON" : "OFF");
      std::snprintf(l[k++], 96, "STAT:Stable 000 no error.");
    }
    const char* lines[8];
    for (size_t i = 0; i < k; ++i) lines[i] = l[i];
    char buf[1024];
    const size_t n = hal_serial::encode_scip_info(line.c_str(), lines, k, buf, sizeof(buf));
    out->append(buf, n);
    return;
  }
  if (cmd == "MD" || cmd == "ME" || cmd == "MS") {
    unsigned s = 0, e = 0, c = 0, iv = 0, nscans = 0;
    if (line.size() < 15 || std::sscanf(line.c_str() + 2, "%4u%4u%2u%1u%2u", &s, &e, &c, &iv, &nscans) != 5) {
      return append_status(line, "01", out);
    }
    if (e < s || s < model_.amin || e > model_.amax) return append_status(line, "04", out);
    scan_cmd_ = cmd == "MS" ? "MD" : cmd;  // the model sends 3-character values only
    start_ = s;
    end_ = e;
    cluster_ = c == 0 ? 1 : c;
    streaming_ = true;
    laser_on_ = true;
    return append_status(line, "00", out);
  }
  append_status(line, "0E", out);  // unknown command
}

std::string HokuyoDevice::scan_answer(const PolarScan& scan, std::uint32_t timestamp_ms) const {
  if (!streaming_) return {};
  char echo[32];
  std::snprintf(echo, sizeof(echo), "%s%04u%04u%02u000", scan_cmd_.c_str(), start_, end_, cluster_);
  std::vector<std::uint32_t> ranges, intensity;
  const double step = 2.0 * M_PI / model_.ares;
  for (std::uint32_t first = start_; first <= end_; first += cluster_) {
    std::uint32_t best = 0;
    for (std::uint32_t st = first; st < first + cluster_ && st <= end_; ++st) {
      double r = 0.0;
      const double a = (static_cast<double>(st) - model_.afrt) * step;
      if (!scan.at(a, &r)) continue;
      const std::uint32_t mm = static_cast<std::uint32_t>(std::lround(r * 1000.0));
      if (mm < model_.dmin_mm || mm > model_.dmax_mm) continue;
      if (best == 0 || mm < best) best = mm;
    }
    ranges.push_back(best == 0 ? 1 : best);  // 1: "no object" (an error code below DMIN)
    intensity.push_back(best == 0 ? 0 : 1000);
  }
  std::vector<char> buf(8 * ranges.size() + 256);
  const size_t n = hal_serial::encode_scip_scan(echo, timestamp_ms, ranges.data(),
                                                scan_cmd_ == "ME" ? intensity.data() : nullptr, ranges.size(), 3,
                                                buf.data(), buf.size());
  return std::string(buf.data(), n);
}

}  // namespace sim
