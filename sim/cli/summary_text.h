// Phrases that tell a run's summary in words: the summary line and story of mml-sim and the notes
// of its picture share them.
#pragma once

#include <string>

#include "sim/cli/sim_runner.h"

namespace sim {

// printf into a std::string (up to 511 characters).
std::string fmt(const char* f, ...) __attribute__((format(printf, 1, 2)));

std::string final_error_text(const SimSummary& s);
std::string availability_text(const SimSummary& s);
std::string pl_text(const SimSummary& s);
std::string kidnap_text(const SimSummary& s);
// " + N not judged (…)": beyond the integrity limits only against the log reference (empty when none).
std::string truth_bound_text(const SimSummary& s);
// One clause for a run through a transport with bytes (empty for none).
std::string transport_text(const SimSummary& s);

}  // namespace sim
