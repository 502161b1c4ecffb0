// GlobalRecord (issue 60): when the tracker took a result of the global search (MML) running on its
// own thread. With global_context = thread the scan at which a result comes back depends on the
// wall clock, and so does pRANSAM's iteration count (deadline mode); the black box keeps one record
// per finished global job, so a replay can run the job inline and hand its result over at the same
// scan (hal/can/README.md "Black box"). Scans are named by their time stamps (µs kept).
#pragma once

#include <cstdint>

namespace hal {

struct GlobalRecord {
  std::uint64_t scan_ns = 0;      // the scan step at which the result was taken (or dropped)
  std::uint64_t job_scan_ns = 0;  // the scan the job was submitted with (the scan MML consumed)
  // pRANSAM rounds run when its deadline stopped the search (0: it ran to I_max or Ω_thres).
  std::uint32_t deadline_rounds = 0;
  bool dropped = false;  // a reset came between submission and result: thrown away, not taken
};

}  // namespace hal
