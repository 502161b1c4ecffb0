#include "firmware/base/arena.h"

#include <sys/mman.h>

#include <cerrno>
#include <cstring>

#include "firmware/base/fault.h"

namespace fw {

StartupArena::~StartupArena() {
  MemoryReport::instance().remove(&used_);
  if (mapped_ && base_ != nullptr) munmap(base_, capacity_);
}

Status StartupArena::init(void* block, std::size_t bytes, const char* module) {
  if (base_ != nullptr) return Status::error(Errc::kInvalidArgument, "arena '%s': init called twice", module);
  if (block == nullptr || bytes == 0) {
    return Status::error(Errc::kInvalidArgument, "arena '%s': empty block", module);
  }
  base_ = static_cast<unsigned char*>(block);
  capacity_ = bytes;
  return MemoryReport::instance().add({module, "startup arena", bytes, bytes, &used_});
}

Status StartupArena::init_mapped(std::size_t bytes, bool lock_memory, const char* module) {
  if (base_ != nullptr) return Status::error(Errc::kInvalidArgument, "arena '%s': init called twice", module);
  if (bytes == 0) return Status::error(Errc::kInvalidArgument, "arena '%s': size 0", module);
  void* p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) {
    return Status::error(Errc::kIoError, "arena '%s': mmap of %zu bytes failed: %s", module, bytes, std::strerror(errno));
  }
  if (lock_memory && mlock(p, bytes) != 0) {
    // Not fatal: unprivileged hosts cannot lock; the caller logs the returned warning if it cares.
  }
  mapped_ = true;
  base_ = static_cast<unsigned char*>(p);
  capacity_ = bytes;
  return MemoryReport::instance().add({module, "startup arena (mmap)", bytes, bytes, &used_});
}

Result<void*> StartupArena::allocate(std::size_t bytes, std::size_t alignment, const char* what) {
  if (sealed_) {
    raise_fault(Fault::kArenaSealed);
    return Status::error(Errc::kCapacityExceeded, "arena sealed: refused %zu bytes for '%s' after start-up", bytes, what);
  }
  if (base_ == nullptr) return Status::error(Errc::kNotInitialized, "arena not initialised (allocating '%s')", what);
  if (alignment == 0 || (alignment & (alignment - 1)) != 0) {
    return Status::error(Errc::kInvalidArgument, "arena: alignment %zu for '%s' is not a power of two", alignment, what);
  }
  const std::uintptr_t start = reinterpret_cast<std::uintptr_t>(base_) + used_;
  const std::uintptr_t aligned = (start + alignment - 1) & ~(static_cast<std::uintptr_t>(alignment) - 1);
  const std::size_t pad = aligned - start;
  if (pad + bytes > capacity_ - used_) {
    return Status::error(Errc::kCapacityExceeded, "arena exhausted: '%s' needs %zu bytes, %zu of %zu left", what,
                         bytes, capacity_ - used_, capacity_);
  }
  used_ += pad + bytes;
  if (used_ > peak_) peak_ = used_;
  return reinterpret_cast<void*>(aligned);
}

}  // namespace fw
