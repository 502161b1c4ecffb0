// gtest main for every test binary: a raised fault bit is fatal in tests ("bad programming" must
// never pass silently). Tests that provoke a fault on purpose swap the handler locally.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

#include "firmware/base/fault.h"

namespace {
void fatal_fault(fw::Fault fault, std::uint32_t bits) {
  std::fprintf(stderr, "FATAL: firmware fault '%s' raised (bits 0x%x)\n", fw::fault_name(fault), bits);
  std::abort();
}
}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  fw::set_fault_handler(&fatal_fault);
  return RUN_ALL_TESTS();
}
