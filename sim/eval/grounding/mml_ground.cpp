// mml-ground: the grounding measurement of the world generator's profiles (issue 55, item 6).
#include <cstdio>
#include <string>
#include <vector>

#include "sim/common/cli_main.h"
#include "sim/eval/grounding/ground_args.h"

int main(int argc, char** argv) {
  return sim::guarded_main("mml-ground", [&] {
    sim::ground::GroundArgs a;
    a.opt.progress = true;
    std::string err;
    if (!sim::ground::parse_ground_args(std::vector<std::string>(argv + 1, argv + argc), &a, &err)) {
      std::fprintf(stderr, "mml-ground: %s\n", err.c_str());
      return 2;
    }
    if (a.help) {
      std::fputs(sim::ground::kGroundUsage, stdout);
      return 0;
    }
    return sim::ground::run_ground(a, "mml-ground");
  });
}
