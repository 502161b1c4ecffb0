// Fault bits for "cannot happen" conditions (ArduPilot's internal-error idea): bad luck is a
// Status plus a counter; bad programming raises a fault bit. The handler is fatal in tests and
// in the simulator; on the robot the bit is published in the health frame.
#pragma once

#include <cstdint>

namespace fw {

enum class Fault : std::uint32_t {
  kLogicError = 1u << 0,        // an invariant was violated (e.g. value() of an error Result)
  kIndexOutOfBounds = 1u << 1,  // a checked container index was out of range
  kPoolCorrupt = 1u << 2,       // freeing a block that is not from the pool / double free
  kArenaSealed = 1u << 3,       // allocation attempted after start-up sealed the arena
  kHeapAfterInit = 1u << 4,     // heap allocation detected after init (tests/sim only)
  kThreading = 1u << 5,         // worker pool misuse (e.g. nested run)
  kNumerical = 1u << 6,         // NaN where the math guarantees a number
};

// Bits 16..31 of the published fault word are hal::HealthFault (sensor/link faults such as
// laser-timeout, hal/msg/health.h): they are bad luck, set and cleared by the runtime, never raised here.
constexpr std::uint32_t kInternalFaultMask = 0x0000FFFFu;

using FaultHandler = void (*)(Fault fault, std::uint32_t all_bits);

// Sets the bit (atomic) and calls the handler if one is installed.
void raise_fault(Fault fault);
std::uint32_t fault_bits();
void clear_faults();
// Installs a handler (tests install one that aborts); returns the previous one.
FaultHandler set_fault_handler(FaultHandler handler);
const char* fault_name(Fault fault);

}  // namespace fw
