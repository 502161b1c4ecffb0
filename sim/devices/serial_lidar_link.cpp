#include "sim/devices/serial_lidar_link.h"

namespace sim {

namespace {

// The units the simulator plays by default: the laser of the Hokuyo and RPLIDAR HIL tests.
constexpr const char* kHokuyoModel = "utm-30lx";
constexpr const char* kRplidarModel = "a1";
// Polls of the driver the start-up handshake may take (each answer moves it one request on).
constexpr int kHandshakePolls = 64;

PolarScan polar_of(const hal::LaserScan& scan) {
  PolarScan p;
  p.angle_min = scan.angle_min;
  p.angle_increment = scan.angle_increment;
  p.max_range = scan.range_max;
  p.ranges.assign(scan.ranges, scan.ranges + scan.beam_count);
  return p;
}

}  // namespace

long DeviceLoopPort::write(const std::uint8_t* buf, std::size_t len) {
  if (!answering_) return static_cast<long>(len);
  answer_.clear();
  if (kind_ == SerialLidarKind::kHokuyo) {
    hokuyo_->receive(buf, len, &answer_);
  } else {
    rplidar_->receive(buf, len, &answer_);
  }
  if (!answer_.empty() &&
      !wire_->device_send(reinterpret_cast<const std::uint8_t*>(answer_.data()), answer_.size())) {
    ++refused_;
  }
  return static_cast<long>(len);
}

bool SerialLidarLink::valid_model(SerialLidarKind kind, const std::string& model) {
  if (model.empty()) return true;
  return kind == SerialLidarKind::kHokuyo ? find_hokuyo_model(model) != nullptr : find_rplidar_model(model) != nullptr;
}

SerialLidarLink::SerialLidarLink(SerialLidarKind kind, const std::string& model, hal_sim::SimSerialPort* wire,
                                 const hal::Clock* clock)
    : kind_(kind),
      hokuyo_dev_(*find_hokuyo_model(kind == SerialLidarKind::kHokuyo && !model.empty() ? model : kHokuyoModel)),
      rplidar_dev_(*find_rplidar_model(kind == SerialLidarKind::kRplidar && !model.empty() ? model : kRplidarModel)),
      clock_(clock),
      loop_(kind, wire, &hokuyo_dev_, &rplidar_dev_) {}

const char* SerialLidarLink::model_name() const {
  return kind_ == SerialLidarKind::kHokuyo ? hokuyo_dev_.model().name : rplidar_dev_.model().name;
}

void SerialLidarLink::init_driver(hal::SerialPort* port) {
  if (kind_ == SerialLidarKind::kHokuyo) {
    hokuyo_.init(port, &clock_, hal_serial::HokuyoOptions{});
    return;
  }
  hal_serial::RplidarOptions o;
  o.stop_settle_ms = 0;  // the simulated unit takes the next request at once (the handshake's clock stands)
  rplidar_.init(port, &clock_, o);
}

hal_serial::SerialLaser& SerialLidarLink::laser() {
  if (kind_ == SerialLidarKind::kHokuyo) return hokuyo_;
  return rplidar_;
}

bool SerialLidarLink::handshake(std::uint64_t t_ns, bool answer_after_handshake, std::string* err) {
  started_ = true;
  clock_.fix(t_ns);
  loop_.set_answering(true);
  hal_serial::SerialLaser& l = laser();
  hal::LaserScan discard;
  bool ok = l.start();
  for (int i = 0; ok && i < kHandshakePolls && !l.ready(); ++i) (void)l.poll(&discard);
  clock_.release();
  loop_.set_answering(answer_after_handshake);
  if (l.ready()) return true;
  char why[256];
  l.describe_handshake(why, sizeof(why));
  *err = std::string(l.protocol_name()) + " (simulated " + model_name() + "): " + why;
  return false;
}

void SerialLidarLink::encode_scan(const hal::LaserScan& scan, std::string* out) {
  const PolarScan p = polar_of(scan);
  if (kind_ == SerialLidarKind::kHokuyo) {
    // The sensor's 24-bit ms counter runs with the simulation clock.
    const auto ms = static_cast<std::uint32_t>((scan.timestamp_ns / 1000000u) & 0xFFFFFFu);
    out->append(hokuyo_dev_.scan_answer(p, ms));
    return;
  }
  // Samples until the head completes a turn: the next sample, in the next scan, carries the start
  // flag that hands this turn to the driver (a turn is delivered when the next one begins).
  const std::size_t limit = 2 * rplidar_dev_.samples_per_turn() + 1;
  for (std::size_t i = 0; i < limit && rplidar_dev_.streaming(); ++i) {
    if (rplidar_dev_.samples(p, 1, out) > 0) return;
  }
}

}  // namespace sim
