// The main() of every host tool in sim/: the tool's body runs inside guarded_main, which turns any C++
// exception that escapes it (std::bad_alloc, std::filesystem::filesystem_error, std::ios_base::failure,
// …) into "TOOL: what happened" on stderr and exit status 1 instead of std::terminate's abort and core
// dump. Exceptions escaping a thread cannot be caught here; the terminate handler installed by
// guarded_main reports those the same way and exits with status 70 (EX_SOFTWARE) instead of aborting.
// Firmware faults ("bad programming", fw::raise_fault) are not exceptions and keep their own policy.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <new>

namespace sim {

namespace detail {
inline const char*& cli_tool_name() {
  static const char* name = "tool";
  return name;
}
[[noreturn]] inline void cli_terminate() {
  const char* tool = cli_tool_name();
  if (std::exception_ptr e = std::current_exception()) {
    try {
      std::rethrow_exception(e);
    } catch (const std::exception& ex) {
      std::fprintf(stderr, "%s: fatal: uncaught exception: %s\n", tool, ex.what());
    } catch (...) {
      std::fprintf(stderr, "%s: fatal: uncaught exception of unknown type\n", tool);
    }
  } else {
    std::fprintf(stderr, "%s: fatal: std::terminate called\n", tool);
  }
  std::fflush(stderr);
  std::_Exit(70);
}
}  // namespace detail

template <typename Body>
int guarded_main(const char* tool, Body&& body) {
  detail::cli_tool_name() = tool;
  std::set_terminate(&detail::cli_terminate);
  try {
    return body();
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "%s: out of memory\n", tool);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", tool, e.what());
  } catch (...) {
    std::fprintf(stderr, "%s: unknown exception\n", tool);
  }
  return 1;
}

}  // namespace sim
