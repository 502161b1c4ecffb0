// bench_ground: scripts/bench.sh ground → build/bench/ground.json (+ ground.md, ground.svg beside it):
// the grounding measurement with mml-ground's defaults. Without ../shared/data the real-log part is
// skipped with a SKIP note (ground_note) and the profiles are still measured; exit status 0.
#include <cstdio>
#include <string>

#include "sim/common/cli_main.h"
#include "sim/eval/grounding/ground_args.h"

int main(int argc, char** argv) {
  return sim::guarded_main("bench_ground", [&] {
    if (argc != 2) {
      std::fprintf(stderr, "usage: bench_ground OUT.json\n");
      return 2;
    }
    const std::string json = argv[1];
    const std::size_t slash = json.find_last_of('/');
    if (json.size() < 5 || json.substr(json.size() - 5) != ".json" ||
        json.substr(slash == std::string::npos ? 0 : slash + 1) != "ground.json") {
      std::fprintf(stderr, "bench_ground: the output must be named ground.json (got '%s')\n", json.c_str());
      return 2;
    }
    sim::ground::GroundArgs a;
    a.opt.progress = true;
    a.out_dir = slash == std::string::npos ? "." : json.substr(0, slash);
    return sim::ground::run_ground(a, "bench_ground");
  });
}
