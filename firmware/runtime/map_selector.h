// MapSelector (issue 60, several maps): what SELECT_MAP needs of the firmware's maps — a localizer
// per loaded map, switched by id, and a checked re-read of a map's image from disk. The app's
// MapSet (firmware/app/map_set.h) implements it; the command handler only calls it, between two
// steps of the loop (the sensor context), so a switch never races a step.
#pragma once

#include <cstdint>

#include "firmware/base/result.h"
#include "firmware/runtime/localizer.h"

namespace fw {

class MapSelector {
 public:
  virtual ~MapSelector() = default;
  // Makes map `id` the active one and returns its localizer, reset (nothing `localized` survives
  // a switch). reload: its image is read from disk again and checked first; a missing or broken
  // file leaves every map as it was. Errors: kNotFound (no map `id`), kCorruptData / kIoError (the
  // image: the message names the file and the problem), kUnsupported, kCapacityExceeded.
  virtual Result<Localizer*> select(std::uint8_t id, bool reload) = 0;
  virtual std::uint8_t active_id() const = 0;
};

}  // namespace fw
