// RingBuffer<T, N>: fixed-capacity FIFO. push on full returns a status (the caller decides to
// drop and count); push_overwrite drops the oldest element explicitly (for "last k" windows).
#pragma once

#include <cstddef>

#include "firmware/base/fault.h"
#include "firmware/base/memory_report.h"
#include "firmware/base/status.h"

namespace fw {

template <typename T, std::size_t N>
class RingBuffer {
  static_assert(N > 0, "RingBuffer needs a positive capacity");

 public:
  static constexpr std::size_t capacity() { return N; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  bool full() const { return size_ == N; }
  std::size_t high_water() const { return high_water_; }

  Status push(const T& v) {
    if (size_ == N) return Status::error(Errc::kCapacityExceeded, "RingBuffer full (capacity %zu)", N);
    items_[(head_ + size_) % N] = v;
    bump();
    return Status::ok();
  }
  // Pushes, dropping the oldest element when full. Returns true if one was dropped.
  bool push_overwrite(const T& v) {
    if (size_ == N) {
      items_[head_] = v;
      head_ = (head_ + 1) % N;
      return true;
    }
    items_[(head_ + size_) % N] = v;
    bump();
    return false;
  }
  // Pops the oldest element into *out; false when empty.
  bool pop(T* out) {
    if (size_ == 0) return false;
    *out = items_[head_];
    head_ = (head_ + 1) % N;
    --size_;
    return true;
  }
  // i = 0 is the oldest element.
  const T& operator[](std::size_t i) const {
    if (i >= size_) raise_fault(Fault::kIndexOutOfBounds);
    return items_[(head_ + i) % N];
  }
  T& operator[](std::size_t i) {
    if (i >= size_) raise_fault(Fault::kIndexOutOfBounds);
    return items_[(head_ + i) % N];
  }
  const T& newest() const { return (*this)[size_ - 1]; }
  void clear() { head_ = 0; size_ = 0; }

  Status report_as(const char* module, const char* name) const {
    return MemoryReport::instance().add({module, name, sizeof(*this), N, &high_water_});
  }

 private:
  void bump() {
    ++size_;
    if (size_ > high_water_) high_water_ = size_;
  }
  T items_[N] = {};
  std::size_t head_ = 0;
  std::size_t size_ = 0;
  std::size_t high_water_ = 0;
};

}  // namespace fw
