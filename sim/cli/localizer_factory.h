// Localizer registry of the simulator: maps a name given on the command line (`--localizer odom`)
// to a fw::Localizer built for the run's map. Owners of a localizer add one entry to the table in
// localizer_factory.cpp (or call register_localizer before the run): "odom" here; "mml", "mcl" and
// "handoff" by their owners.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "sim/localizers/localizer_context.h"

namespace sim {

// nullptr with *err naming the unknown localizer (and listing the known ones) or the bad option.
std::unique_ptr<fw::Localizer> make_localizer(const std::string& name, const LocalizerContext& ctx, std::string* err);

struct LocalizerInfo {
  std::string name, description;
};
std::vector<LocalizerInfo> localizer_names();

// Adds (or replaces) a localizer at run time; used by tests and by owners before their entry is in
// the built-in table.
void register_localizer(const std::string& name, const std::string& description, LocalizerFactoryFn fn);

}  // namespace sim
