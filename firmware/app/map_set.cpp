#include "firmware/app/map_set.h"

#include <time.h>

#include <new>

#include "firmware/base/memory_report.h"
#include "firmware/map/map_image.h"

namespace fw {
namespace {

// Memory report rows (static strings: the report keeps the pointers).
constexpr const char* kSlotNames[MapSet::kMaxMaps + 1] = {"map slot 0", "map slot 1", "map slot 2", "map slot 3",
                                                          "map slot 4"};
constexpr std::size_t kSlotAlignment = 64;

std::size_t round_up(std::size_t n, std::size_t to) { return (n + to - 1) / to * to; }

// A switch away from a map whose global thread still runs a job must wait for it: the worker pool
// is shared by every map's MML, and two global steps must never drive it at once. A job ends
// within its deadline (a few scan periods); 2 s is a broken thread, not a slow one.
Status wait_for_global_job(LocalizationSystem& sys) {
  track::TrackedLocalizer* t = sys.tracked();
  if (t == nullptr || !t->global_context().threaded()) return Status::ok();
  for (int i = 0; i < 2000 && t->global_context().job_in_flight(); ++i) {
    const timespec ms{0, 1000000};
    nanosleep(&ms, nullptr);
  }
  if (t->global_context().job_in_flight()) {
    return Status::error(Errc::kBusy, "the active map's global search did not finish its step within 2 s");
  }
  return Status::ok();
}

}  // namespace

MapSet::~MapSet() { stop_global_contexts(); }

Status MapSet::carve(Slot& s, StartupArena& arena, std::size_t bytes, int index) {
  Result<void*> r = arena.allocate(bytes, kSlotAlignment, kSlotNames[index]);
  if (!r) return r.status();
  s.block = *r;
  s.bytes = bytes;
  return s.arena.init(s.block, s.bytes, kSlotNames[index]);
}

// The map image (checked: size, CRC, version, sections; map_image.h), its relation table if any,
// and the system built on it, all in the slot's arena.
Status MapSet::load_into(Slot& s, int id, const char* path, WorkerPool* pool) {
  FW_RETURN_IF_ERROR(s.image.open(path));
  FW_RETURN_IF_ERROR(load_map_image(s.image.data(), s.image.size(), s.arena, &s.map, path));
  s.table = find_section(s.image.data(), s.image.size(), MapSectionType::kRelationTable2D, &s.table_len);
  s.image_had_table = s.table != nullptr;
  FW_RETURN_IF_ERROR(fresh_work_arena());
  const Status st = s.system.build(spec_, s.map, s.table, s.table_len, s.arena, pool, work_block_ ? &work_ : nullptr);
  if (work_.peak_used() > work_peak_) work_peak_ = work_.peak_used();
  if (!st) return Status::error(st.code(), "map %d '%s': %s", id, path, st.message());
  // The map lives in the arena now; the copy of the image stays only where MML reads its relation
  // table in place (only those pages are kept).
  if (s.table != nullptr && s.system.table_in_use()) {
    FW_RETURN_IF_ERROR(s.image.retain(s.table, s.table_len));
    s.table = s.image.data();
  } else {
    s.image.close();
    s.table = nullptr;
    s.table_len = 0;
  }
  if (log_ != nullptr) {
    log_->log(hal::LogLevel::kInfo, "mmlfw: map %d '%s' %ux%u cells at %.3f m, %u points%s", id, path,
              s.map.geometry.width, s.map.geometry.height, static_cast<double>(s.map.geometry.resolution),
              s.map.num_points, s.table != nullptr ? ", precomputed relation table" : "");
  }
  return Status::ok();
}

// Every build starts at the block's base: the maps' systems get the same working memory.
Status MapSet::fresh_work_arena() {
  if (work_block_ == nullptr) return Status::ok();
  work_.~StartupArena();
  new (&work_) StartupArena();
  FW_RETURN_IF_ERROR(work_.init(work_block_, work_bytes_, "shared work"));
  return Status::ok();
}

void MapSet::clear(Slot& s) {
  s.system.~LocalizationSystem();
  new (&s.system) LocalizationSystem();
  s.image.close();
  s.map = GlobalMap{};
  s.table = nullptr;
  s.table_len = 0;
  s.image_had_table = false;
  s.arena.~StartupArena();
  new (&s.arena) StartupArena();
}

Status MapSet::init(const MapSetSpec& spec, StartupArena& arena, WorkerPool* pool, hal::LogSink* log) {
  if (count_ != 0) return Status::error(Errc::kInvalidArgument, "maps: init called twice");
  if (spec.count < 1 || spec.count > kMaxMaps) {
    return Status::error(Errc::kInvalidArgument, "maps: %d maps (1..%d)", spec.count, kMaxMaps);
  }
  spec_ = spec.system;
  pool_ = pool;
  log_ = log;
  // Before the slots: the working memory every map's MML shares (sized by the config alone).
  work_bytes_ = round_up(LocalizationSystem::working_bytes(spec_), kSlotAlignment);
  if (work_bytes_ > 0) {
    Result<void*> w = arena.allocate(work_bytes_, kSlotAlignment, "maps' shared working memory");
    if (!w) return Status::error(w.status().code(), "maps: the shared working memory: %s", w.status().message());
    work_block_ = *w;
  }
  std::size_t largest = 0;
  for (int id = 0; id < spec.count; ++id) {
    if (spec.paths[id] == nullptr || !spec.paths[id][0]) {
      return Status::error(Errc::kInvalidArgument, "maps: map %d has no file", id);
    }
    paths_[id] = spec.paths[id];
    slot_of_[id] = id;
    Slot& s = slots_[id];
    // The slot takes what is left of the arena while its map and system are built, then keeps its
    // peak only (the next slot starts there): slots are as large as their maps need.
    const std::size_t mark = arena.mark();
    const std::size_t left = arena.capacity() - arena.used();
    if (left < 2 * kSlotAlignment) {
      return Status::error(Errc::kCapacityExceeded, "map %d '%s': the arena is full before this map (arena_mib)", id,
                           paths_[id]);
    }
    FW_RETURN_IF_ERROR(carve(s, arena, (left - kSlotAlignment) / kSlotAlignment * kSlotAlignment, id));
    FW_RETURN_IF_ERROR(load_into(s, id, paths_[id], pool));
    const std::size_t need = round_up(s.arena.peak_used(), kSlotAlignment);
    arena.rewind(mark);
    Result<void*> r = arena.allocate(need, kSlotAlignment, kSlotNames[id]);
    if (!r || *r != s.block) return Status::error(Errc::kInvalidArgument, "map %d: slot moved while carved", id);
    s.bytes = need;
    s.arena.seal();  // a map's slot never allocates again (a reload builds in the spare)
    // The slot's row says what it keeps (its arena registered the whole rest while it was built).
    FW_RETURN_IF_ERROR(MemoryReport::instance().add({kSlotNames[id], "startup arena", need, need, nullptr}));
    if (need > largest) largest = need;
    count_ = id + 1;
  }
  if (spec.reload) {
    spare_ = spec.count;
    const std::size_t bytes = round_up(largest + largest / 4, 4096);
    const Status st = carve(slots_[spare_], arena, bytes, spare_);
    if (!st) return Status::error(st.code(), "map_reload: the spare slot (%zu bytes): %s", bytes, st.message());

  }
  active_ = 0;
  // The last map built wrote the working memory last: map 0 starts on it wiped.
  if (count_ > 1) activate(0);
  return Status::ok();
}

// `id` becomes the active map, its localizer reset on wiped working memory (another map's MML has
// used it since). A threaded global search serves it from now on.
void MapSet::activate(std::uint8_t id) {
  active_ = id;
  LocalizationSystem& now = active();
  now.mark_working_memory_foreign();
  now.localizer().reset();
  if (threaded_ && now.tracked() != nullptr) global_thread_.serve(&now.tracked()->global_context());
}

void MapSet::set_global_record_sink(hal::GlobalRecordSink* sink) {
  record_sink_ = sink;
  for (int id = 0; id < count_; ++id) system(id).set_global_record_sink(sink);
}

Status MapSet::attach_global(LocalizationSystem& sys) {
  sys.set_global_record_sink(record_sink_);
  if (!threaded_) {
    if (sys.tracked() != nullptr) sys.tracked()->global_context().set_clock(clock_);
    return Status::ok();
  }
  return sys.attach_global_thread(&global_thread_, clock_, global_ctx_);
}

Status MapSet::start_global_contexts(bool threaded, bool realtime, const hal::Clock* clock,
                                     const ExecutionContext& context) {
  clock_ = clock;
  global_ctx_ = context;
  // The one global thread, created here at start-up: it serves the active map (a reloaded one too).
  if (threaded) FW_RETURN_IF_ERROR(global_thread_.start(context, realtime));
  threaded_ = threaded;
  for (int id = 0; id < count_; ++id) FW_RETURN_IF_ERROR(attach_global(system(id)));
  LocalizationSystem& now = active();
  if (threaded_ && now.tracked() != nullptr) global_thread_.serve(&now.tracked()->global_context());
  return Status::ok();
}

void MapSet::stop_global_contexts() {
  global_thread_.stop();  // after its job, if any; then the contexts let go of it
  for (Slot& s : slots_) s.system.stop_global_context();
  threaded_ = false;
}

std::size_t MapSet::table_copy_bytes() const {
  std::size_t n = 0;
  for (const Slot& s : slots_) n += s.table != nullptr ? s.image.mapped_bytes() : 0;
  return n;
}

Status MapSet::reload_into_spare(std::uint8_t id) {
  if (spare_ < 0) {
    return Status::error(Errc::kUnsupported, "map %u '%s': reload needs map_reload = true (a spare slot)", id, paths_[id]);
  }
  Slot& s = slots_[spare_];
  clear(s);
  FW_RETURN_IF_ERROR(s.arena.init(s.block, s.bytes, kSlotNames[spare_]));
  FW_RETURN_IF_ERROR(fresh_work_arena());  // its peak then says whether the build wrote it
  Status st = load_into(s, id, paths_[id], pool_);
  if (st) st = attach_global(s.system);  // no thread is created: the global one serves it once active
  if (!st) {
    clear(s);  // the spare keeps nothing of a failed reload
    // A build that got as far as MML wrote the shared working memory: the active map's search
    // starts again on it wiped (the map itself stays).
    const bool restarted = work_block_ != nullptr && work_.peak_used() > 0;
    if (restarted) activate(active_);
    // The loader's messages name the file; say what stays.
    return Status::error(st.code(), "reload of map %u refused, the loaded map stays%s: %s", id,
                         restarted ? " (its search restarted)" : "", st.message());
  }
  s.arena.seal();
  const int old = slot_of_[id];
  slot_of_[id] = spare_;
  spare_ = old;  // its system is dropped at the next reload
  ++reloads_;
  return Status::ok();
}

Result<Localizer*> MapSet::select(std::uint8_t id, bool reload) {
  if (id >= count_) {
    return Status::error(Errc::kNotFound, "map %u: no such map (%d loaded, ids 0..%d)", id, count_, count_ - 1);
  }
  LocalizationSystem& old = active();
  FW_RETURN_IF_ERROR(wait_for_global_job(old));
  if (reload) FW_RETURN_IF_ERROR(reload_into_spare(id));
  // The old map's state goes (its late global results are dropped by the reset's generation), and
  // the new one starts from nothing: the robot is somewhere on that map, not where it was.
  old.localizer().reset();
  activate(id);
  return &active().localizer();
}

}  // namespace fw
