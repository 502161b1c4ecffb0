// scripts/bench.sh corpus (issue 55): mml-track on the generated corpus, build/bench/corpus.json.
// The seed is MMLFW_CORPUS_SEED (default 1010: the published figures' seed, never tuned on; README of
// this folder lists which seeds have been read), the size MMLFW_CORPUS_RUNS (default 260: over
// 100,000 `localized` steps), both also written into the JSON.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "sim/cli/corpus/corpus_runner.h"

namespace {
std::uint64_t env_or(const char* name, std::uint64_t fallback) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return fallback;
  char* end = nullptr;
  const unsigned long long x = std::strtoull(v, &end, 10);
  if (*end != '\0') {
    std::fprintf(stderr, "bench_corpus: %s='%s' is not a number; using %llu\n", name, v,
                 static_cast<unsigned long long>(fallback));
    return fallback;
  }
  return x;
}
}  // namespace

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : "build/bench/corpus.json";
  sim::corpus::CorpusOptions opt;
  opt.seed = env_or("MMLFW_CORPUS_SEED", 1010);
  opt.runs = env_or("MMLFW_CORPUS_RUNS", 260);
  opt.jobs = static_cast<int>(env_or("MMLFW_CORPUS_JOBS", 2));
  opt.out_dir = "build/bench/corpus_" + std::to_string(opt.seed);
  std::printf("bench_corpus: seed %llu, %zu runs, %d at once -> %s\n", static_cast<unsigned long long>(opt.seed), opt.runs,
              opt.jobs, opt.out_dir.c_str());
  sim::BenchJson json;
  std::string err;
  if (!sim::corpus::run_corpus(opt, &json, nullptr, &err)) {
    std::fprintf(stderr, "bench_corpus: %s\n", err.c_str());
    return 1;
  }
  return json.write(out) ? 0 : 1;
}
