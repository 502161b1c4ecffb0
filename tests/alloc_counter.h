// Allocation counter for the zero-heap-after-init proof: this library interposes operator new /
// delete (all overloads) and glibc's malloc family, and counts calls from every thread while
// counting is enabled. Link `mmlfw_alloc_counter` into a test; call begin() after init and
// end() after the steady-state run; end() returns the number of heap allocations in between.
// Not usable under ASan/TSan (they own malloc); tests skip there.
#pragma once

#include <cstddef>

namespace mmlfw_test {

struct AllocCounter {
  static void begin();
  // Stops counting; returns allocations (new + malloc family) since begin().
  static long end();
  static long bytes();  // bytes requested since begin()
  static bool available();  // false under sanitizers
};

}  // namespace mmlfw_test
