#include "firmware/app/app_config.h"

#include "firmware/app/localizer_names.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace fw {
namespace {

bool parse_int(const char* v, long lo, long hi, long* out) {
  char* end = nullptr;
  errno = 0;
  const long x = std::strtol(v, &end, 10);
  if (end == v || *end || errno || x < lo || x > hi) return false;
  *out = x;
  return true;
}

bool parse_bool(const char* v, bool* out) {
  if (!std::strcmp(v, "true") || !std::strcmp(v, "1") || !std::strcmp(v, "yes")) { *out = true; return true; }
  if (!std::strcmp(v, "false") || !std::strcmp(v, "0") || !std::strcmp(v, "no")) { *out = false; return true; }
  return false;
}

bool copy(char* dst, std::size_t cap, const char* v) {
  if (std::strlen(v) >= cap) return false;
  std::strcpy(dst, v);
  return true;
}

// The serial laser kinds (hal/linux/board.h): "serial" is the older name of "sick".
constexpr const char* kSerialLaserKinds[] = {"serial:", "sick:", "hokuyo:", "rplidar:"};

// Length of the serial laser kind prefix of v ("hokuyo:" → 7), 0 when v is none of them.
std::size_t serial_laser_prefix(const char* v) {
  for (const char* k : kSerialLaserKinds) {
    const std::size_t n = std::strlen(k);
    if (!std::strncmp(v, k, n)) return n;
  }
  return 0;
}

// The laser may also be "can:IFACE" (= socketcan:IFACE) or a serial laser.
bool spec_ok(const char* v, bool allow_serial, const char* extra) {
  if (extra && !std::strcmp(v, extra)) return true;
  if (!std::strncmp(v, "socketcan:", 10) && v[10]) return true;
  if (allow_serial && !std::strncmp(v, "can:", 4) && v[4]) return true;
  const std::size_t p = serial_laser_prefix(v);
  if (allow_serial && p > 0 && v[p]) return true;
  return false;
}

// Serial rates the termios backend sets (hal/serial/termios_port.h); anything else is refused
// here, with the line and key, instead of at open time.
constexpr unsigned long kBauds[] = {9600, 19200, 38400, 57600, 115200, 230400, 256000, 460800, 500000, 921600, 1000000};
constexpr const char* kBaudList = "9600, 19200, 38400, 57600, 115200, 230400, 256000, 460800, 500000, 921600, 1000000";

// "@BAUD" of serial:DEVICE@BAUD: digits only, no overflow, a supported rate.
bool parse_baud(const char* v, unsigned long* out) {
  if (!*v) return false;
  for (const char* c = v; *c; ++c)
    if (*c < '0' || *c > '9') return false;
  if (std::strlen(v) > 7) return false;  // > 9999999: no rate of ours, and no overflow below
  const unsigned long b = std::strtoul(v, nullptr, 10);
  for (unsigned long k : kBauds)
    if (b == k) { *out = b; return true; }
  return false;
}

// Keys the file may set, each at most once (a second `laser = ...` used to win silently).
constexpr const char* kKeys[] = {"laser",     "odometry",  "output",  "can_fd",           "localizer",
                                 "mml_preset", "map",       "workers", "cores",            "realtime",
                                 "arena_mib", "step_deadline_ms", "health_period_ms", "laser_timeout_ms", "seed",
                                 "log_level", "global_context", "global_period_scans", "odom_noise",
                                 "odom_noise_per_step", "odom_slip", "laser_mount", "blackbox", "blackbox_frames",
                                 "blackbox_serial_chunks",                                 "map.1", "map.2", "map.3", "map_reload"};
constexpr int kNumKeys = static_cast<int>(sizeof(kKeys) / sizeof(kKeys[0]));

// The config path as shown in messages: at most kShownPath characters, the end kept (the file
// name), so a long path never pushes the line, key and problem out of the message.
constexpr std::size_t kShownPath = 96;
void shown_path(const char* path, char* out, std::size_t cap) {
  const std::size_t n = std::strlen(path);
  if (n < cap) {
    std::memcpy(out, path, n + 1);
    return;
  }
  const std::size_t keep = cap - 4;
  std::memcpy(out, "...", 3);
  std::memcpy(out + 3, path + n - keep, keep + 1);
}

}  // namespace

