// The host tools' error convention: a function that fails writes what went wrong (naming the input)
// to *error, when given, and returns false.
#pragma once

#include <string>

namespace sim {

inline bool fail(std::string* error, const std::string& msg) {
  if (error != nullptr) *error = msg;
  return false;
}

}  // namespace sim
