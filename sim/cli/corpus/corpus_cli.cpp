#include "sim/cli/corpus/corpus_cli.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "sim/cli/corpus/corpus_draw.h"
#include "sim/cli/corpus/corpus_runner.h"

namespace sim::corpus {

namespace {

int bad(const std::string& what) {
  std::fprintf(stderr, "mml-eval: %s\nusage: mml-eval --corpus N [--seed S] [--jobs J] [--out DIR] [--pictures K] [--no-timing] [--draw K] [--opt KEY=VALUE]... [--list]\n",
               what.c_str());
  return 2;
}

bool parse_count(const char* s, unsigned long long lo, unsigned long long hi, unsigned long long* v) {
  char* end = nullptr;
  if (s == nullptr || *s == '\0' || *s == '-') return false;
  *v = std::strtoull(s, &end, 10);
  return *end == '\0' && *v >= lo && *v <= hi;
}

}  // namespace

bool wants_corpus(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--corpus") == 0) return true;
  }
  return false;
}

int corpus_main(int argc, char** argv) {
  CorpusOptions opt;
  bool one_draw = false, list = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const char* v = i + 1 < argc ? argv[i + 1] : nullptr;
    unsigned long long n = 0;
    if (a == "--no-timing") {
      opt.timing = false;
      continue;
    }
    if (a == "--list") {  // the draws, one line each, without running them (to pick an ablation's subset)
      list = true;
      continue;
    }
    if (a != "--corpus" && a != "--seed" && a != "--jobs" && a != "--out" && a != "--pictures" && a != "--draw" && a != "--opt") {
      return bad("unknown argument '" + a + "' with --corpus");
    }
    if (v == nullptr) return bad("missing value for " + a);
    ++i;
    if (a == "--out") {
      opt.out_dir = v;
    } else if (a == "--corpus") {
      if (!parse_count(v, 1, 100000, &n)) return bad("bad value for --corpus: '" + std::string(v) + "' (1–100000 runs)");
      opt.runs = n;
    } else if (a == "--seed") {
      if (!parse_count(v, 0, 1ull << 40, &n)) return bad("bad value for --seed: '" + std::string(v) + "'");
      opt.seed = n;
    } else if (a == "--opt") {
      const std::string kv = v;
      const std::size_t eq = kv.find('=');
      if (eq == std::string::npos || eq == 0) return bad("bad value for --opt: '" + kv + "' (KEY=VALUE)");
      opt.run.localizer_options[kv.substr(0, eq)] = kv.substr(eq + 1);
    } else if (a == "--draw") {
      if (!parse_count(v, 0, 1000000, &n)) return bad("bad value for --draw: '" + std::string(v) + "'");
      opt.first_draw = n;
      one_draw = true;
    } else if (a == "--jobs") {
      if (!parse_count(v, 1, 64, &n)) return bad("bad value for --jobs: '" + std::string(v) + "' (1–64)");
      opt.jobs = static_cast<int>(n);
    } else {
      if (!parse_count(v, 0, 100000, &n)) return bad("bad value for --pictures: '" + std::string(v) + "'");
      opt.pictures = n;
    }
  }
  if (one_draw) {
    opt.runs = 1;
    opt.jobs = 1;
  }
  if (list) {
    const std::vector<CorpusDraw> draws = draw_corpus(opt.seed, opt.first_draw + opt.runs, opt.draws);
    for (std::size_t k = opt.first_draw; k < draws.size(); ++k) std::printf("%s\n", describe_draw(draws[k]).c_str());
    return 0;
  }
  BenchJson json;
  std::string err;
  if (!run_corpus(opt, &json, nullptr, &err)) {
    std::fprintf(stderr, "mml-eval: %s\n", err.c_str());
    return 1;
  }
  if (!json.write(opt.out_dir + "/corpus.json")) return 1;
  std::printf("wrote %s/{corpus.json,corpus.md,runs.csv,draw_*/}\n", opt.out_dir.c_str());
  return 0;
}

}  // namespace sim::corpus
