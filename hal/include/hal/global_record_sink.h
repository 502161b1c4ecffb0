// GlobalRecordSink (issue 60): where the firmware's global context reports each result of a
// threaded global search it took or dropped (hal/msg/global_record.h) — the black box on a robot
// (hal_can/black_box.h). Called from the sensor context only; must not allocate or block.
#pragma once

#include "hal/msg/global_record.h"

namespace hal {

class GlobalRecordSink {
 public:
  virtual void record_global(const GlobalRecord& record) = 0;

 protected:
  ~GlobalRecordSink() = default;
};

}  // namespace hal
