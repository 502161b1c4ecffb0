// Built-in worlds that need no files:
//  - "small-office": 20 × 12 m, one corridor, seven rooms (two alike, one with furniture that makes
//    it unique), an unmapped room (unknown area).
//  - "large-office": the dissertation's simulated scenario (Sec. 5.7.1, Fig. 5.6d): 81 × 47 m with
//    three long bare corridors of 81 m joined by three bare cross corridors, 72 rooms of which most
//    are identical (structural ambiguity), a pillared hall and a few furnished rooms that eventually
//    disambiguate, and an unmapped block of rooms (unknown area, Sec. 5.6).
//  - "corridor": a closed, bare 30 × 2 m corridor — symmetric, so no localizer can be sure.
#pragma once

#include <string>
#include <vector>

#include "sim/world/world.h"

namespace sim {

std::vector<std::string> builtin_world_names();
// False with *err naming the unknown world and listing the valid names.
bool make_builtin_world(const std::string& name, World* out, std::string* err);

}  // namespace sim
