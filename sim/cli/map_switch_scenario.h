// A robot riding a lift (issue 60, several maps): it is switched on in one simulated world (floor
// A), localizes there, then is carried to another world (floor B) while the operator sends
// SELECT_MAP for B. Both maps are compiled to map image files and loaded by the firmware's MapSet
// (firmware/app/map_set.h) as mmlfw loads them; the commands go through the firmware's
// CommandHandler, the scans straight to the active map's localizer (mml-track, the reference
// schedule: deterministic). Used by bench_ops (map_switch_*) and map_switch_test.
#pragma once

#include <cstdint>
#include <string>

#include "hal/msg/command.h"

namespace sim {

struct MapSwitchOptions {
  std::string world_a = "small-office";
  std::string world_b = "large-office";  // (the corridor is symmetric: no fix, by design)
  std::string dir;                 // map images a.mmap, b.mmap are written here
  std::size_t scans_a = 80;        // on floor A before the lift
  std::size_t scans_b = 150;       // on floor B after SELECT_MAP
  std::uint64_t seed = 1;
  bool reload_slot = false;        // config map_reload = true (a spare slot)
  // global_context = thread (the live schedule, one global thread for every map) instead of the
  // inline reference schedule. The scenario waits for each global step before the next scan (a
  // board whose global steps all finish within their window), so the run does not depend on timing.
  bool threaded_global = false;
  // After scans_b: the robot rides back to floor A and SELECT_MAP 0 with reload reads A's good
  // image again (built in the spare slot), then this many scans of a new run on A; the corrupt
  // reload of B below then happens with A in use (and the scans after it are A's).
  std::size_t scans_after_reload = 0;
  // After scans_b: the image of B is corrupted on disk and a SELECT_MAP 1 with reload sent, then
  // `scans_after_corrupt` more scans on B (the old map must stay active and localizing).
  std::size_t scans_after_corrupt = 0;
  // Called right before the SELECT_MAP and after B's last scan (before the corrupt file): a test
  // counts heap allocations in between (tests/alloc_counter.h; sim/ never includes tests/).
  void (*before_switch)() = nullptr;
  long (*after_b)() = nullptr;
};

struct MapSwitchResult {
  bool localized_on_a = false;     // a `localized` pose on A before the lift
  long integrity_failures_a = 0;
  hal::CommandResult switch_reply = hal::CommandResult::kMalformed;
  long scans_to_localized = -1;    // after SELECT_MAP, the first `localized` scan on B counts 1
  double seconds_to_localized = -1;  // robot time from SELECT_MAP to that scan
  double steps_cpu_s = 0;          // CPU time of B's steps up to that scan
  double select_cpu_s = 0;         // CPU time of the switch itself (SELECT_MAP carried out)
  long integrity_failures = 0;     // `localized` on B beyond 0.5 m / 5° (incl. after the corrupt reload)
  long localized_steps_b = 0;
  hal::CommandResult corrupt_reply = hal::CommandResult::kMalformed;
  std::string corrupt_message;     // the error of the refused reload
  long localized_after_corrupt = 0;
  std::uint8_t active_after_corrupt = 255;
  long allocations = -1;           // what after_b returned, -1 = not counted
  hal::CommandResult reload_reply = hal::CommandResult::kMalformed;  // the good reload
  long localized_after_reload = 0;
  std::uint32_t reloads = 0;       // MapSet::reloads() at the end
  std::size_t shared_work_bytes = 0;
  std::size_t slot_bytes_a = 0, slot_bytes_b = 0;
};

// Compiles a built-in world's map (as mml-sim draws it) into a map image file.
bool write_world_map_image(const std::string& world, const std::string& path, std::string* err);
bool run_map_switch(const MapSwitchOptions& opt, MapSwitchResult* out, std::string* err);

}  // namespace sim
