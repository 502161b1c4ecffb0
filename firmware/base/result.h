// Result<T>: a value or a Status (an `expected` without exceptions or heap).
#pragma once

#include <new>
#include <type_traits>
#include <utility>

#include "firmware/base/fault.h"
#include "firmware/base/status.h"

namespace fw {

template <typename T>
class Result {
 public:
  Result(const T& value) : has_value_(true) { new (&storage_) T(value); }  // NOLINT implicit
  Result(T&& value) : has_value_(true) { new (&storage_) T(std::move(value)); }  // NOLINT
  Result(const Status& status) : has_value_(false), status_(status) {  // NOLINT implicit
    if (status.is_ok()) {
      // An ok status without a value is a programming error.
      raise_fault(Fault::kLogicError);
      status_ = Status::error(Errc::kInvalidArgument, "Result built from ok status without value");
    }
  }
  Result(const Result& other) : has_value_(other.has_value_), status_(other.status_) {
    if (has_value_) new (&storage_) T(other.value());
  }
  Result& operator=(const Result& other) {
    if (this != &other) {
      destroy();
      has_value_ = other.has_value_;
      status_ = other.status_;
      if (has_value_) new (&storage_) T(other.value());
    }
    return *this;
  }
  ~Result() { destroy(); }

  bool has_value() const { return has_value_; }
  bool is_ok() const { return has_value_; }
  explicit operator bool() const { return has_value_; }
  const Status& status() const { return status_; }

  T& value() {
    if (!has_value_) raise_fault(Fault::kLogicError);
    return *std::launder(reinterpret_cast<T*>(&storage_));
  }
  const T& value() const {
    if (!has_value_) raise_fault(Fault::kLogicError);
    return *std::launder(reinterpret_cast<const T*>(&storage_));
  }
  T& operator*() { return value(); }
  const T& operator*() const { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

 private:
  void destroy() {
    if (has_value_) value().~T();
    has_value_ = false;
  }
  alignas(T) unsigned char storage_[sizeof(T)];
  bool has_value_;
  Status status_;
};

}  // namespace fw
