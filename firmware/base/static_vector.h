// StaticVector<T, N>: a vector whose capacity is part of its type (ETL style). push_back on a
// full vector returns a status and writes nothing; checked indexing raises a fault.
#pragma once

#include <cstddef>
#include <new>
#include <type_traits>
#include <utility>

#include "firmware/base/fault.h"
#include "firmware/base/memory_report.h"
#include "firmware/base/status.h"

namespace fw {

template <typename T, std::size_t N>
class StaticVector {
  static_assert(N > 0, "StaticVector needs a positive capacity");

 public:
  using value_type = T;
  StaticVector() = default;
  StaticVector(const StaticVector& other) { copy_from(other); }
  StaticVector& operator=(const StaticVector& other) {
    if (this != &other) { clear(); copy_from(other); }
    return *this;
  }
  ~StaticVector() { clear(); }

  static constexpr std::size_t capacity() { return N; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  bool full() const { return size_ == N; }
  std::size_t high_water() const { return high_water_; }

  Status push_back(const T& v) {
    if (size_ == N) return Status::error(Errc::kCapacityExceeded, "StaticVector full (capacity %zu)", N);
    new (slot(size_)) T(v);
    bump();
    return Status::ok();
  }
  template <typename... Args>
  Status emplace_back(Args&&... args) {
    if (size_ == N) return Status::error(Errc::kCapacityExceeded, "StaticVector full (capacity %zu)", N);
    new (slot(size_)) T(std::forward<Args>(args)...);
    bump();
    return Status::ok();
  }
  void pop_back() {
    if (size_ == 0) { raise_fault(Fault::kIndexOutOfBounds); return; }
    --size_;
    slot(size_)->~T();
  }
  // Shrinks (never grows beyond capacity); growing default-constructs. Returns false if n > N.
  Status resize(std::size_t n) {
    if (n > N) return Status::error(Errc::kCapacityExceeded, "StaticVector resize to %zu > capacity %zu", n, N);
    while (size_ > n) pop_back();
    while (size_ < n) { new (slot(size_)) T(); bump(); }
    return Status::ok();
  }
  void clear() {
    if constexpr (!std::is_trivially_destructible_v<T>) {
      for (std::size_t i = 0; i < size_; ++i) slot(i)->~T();
    }
    size_ = 0;
  }

  T& operator[](std::size_t i) { check(i); return *slot(i); }
  const T& operator[](std::size_t i) const { check(i); return *slot(i); }
  T& back() { check(size_ - 1); return *slot(size_ - 1); }
  const T& back() const { check(size_ - 1); return *slot(size_ - 1); }
  T* data() { return slot(0); }
  const T* data() const { return slot(0); }
  T* begin() { return slot(0); }
  T* end() { return slot(size_); }
  const T* begin() const { return slot(0); }
  const T* end() const { return slot(size_); }

  // Registers capacity and high-water mark with the memory report (call at start-up).
  Status report_as(const char* module, const char* name) const {
    return MemoryReport::instance().add({module, name, sizeof(*this), N, &high_water_});
  }

 private:
  void check(std::size_t i) const {
    if (i >= size_) raise_fault(Fault::kIndexOutOfBounds);
  }
  void bump() {
    ++size_;
    if (size_ > high_water_) high_water_ = size_;
  }
  void copy_from(const StaticVector& other) {
    for (std::size_t i = 0; i < other.size_; ++i) new (slot(i)) T(*other.slot(i));
    size_ = other.size_;
    if (size_ > high_water_) high_water_ = size_;
  }
  T* slot(std::size_t i) { return std::launder(reinterpret_cast<T*>(storage_) + i); }
  const T* slot(std::size_t i) const { return std::launder(reinterpret_cast<const T*>(storage_) + i); }

  alignas(T) unsigned char storage_[sizeof(T) * N];
  std::size_t size_ = 0;
  std::size_t high_water_ = 0;
};

}  // namespace fw
