#include "firmware/base/fault.h"

#include <atomic>

namespace fw {
namespace {
std::atomic<std::uint32_t> g_fault_bits{0};
std::atomic<FaultHandler> g_handler{nullptr};
}  // namespace

void raise_fault(Fault fault) {
  const std::uint32_t bits =
      g_fault_bits.fetch_or(static_cast<std::uint32_t>(fault), std::memory_order_relaxed) |
      static_cast<std::uint32_t>(fault);
  FaultHandler handler = g_handler.load(std::memory_order_acquire);
  if (handler != nullptr) handler(fault, bits);
}

std::uint32_t fault_bits() { return g_fault_bits.load(std::memory_order_relaxed); }
void clear_faults() { g_fault_bits.store(0, std::memory_order_relaxed); }

FaultHandler set_fault_handler(FaultHandler handler) {
  return g_handler.exchange(handler, std::memory_order_acq_rel);
}

const char* fault_name(Fault fault) {
  switch (fault) {
    case Fault::kLogicError: return "logic-error";
    case Fault::kIndexOutOfBounds: return "index-out-of-bounds";
    case Fault::kPoolCorrupt: return "pool-corrupt";
    case Fault::kArenaSealed: return "arena-sealed";
    case Fault::kHeapAfterInit: return "heap-after-init";
    case Fault::kThreading: return "threading";
    case Fault::kNumerical: return "numerical";
  }
  return "unknown";
}

}  // namespace fw
