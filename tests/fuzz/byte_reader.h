// ByteReader: takes fields front to back from a fuzz input (LLVMFuzzerTestOneInput's bytes), so
// the seed generator (fuzz_seeds.cpp) can write inputs in the same layout with ByteWriter.
// libFuzzer's FuzzedDataProvider takes integers from the end, which makes seeds awkward to write.
// Reading past the end yields zeros and sets exhausted(): a harness stops at that point.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace fuzz {

class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool exhausted() const { return pos_ >= size_; }
  std::size_t remaining() const { return size_ - pos_; }
  std::uint8_t u8() { return pos_ < size_ ? data_[pos_++] : 0; }
  std::uint16_t u16() { return static_cast<std::uint16_t>(u8() | (u8() << 8)); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(u16()) | (static_cast<std::uint32_t>(u16()) << 16); }
  std::uint64_t u64() { return static_cast<std::uint64_t>(u32()) | (static_cast<std::uint64_t>(u32()) << 32); }
  float f32() {
    const std::uint32_t b = u32();
    float f;
    std::memcpy(&f, &b, sizeof f);
    return f;
  }
  // Up to n bytes (fewer at the end of the input).
  void bytes(std::uint8_t* out, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) out[i] = u8();
  }
  // A length-prefixed (u16) blob.
  std::vector<std::uint8_t> blob() {
    const std::size_t n = u16();
    const std::size_t k = n < remaining() ? n : remaining();
    std::vector<std::uint8_t> v(data_ + pos_, data_ + pos_ + k);
    pos_ += k;
    return v;
  }
  // Everything that is left.
  std::vector<std::uint8_t> rest() {
    std::vector<std::uint8_t> v(data_ + pos_, data_ + size_);
    pos_ = size_;
    return v;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

class ByteWriter {
 public:
  void u8(std::uint8_t v) { out_.push_back(v); }
  void u16(std::uint16_t v) { u8(v & 0xFF); u8(v >> 8); }
  void u32(std::uint32_t v) { u16(v & 0xFFFF); u16(v >> 16); }
  void u64(std::uint64_t v) { u32(static_cast<std::uint32_t>(v)); u32(static_cast<std::uint32_t>(v >> 32)); }
  void f32(float f) {
    std::uint32_t b;
    std::memcpy(&b, &f, sizeof b);
    u32(b);
  }
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const std::uint8_t*>(p);
    out_.insert(out_.end(), b, b + n);
  }
  void blob(const std::vector<std::uint8_t>& v) {
    u16(static_cast<std::uint16_t>(v.size()));
    bytes(v.data(), v.size());
  }
  const std::vector<std::uint8_t>& data() const { return out_; }

 private:
  std::vector<std::uint8_t> out_;
};

}  // namespace fuzz