#define CFG_ERR(fmt, ...) \
  Status::error(Errc::kInvalidArgument, "config '%s' line %d: key '%s': " fmt, name, line, key, ##__VA_ARGS__)

namespace {

// Length and form of the part after "kind:" (the board keeps it in fixed buffers): a value that
// is too long is reported as such, not as a malformed spec; a serial rate must be one we set.
Status check_backend_arg(const char* name, int line, const char* key, const char* v, std::size_t cap) {
  const std::size_t n = std::strlen(v);
  if (n >= cap) return CFG_ERR("value too long (%zu characters, at most %zu)", n, cap - 1);
  const bool can = !std::strncmp(v, "can:", 4);
  if (can || !std::strncmp(v, "socketcan:", 10)) {
    const std::size_t iface = n - (can ? 4 : 10);
    if (iface > kMaxCanInterfaceName) {
      return CFG_ERR("interface name too long (%zu characters, at most %zu)", iface, kMaxCanInterfaceName);
    }
    return Status::ok();
  }
  const std::size_t p = serial_laser_prefix(v);
  if (p == 0) return Status::ok();
  // DEVICE[@BAUD][,OPTION]...: hokuyo takes "intensity" (ME); rplidar "express" or "force", "pwm=1..1023"
  // (A2/A3 motor duty) and "beams=1..1081" (the grid of a revolution), as hal/linux/board.h.
  char arg[128];
  std::snprintf(arg, sizeof(arg), "%s", v + p);
  if (char* comma = std::strchr(arg, ',')) {
    *comma = '\0';
    const bool hokuyo = !std::strncmp(v, "hokuyo:", 7), rplidar = !std::strncmp(v, "rplidar:", 8);
    for (char* opt = comma + 1; opt != nullptr;) {
      char* next = std::strchr(opt, ',');
      if (next != nullptr) *next++ = '\0';
      long x = 0;
      const bool ok = (hokuyo && !std::strcmp(opt, "intensity")) ||
                      (rplidar && (!std::strcmp(opt, "express") || !std::strcmp(opt, "force"))) ||
                      (rplidar && !std::strncmp(opt, "pwm=", 4) && parse_int(opt + 4, 1, 1023, &x)) ||
                      (rplidar && !std::strncmp(opt, "beams=", 6) && parse_int(opt + 6, 1, 1081, &x));
      if (!ok) {
        return CFG_ERR("'%s': option '%s' unknown (hokuyo: intensity; rplidar: express, force, pwm=1..1023, beams=1..1081)",
                       v, opt);
      }
      opt = next;
    }
  }
  const char* at = std::strchr(arg, '@');
  if (at == arg || arg[0] == '\0') return CFG_ERR("'%s': no device", v);
  if (at != nullptr) {
    unsigned long baud = 0;
    if (!parse_baud(at + 1, &baud)) return CFG_ERR("baud '%s' is not one of %s", at + 1, kBaudList);
  }
  return Status::ok();
}

// `count` comma-separated numbers, number i in 0..hi[i]; `names` lists them for the messages.
Status parse_number_list(const char* name, int line, const char* key, char* v, float* out, int count,
                         const float* hi, const char* names) {
  int commas = 0;
  for (const char* c = v; *c; ++c) commas += *c == ',';
  if (commas != count - 1) return CFG_ERR("'%s' is not %d numbers %s", v, count, names);
  char* tok = v;
  for (int i = 0; i < count; ++i) {
    char* comma = std::strchr(tok, ',');
    if (comma != nullptr) *comma = '\0';
    char* pe = nullptr;
    const double d = std::strtod(tok, &pe);
    while (pe != nullptr && (*pe == ' ' || *pe == '\t')) ++pe;
    if (pe == tok || *pe || !std::isfinite(d) || d < 0.0 || d > hi[i]) {
      return CFG_ERR("number %d '%s' is not in 0..%g (%s)", i + 1, tok, static_cast<double>(hi[i]), names);
    }
    out[i] = static_cast<float>(d);
    tok = comma != nullptr ? comma + 1 : nullptr;
  }
  return Status::ok();
}

// "TT, TR, RR, RT": the tracker's odometry noise model (track_options.h), four numbers in 0..10.
Status parse_odom_noise(const char* name, int line, const char* key, char* v, float out[4]) {
  static const float kHi[4] = {10.0f, 10.0f, 10.0f, 10.0f};
  return parse_number_list(name, line, key, v, out, 4, kHi, "TT, TR, RR, RT");
}

// "M, DEG": the tracker's per-step odometry noise (TrackOptions::odom_trans_per_step_m, the other in degrees).
Status parse_odom_noise_per_step(const char* name, int line, const char* key, char* v, float out[2]) {
  static const float kHi[2] = {1.0f, 28.0f};
  return parse_number_list(name, line, key, v, out, 2, kHi, "M, DEG");
}

// "RATE, MAX_M": declared wheel slips (TrackOptions::odom_slip_per_100m, odom_slip_max_m).
Status parse_odom_slip(const char* name, int line, const char* key, char* v, float out[2]) {
  static const float kHi[2] = {1000.0f, 100.0f};
  return parse_number_list(name, line, key, v, out, 2, kHi, "RATE, MAX_M");
}

// odom_noise, odom_noise_per_step, odom_slip: the tracker's odometry model (kKeys lists them).
Status parse_odometry_key(const char* name, int line, const char* key, char* v, AppConfig* out) {
  if (!std::strcmp(key, "odom_noise")) return parse_odom_noise(name, line, key, v, out->odom_noise);
  if (!std::strcmp(key, "odom_noise_per_step")) return parse_odom_noise_per_step(name, line, key, v, out->odom_noise_per_step);
  return parse_odom_slip(name, line, key, v, out->odom_slip);
}

// laser: the backend spec; laser_mount: "YAW_DEG[, upside-down]", how the laser sits on the robot
// (its zero direction turned YAW degrees counter-clockwise from the robot's front; upside down it
// sees the world mirrored). The board turns every scan into the robot's orientation.
Status parse_laser_key(const char* name, int line, const char* key, char* v, AppConfig* out) {
  if (!std::strcmp(key, "laser")) {
    if (!spec_ok(v, true, nullptr)) return CFG_ERR("'%s' is not can:IFACE, sick:, hokuyo: or rplidar:DEVICE[@BAUD]", v);
    FW_RETURN_IF_ERROR(check_backend_arg(name, line, key, v, sizeof(out->laser)));
    copy(out->laser, sizeof(out->laser), v);
    return Status::ok();
  }
  char* comma = std::strchr(v, ',');
  if (comma != nullptr) {
    *comma = '\0';
    char* flag = comma + 1;
    while (*flag == ' ' || *flag == '\t') ++flag;
    if (std::strcmp(flag, "upside-down") != 0) return CFG_ERR("'%s' is not 'upside-down'", flag);
    out->laser_upside_down = true;
  }
  char* pe = nullptr;
  const double d = std::strtod(v, &pe);
  while (pe != nullptr && (*pe == ' ' || *pe == '\t')) ++pe;
  if (pe == v || *pe || !std::isfinite(d) || d < -180.0 || d > 180.0) {
    return CFG_ERR("yaw '%s' is not a number of degrees in -180..180 (laser_mount = YAW_DEG[, upside-down])", v);
  }
  out->laser_mount_yaw_deg = static_cast<float>(d);
  return Status::ok();
}

// blackbox = PATH | off, blackbox_frames = N, blackbox_serial_chunks = N (issue 60; kKeys lists them).
Status parse_blackbox_key(const char* name, int line, const char* key, const char* v, AppConfig* out) {
  if (!std::strcmp(key, "blackbox")) {
    if (!std::strcmp(v, "off")) {
      out->blackbox[0] = '\0';
      return Status::ok();
    }
    if (!copy(out->blackbox, sizeof(out->blackbox), v)) {
      return CFG_ERR("path longer than %zu characters", sizeof(out->blackbox) - 1);
    }
    return Status::ok();
  }
  if (!std::strcmp(key, "blackbox_frames")) {
    long x = 0;
    if (!parse_int(v, 0, AppConfig::kMaxBlackBoxFrames, &x)) {
      return CFG_ERR("'%s' is not an integer in 0..%ld", v, AppConfig::kMaxBlackBoxFrames);
    }
    out->blackbox_frames = static_cast<std::uint32_t>(x);
    return Status::ok();
  }
  if (!std::strcmp(key, "blackbox_serial_chunks")) {
    long x = 0;
    if (!parse_int(v, 0, AppConfig::kMaxBlackBoxFrames, &x)) {
      return CFG_ERR("'%s' is not an integer in 0..%ld", v, AppConfig::kMaxBlackBoxFrames);
    }
    out->blackbox_serial_chunks = static_cast<std::uint32_t>(x);
    return Status::ok();
  }
  return Status::error(Errc::kInvalidArgument, "config '%s' line %d: unknown key '%s'", name, line, key);
}

// map = PATH (id 0), map.N = PATH (N = 1 .. kMaxMaps - 1), map_reload = true|false (issue 60).
Status parse_map_key(const char* name, int line, const char* key, const char* v, AppConfig* out) {
  if (!std::strcmp(key, "map")) {
    if (!copy(out->map, sizeof(out->map), v)) return CFG_ERR("path longer than %zu characters", sizeof(out->map) - 1);
    return Status::ok();
  }
  if (std::strncmp(key, "map.", 4) != 0 && std::strcmp(key, "map_reload") != 0) {
    return Status::error(Errc::kInvalidArgument, "config '%s' line %d: unknown key '%s'", name, line, key);
  }
  if (!std::strcmp(key, "map_reload")) {
    if (!parse_bool(v, &out->map_reload)) return CFG_ERR("'%s' is not true or false", v);
    return Status::ok();
  }
  long id = 0;
  if (!parse_int(key + 4, 1, AppConfig::kMaxMaps - 1, &id)) {
    return CFG_ERR("not a map key: map 0 is 'map', more maps are 'map.1' .. 'map.%d' (at most %d maps)",
                   AppConfig::kMaxMaps - 1, AppConfig::kMaxMaps);
  }
  char* dst = out->more_maps[id - 1];
  if (!copy(dst, sizeof(out->more_maps[0]), v)) return CFG_ERR("path longer than %zu characters", sizeof(out->more_maps[0]) - 1);
  return Status::ok();
}

// Map ids are consecutive from 0, so an id names the same map in every config of a fleet.
Status check_map_ids(const char* name, const AppConfig& c) {
  for (int id = 1; id < AppConfig::kMaxMaps; ++id) {
    if (!c.more_maps[id - 1][0]) continue;
    if (!map_path(c, id - 1)[0]) {
      return Status::error(Errc::kInvalidArgument, "config '%s': key 'map.%d' is set but '%s' is not (map ids are consecutive from 0 = 'map')",
                           name, id, id == 1 ? "map" : (id == 2 ? "map.1" : "map.2"));
    }
  }
  if (c.map_reload && !c.map[0]) {
    return Status::error(Errc::kInvalidArgument, "config '%s': key 'map_reload' needs a map (key 'map')", name);
  }
  return Status::ok();
}

}  // namespace

int map_count(const AppConfig& c) {
  int n = 0;
  while (n < AppConfig::kMaxMaps && map_path(c, n)[0]) ++n;
  return n;
}

const char* map_path(const AppConfig& c, int id) {
  if (id == 0) return c.map;
  if (id < 0 || id >= AppConfig::kMaxMaps) return "";
  return c.more_maps[id - 1];
}

Status parse_app_config(const char* path, const char* text, std::size_t len, AppConfig* out) {
  *out = AppConfig{};
  char name[kShownPath + 1];
  shown_path(path != nullptr ? path : "", name, sizeof(name));
  char buf[512];
  int line = 0;
  std::size_t pos = 0;
  bool seen_laser = false;
  int key_line[kNumKeys] = {0};
  while (pos < len) {
    std::size_t e = pos;
    while (e < len && text[e] != '\n') ++e;
    ++line;
    const std::size_t n = e - pos;
    if (n >= sizeof(buf)) {
      return Status::error(Errc::kInvalidArgument, "config '%s' line %d: longer than %zu characters", name, line,
                           sizeof(buf) - 1);
    }
    // A NUL byte would end the line early for every string function below (a line starting with
    // one used to vanish): binary junk in a config is an error, not a comment.
    if (const void* nul = std::memchr(text + pos, '\0', n)) {
      return Status::error(Errc::kInvalidArgument, "config '%s' line %d: NUL byte at column %zu (binary data?)", name,
                           line, static_cast<std::size_t>(static_cast<const char*>(nul) - (text + pos)) + 1);
    }
    std::memcpy(buf, text + pos, n);
    buf[n] = '\0';
    pos = e + 1;
    if (char* hash = std::strchr(buf, '#')) *hash = '\0';
    // Trim.
    char* s = buf;
    while (*s == ' ' || *s == '\t' || *s == '\r') ++s;
    char* end = s + std::strlen(s);
    while (end > s && (end[-1] == ' ' || end[-1] == '\t' || end[-1] == '\r')) *--end = '\0';
    if (!*s) continue;
    char* eq = std::strchr(s, '=');
    if (!eq) {
      return Status::error(Errc::kInvalidArgument, "config '%s' line %d: '%s' is not 'key = value'", name, line, s);
    }
    *eq = '\0';
    char* key = s;
    char* kend = eq;
    while (kend > key && (kend[-1] == ' ' || kend[-1] == '\t')) *--kend = '\0';
    char* v = eq + 1;
    while (*v == ' ' || *v == '\t') ++v;
    if (!*key) return Status::error(Errc::kInvalidArgument, "config '%s' line %d: empty key", name, line);
    if (!*v) return CFG_ERR("empty value");
    for (int k = 0; k < kNumKeys; ++k) {
      if (std::strcmp(key, kKeys[k]) != 0) continue;
      if (key_line[k] != 0) {
        return Status::error(Errc::kInvalidArgument, "config '%s' line %d: key '%s' set again (first set on line %d)",
                             name, line, key, key_line[k]);
      }
      key_line[k] = line;
    }
    long x = 0;
    if (!std::strcmp(key, "laser") || !std::strcmp(key, "laser_mount")) {
      FW_RETURN_IF_ERROR(parse_laser_key(name, line, key, v, out));
      seen_laser = seen_laser || !std::strcmp(key, "laser");
    } else if (!std::strcmp(key, "odometry")) {
      if (!spec_ok(v, false, "none")) return CFG_ERR("'%s' is not socketcan:IFACE or none", v);
      FW_RETURN_IF_ERROR(check_backend_arg(name, line, key, v, sizeof(out->odometry)));
      copy(out->odometry, sizeof(out->odometry), v);
    } else if (!std::strcmp(key, "output")) {
      if (!spec_ok(v, false, "log")) return CFG_ERR("'%s' is not socketcan:IFACE or log", v);
      FW_RETURN_IF_ERROR(check_backend_arg(name, line, key, v, sizeof(out->output)));
      copy(out->output, sizeof(out->output), v);
    } else if (!std::strcmp(key, "can_fd")) {
      bool b = false;
      if (!std::strcmp(v, "auto")) out->can_fd = -1;
      else if (parse_bool(v, &b)) out->can_fd = b ? 1 : 0;
      else return CFG_ERR("'%s' is not auto, true or false", v);
    } else if (!std::strcmp(key, "localizer")) {
      if (!is_known_localizer(v)) return CFG_ERR("'%s' unknown (%s)", v, kKnownLocalizers);
      copy(out->localizer, sizeof(out->localizer), v);
    } else if (!std::strcmp(key, "mml_preset")) {
      if (!parse_int(v, 1, 4, &x)) return CFG_ERR("'%s' is not a configuration 1..4 (Tables 5.1-5.4)", v);
      out->mml_preset = static_cast<int>(x);
    } else if (!std::strncmp(key, "map", 3)) {
      FW_RETURN_IF_ERROR(parse_map_key(name, line, key, v, out));
    } else if (!std::strcmp(key, "workers")) {
      if (!parse_int(v, 1, 16, &x)) return CFG_ERR("'%s' is not an integer in 1..16", v);
      out->workers = static_cast<int>(x);
    } else if (!std::strcmp(key, "cores")) {
      out->num_cores = 0;
      char* tok = v;
      while (tok && *tok) {
        char* comma = std::strchr(tok, ',');
        if (comma) *comma = '\0';
        while (*tok == ' ') ++tok;
        char* te = tok + std::strlen(tok);
        while (te > tok && te[-1] == ' ') *--te = '\0';
        if (out->num_cores >= AppConfig::kMaxCores) return CFG_ERR("more than %d cores", AppConfig::kMaxCores);
        if (!parse_int(tok, 0, 1023, &x)) return CFG_ERR("'%s' is not a CPU number 0..1023", tok);
        out->cores[out->num_cores++] = static_cast<int>(x);
        tok = comma ? comma + 1 : nullptr;
      }
    } else if (!std::strcmp(key, "realtime")) {
      if (!parse_bool(v, &out->realtime)) return CFG_ERR("'%s' is not true or false", v);
    } else if (!std::strcmp(key, "global_period_scans")) {
      if (!parse_int(v, 1, 8, &x)) return CFG_ERR("'%s' is not an integer in 1..8", v);
      out->global_period_scans = static_cast<std::uint32_t>(x);
    } else if (!std::strcmp(key, "global_context")) {
      if (!std::strcmp(v, "thread")) out->global_threaded = true;
      else if (!std::strcmp(v, "inline")) out->global_threaded = false;
      else return CFG_ERR("'%s' is not thread or inline", v);
    } else if (!std::strcmp(key, "arena_mib")) {
      if (!parse_int(v, 1, 4096, &x)) return CFG_ERR("'%s' is not an integer in 1..4096", v);
      out->arena_mib = static_cast<std::uint32_t>(x);
    } else if (!std::strcmp(key, "step_deadline_ms")) {
      char* pe = nullptr;
      const double d = std::strtod(v, &pe);
      if (pe == v || *pe || !std::isfinite(d) || d < 0.1 || d > 1000) return CFG_ERR("'%s' is not a number in 0.1..1000", v);
      out->step_deadline_ms = d;
    } else if (!std::strcmp(key, "health_period_ms")) {
      if (!parse_int(v, 10, 10000, &x)) return CFG_ERR("'%s' is not an integer in 10..10000", v);
      out->health_period_ms = static_cast<std::uint32_t>(x);
    } else if (!std::strcmp(key, "laser_timeout_ms")) {
      if (!parse_int(v, 10, 60000, &x)) return CFG_ERR("'%s' is not an integer in 10..60000", v);
      out->laser_timeout_ms = static_cast<std::uint32_t>(x);
    } else if (!std::strcmp(key, "seed")) {
      if (!parse_int(v, 0, 0x7FFFFFFF, &x)) return CFG_ERR("'%s' is not a non-negative integer", v);
      out->seed = static_cast<std::uint64_t>(x);
    } else if (!std::strncmp(key, "blackbox", 8)) {
      FW_RETURN_IF_ERROR(parse_blackbox_key(name, line, key, v, out));
    } else if (!std::strncmp(key, "odom_", 5)) {
      FW_RETURN_IF_ERROR(parse_odometry_key(name, line, key, v, out));
    } else if (!std::strcmp(key, "log_level")) {
      static const char* const kLevels[] = {"debug", "info", "warning", "error"};
      int lvl = -1;
      for (int i = 0; i < 4; ++i)
        if (!std::strcmp(v, kLevels[i])) lvl = i;
      if (lvl < 0) return CFG_ERR("'%s' is not debug, info, warning or error", v);
      out->log_level = lvl;
    } else {
      return Status::error(Errc::kInvalidArgument, "config '%s' line %d: unknown key '%s'", name, line, key);
    }
  }
  if (!seen_laser) return Status::error(Errc::kInvalidArgument, "config '%s': key 'laser' is required", name);
  if (out->num_cores > 0 && out->num_cores < out->workers) {
    return Status::error(Errc::kInvalidArgument, "config '%s': key 'cores' lists %d CPUs for %d workers", name,
                         out->num_cores, out->workers);
  }
  FW_RETURN_IF_ERROR(check_map_ids(name, *out));
  if (std::strcmp(out->localizer, "odom") && !out->map[0]) {
    return Status::error(Errc::kInvalidArgument, "config '%s': key 'map' is required for localizer '%s' (localizer = odom runs without a map)", name,
                         out->localizer);
  }
  return Status::ok();
}

Status load_app_config(const char* path, AppConfig* out) {
  static char text[16384];
  // O_NONBLOCK + a regular-file check: a FIFO or device given as the config must not block start-up.
  const int fd = ::open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    const int e = errno;
    return Status::error(Errc::kIoError, "config '%s': %s", path, strerror(e));
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return Status::error(Errc::kIoError, "config '%s': not a regular file", path);
  }
  std::size_t len = 0;
  for (;;) {
    const ssize_t n = ::read(fd, text + len, sizeof(text) - len);
    if (n < 0) {
      const int e = errno;
      ::close(fd);
      char name[kShownPath + 1];
      shown_path(path, name, sizeof(name));
      return Status::error(Errc::kIoError, "config '%s': read: %s", name, strerror(e));
    }
    if (n == 0) break;
    len += static_cast<std::size_t>(n);
    if (len == sizeof(text)) {
      ::close(fd);
      char name[kShownPath + 1];
      shown_path(path, name, sizeof(name));
      return Status::error(Errc::kCapacityExceeded, "config '%s': larger than %zu bytes", name, sizeof(text) - 1);
    }
  }
  ::close(fd);
  return parse_app_config(path, text, len, out);
}

}  // namespace fw
