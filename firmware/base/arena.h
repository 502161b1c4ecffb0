// StartupArena: one block, sized once at start-up from the configuration, carved up by bump
// allocation while modules initialise, then sealed. After seal() every allocation is refused with
// a status and raises Fault::kArenaSealed: the steady state never allocates.
// The block comes from the caller (static storage) or from one anonymous mmap at init (a system
// call, not the heap; the firmware libraries never reference malloc/new — see the symbol check).
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>

#include "firmware/base/memory_report.h"
#include "firmware/base/result.h"

namespace fw {

class StartupArena {
 public:
  StartupArena() = default;
  StartupArena(const StartupArena&) = delete;
  StartupArena& operator=(const StartupArena&) = delete;
  ~StartupArena();

  // Uses caller-provided storage (e.g. a static array).
  Status init(void* block, std::size_t bytes, const char* module = "arena");
  // Maps `bytes` of anonymous memory once (optionally locked with mlock for real-time use).
  Status init_mapped(std::size_t bytes, bool lock_memory, const char* module = "arena");

  // Bump allocation with alignment; refused once sealed or when the block is exhausted.
  Result<void*> allocate(std::size_t bytes, std::size_t alignment, const char* what);

  // Allocates and value-initialises `count` objects of T.
  template <typename T>
  Result<T*> allocate_array(std::size_t count, const char* what) {
    Result<void*> r = allocate(sizeof(T) * count, alignof(T), what);
    if (!r) return r.status();
    T* p = static_cast<T*>(*r);
    for (std::size_t i = 0; i < count; ++i) new (p + i) T();
    return p;
  }

  // Start-up scratch, stack-like: note mark() before temporary allocations and rewind(mark) when they
  // are no longer needed (e.g. the map loader's distance-transform buffers); everything allocated
  // since the mark is forgotten, so only trivially destructible data belongs there. The capacity must
  // cover the peak (peak_used()), not just used().
  std::size_t mark() const { return used_; }
  void rewind(std::size_t mark) {
    if (!sealed_ && mark <= used_) used_ = mark;
  }
  std::size_t peak_used() const { return peak_; }

  void seal() { sealed_ = true; }
  bool sealed() const { return sealed_; }
  std::size_t capacity() const { return capacity_; }
  std::size_t used() const { return used_; }

 private:
  unsigned char* base_ = nullptr;
  std::size_t capacity_ = 0;
  std::size_t used_ = 0;
  std::size_t peak_ = 0;
  bool sealed_ = false;
  bool mapped_ = false;
};

}  // namespace fw
