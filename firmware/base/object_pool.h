// ObjectPool<T, N>: N slots of T with an intrusive free list; acquire/release in O(1), no heap.
// Empty pool => status. Releasing a pointer that is not ours, or twice, raises a fault.
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>
#include <utility>

#include "firmware/base/fault.h"
#include "firmware/base/memory_report.h"
#include "firmware/base/result.h"

namespace fw {

template <typename T, std::size_t N>
class ObjectPool {
  static_assert(N > 0 && N < 0xFFFFFFFFu, "ObjectPool capacity out of range");

 public:
  ObjectPool() {
    for (std::size_t i = 0; i < N; ++i) {
      next_[i] = static_cast<std::uint32_t>(i + 1);
      used_[i] = false;
    }
    free_head_ = 0;
  }
  ObjectPool(const ObjectPool&) = delete;
  ObjectPool& operator=(const ObjectPool&) = delete;
  ~ObjectPool() {
    for (std::size_t i = 0; i < N; ++i) {
      if (used_[i]) slot(i)->~T();
    }
  }

  static constexpr std::size_t capacity() { return N; }
  std::size_t in_use() const { return in_use_; }
  std::size_t high_water() const { return high_water_; }

  template <typename... Args>
  Result<T*> acquire(Args&&... args) {
    if (free_head_ == kEnd) {
      return Status::error(Errc::kCapacityExceeded, "ObjectPool exhausted (capacity %zu)", N);
    }
    const std::uint32_t i = free_head_;
    free_head_ = next_[i];
    used_[i] = true;
    ++in_use_;
    if (in_use_ > high_water_) high_water_ = in_use_;
    return new (slot(i)) T(std::forward<Args>(args)...);
  }

  void release(T* p) {
    const std::uintptr_t base = reinterpret_cast<std::uintptr_t>(storage_);
    const std::uintptr_t addr = reinterpret_cast<std::uintptr_t>(p);
    if (addr < base || addr >= base + sizeof(storage_) || (addr - base) % sizeof(T) != 0) {
      raise_fault(Fault::kPoolCorrupt);
      return;
    }
    const std::size_t i = (addr - base) / sizeof(T);
    if (!used_[i]) {
      raise_fault(Fault::kPoolCorrupt);
      return;
    }
    p->~T();
    used_[i] = false;
    next_[i] = free_head_;
    free_head_ = static_cast<std::uint32_t>(i);
    --in_use_;
  }

  Status report_as(const char* module, const char* name) const {
    return MemoryReport::instance().add({module, name, sizeof(*this), N, &high_water_});
  }

 private:
  static constexpr std::uint32_t kEnd = static_cast<std::uint32_t>(N);
  T* slot(std::size_t i) { return std::launder(reinterpret_cast<T*>(storage_) + i); }

  alignas(T) unsigned char storage_[sizeof(T) * N];
  std::uint32_t next_[N];
  bool used_[N];
  std::uint32_t free_head_ = 0;
  std::size_t in_use_ = 0;
  std::size_t high_water_ = 0;
};

}  // namespace fw
