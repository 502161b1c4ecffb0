// MapSet (issue 60, several maps): the maps mmlfw loads at start-up — one per floor or site, ids
// 0..count-1 — each with its own localization system, and SELECT_MAP's switch between them.
//
// Why one system per map (and not one system rebuilt at each switch): a system is built from its
// map at start-up (pRANSAM's relation table filled or read from the image, the unmapped-space
// labels, the distance fields, MML's fixed arrays sized to the map); rebuilding it at a switch
// would take the start-up's seconds and allocations in the middle of a lift ride. So every map
// gets a slot of the start-up arena holding its GlobalMap and what its system derives from it,
// built once; a switch is a pointer swap and a reset (microseconds).
//
// Shared working memory: most of MML's memory is working memory sized by the config, not by the
// map (RBSM's end-point grid, pRANSAM's R_A and worker buffers, ...: MmlLocalizer::init's `work`),
// and only the active map's MML runs. So it is one block of the start-up arena, carved once before
// the slots (sized by LocalizationSystem::working_bytes) and given to every map's system; a
// switch tells the new map's MML that another one wrote it (mark_working_memory_foreign) and
// resets it, so its search starts on wiped memory. The slots keep only the per-map parts.
//
// Global search on a thread (global_context = thread): one `global` thread, created and pinned at
// start-up, serves whichever map is active (GlobalThread::serve); a switch first waits for the old
// map's running global step (it also shares the worker pool and the working memory).
//
// Reload (config map_reload = true): one spare slot, as large as the largest map's slot plus 25 %,
// receives a map's image read from disk again. It is checked (size, CRC, version, every section:
// map_image.h) and its system built in the spare (attached to the global thread when there is
// one: no thread is created); only when all of that succeeded does the spare become that map's
// slot (and the old slot the spare). A missing, truncated or corrupt file, or a map too large for
// the spare, leaves every map as it was and the error names the file and the problem; a build that
// failed after it had written the shared working memory also restarts the active map's search. A
// reload rebuilds a system, so it takes start-up time (seconds on a large map) in the sensor context.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/app/system.h"
#include "firmware/base/arena.h"
#include "firmware/map/global_map.h"
#include "firmware/map/map_image_file.h"
#include "firmware/runtime/map_selector.h"
#include "firmware/track/global_thread.h"
#include "hal/clock.h"
#include "hal/log_sink.h"

namespace fw {

struct MapSetSpec {
  static constexpr int kMaxMaps = 4;
  const char* paths[kMaxMaps] = {};  // map ids 0..count-1
  int count = 0;
  bool reload = false;               // keep a spare slot for SELECT_MAP reload
  SystemSpec system;                 // the same localizer on every map
};

class MapSet : public MapSelector {
 public:
  static constexpr int kMaxMaps = MapSetSpec::kMaxMaps;
  MapSet() = default;
  MapSet(const MapSet&) = delete;
  MapSet& operator=(const MapSet&) = delete;
  ~MapSet() override;

  // Start-up: every map into its own slot carved from `arena`, its system built there; map 0 active.
  // Errors name the map (id and file) and the problem. `log` (may be null) gets one line per map.
  Status init(const MapSetSpec& spec, StartupArena& arena, WorkerPool* pool, hal::LogSink* log);
  // mml-track with the global search on a thread: one, started here at start-up, serving the
  // active map (a reloaded map too). Inline: `clock` times the global steps.
  Status start_global_contexts(bool threaded, bool realtime, const hal::Clock* clock, const ExecutionContext& context);
  void stop_global_contexts();
  // Every map's global context records its results here (the black box, issue 60), a map
  // reloaded later too. Sensor context (start-up).
  void set_global_record_sink(hal::GlobalRecordSink* sink);

  Result<Localizer*> select(std::uint8_t id, bool reload) override;
  std::uint8_t active_id() const override { return active_; }

  int count() const { return count_; }
  LocalizationSystem& active() { return slots_[slot_of_[active_]].system; }
  const LocalizationSystem& active() const { return slots_[slot_of_[active_]].system; }
  LocalizationSystem& system(int id) { return slots_[slot_of_[id]].system; }
  const GlobalMap& map(int id) const { return slots_[slot_of_[id]].map; }
  const char* path(int id) const { return paths_[id]; }
  // The image has a precomputed relation table section (used in place or not).
  bool has_table(int id) const { return slots_[slot_of_[id]].image_had_table; }
  // Bytes of map `id`'s slot (its map, scratch peak and localizer) and of the spare (0 = none).
  std::size_t slot_bytes(int id) const { return slots_[slot_of_[id]].bytes; }
  std::size_t spare_bytes() const { return spare_ >= 0 ? slots_[spare_].bytes : 0; }
  // Bytes of the working memory the maps' systems share (0 = none: no MML), and its peak use.
  std::size_t shared_work_bytes() const { return work_bytes_; }
  std::size_t shared_work_peak() const { return work_peak_; }
  // Image copies kept because a relation table is read in place (whole pages), all maps.
  std::size_t table_copy_bytes() const;
  std::uint32_t reloads() const { return reloads_; }

 private:
  struct Slot {
    StartupArena arena;       // a block of the start-up arena
    void* block = nullptr;
    std::size_t bytes = 0;
    MapImageFile image;       // kept only while its relation table is read in place
    GlobalMap map{};
    const std::uint8_t* table = nullptr;
    std::size_t table_len = 0;
    bool image_had_table = false;
    LocalizationSystem system;
  };
  Status load_into(Slot& s, int id, const char* path, WorkerPool* pool);
  Status fresh_work_arena();
  Status attach_global(LocalizationSystem& sys);
  void activate(std::uint8_t id);
  Status carve(Slot& s, StartupArena& arena, std::size_t bytes, int index);
  void clear(Slot& s);
  Status reload_into_spare(std::uint8_t id);

  Slot slots_[kMaxMaps + 1];
  int slot_of_[kMaxMaps] = {};  // map id → slot index
  int spare_ = -1;
  int count_ = 0;
  std::uint8_t active_ = 0;
  const char* paths_[kMaxMaps] = {};
  SystemSpec spec_;
  WorkerPool* pool_ = nullptr;
  hal::LogSink* log_ = nullptr;
  bool threaded_ = false;
  std::uint32_t reloads_ = 0;
  // The shared working memory: one block of the start-up arena; each build starts at its base.
  StartupArena work_;
  void* work_block_ = nullptr;
  std::size_t work_bytes_ = 0, work_peak_ = 0;
  // The one global thread (threaded_) and what a system attached to it needs.
  track::GlobalThread global_thread_;
  const hal::Clock* clock_ = nullptr;
  ExecutionContext global_ctx_ = kGlobalContext;
  hal::GlobalRecordSink* record_sink_ = nullptr;
};

}  // namespace fw
