// What a localizer factory of the simulator receives and returns: the run's map, seed, options and
// the optional hooks that expose internals to pictures. Shared by the simulator's registry
// (sim/cli/localizer_factory) and the factories that live with their evaluation harness
// (sim/eval/mml_eval); it sits below both so neither includes the other's folder the wrong way
// (layer rule: README "Layers").
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "firmware/base/se2.h"
#include "firmware/map/global_map.h"
#include "firmware/runtime/localizer.h"
#include "sim/io/ros_map.h"

namespace fw::track {
class GlobalContext;  // firmware/track/global_context.h
}  // namespace fw::track

namespace sim {

// One hypothesis as drawn in pictures (map frame); weight ∈ [0, 1] (e.g. normalised rating).
struct HypothesisPoint {
  double x = 0, y = 0, theta = 0, weight = 1;
};

// Optional views a factory may fill to expose localizer internals to the simulator. The hook is
// called after each step; it must not change the localizer's state.
struct LocalizerHooks {
  std::function<void(std::vector<HypothesisPoint>*)> hypotheses;
  // mml-track: its global context (the black box's global records, issue 60); null otherwise.
  std::function<fw::track::GlobalContext*()> global_context;
  // mml-track: why the track awaits MML's word (TrackedLocalizer::wait_cause; "none" when it does
  // not); null otherwise.
  std::function<const char*()> wait_cause;
};

struct LocalizerContext {
  // The global map: the compiled map image as the firmware loaded it (nullptr when the run has no
  // map, e.g. a log replay without --map), its bytes (for extra sections such as pRANSAM's relation
  // table) and the host grid it was built from.
  const fw::GlobalMap* global_map = nullptr;
  const std::vector<std::uint8_t>* map_image = nullptr;
  const OccupancyGrid* grid = nullptr;
  std::string map_name;
  std::uint64_t seed = 1;
  int threads = 1;
  // True start pose when known (synthetic worlds, logs with a reference). Only for baselines that
  // need an anchor (odom with anchor=truth); a global localizer must not look at it.
  bool has_true_start = false;
  fw::Se2d true_start;
  // --opt key=value pairs for the chosen localizer. A factory must reject keys it does not know.
  std::map<std::string, std::string> options;
  // Filled by the factory if it can expose hypotheses (may be nullptr).
  LocalizerHooks* hooks = nullptr;
};

using LocalizerFactoryFn =
    std::function<std::unique_ptr<fw::Localizer>(const LocalizerContext& ctx, std::string* err)>;

// Helper for factories: error text for option keys not in `known`, or empty.
std::string unknown_option_keys(const std::string& localizer, const std::map<std::string, std::string>& options,
                                const std::vector<std::string>& known);

}  // namespace sim
