// scripts/bench.sh corpus (issue 55): mml-track on the generated corpus, build/bench/corpus.json.
// The seed is MMLFW_CORPUS_SEED (default 1414: the published figures' seed, never tuned on; README of
// this folder lists which seeds have been read), the size MMLFW_CORPUS_RUNS (default 260: over
// 100,000 `localized` steps), both also written into the JSON.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "sim/cli/corpus/corpus_runner.h"

namespace {
// A variable set to something that is not a number is an error, not a silent default: a corpus run
// under the wrong seed would publish figures for a seed nobody asked for.
bool env_or(const char* name, std::uint64_t fallback, std::uint64_t* out) {
  *out = fallback;
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return true;
  char* end = nullptr;
  const unsigned long long x = std::strtoull(v, &end, 10);
  if (*end != '\0' || *v == '-') {
    std::fprintf(stderr, "bench_corpus: %s='%s' is not a non-negative integer\n", name, v);
    return false;
  }
  *out = x;
  return true;
}
}  // namespace

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : "build/bench/corpus.json";
  sim::corpus::CorpusOptions opt;
  std::uint64_t seed = 0, runs = 0, jobs = 0;
  if (!env_or("MMLFW_CORPUS_SEED", 1414, &seed) || !env_or("MMLFW_CORPUS_RUNS", 260, &runs) ||
      !env_or("MMLFW_CORPUS_JOBS", 2, &jobs)) {
    return 2;
  }
  if (runs == 0 || jobs == 0 || jobs > 64) {
    std::fprintf(stderr, "bench_corpus: MMLFW_CORPUS_RUNS must be >= 1 and MMLFW_CORPUS_JOBS 1..64 (got %llu, %llu)\n",
                 static_cast<unsigned long long>(runs), static_cast<unsigned long long>(jobs));
    return 2;
  }
  opt.seed = seed;
  opt.runs = static_cast<std::size_t>(runs);
  opt.jobs = static_cast<int>(jobs);
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
