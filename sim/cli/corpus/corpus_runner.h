// `mml-eval --corpus N --seed S` and scripts/bench.sh corpus: draws N runs of the generated corpus,
// runs them (in `jobs` child processes: the firmware keeps process-wide start-up state, so runs are
// kept apart as processes, and read back in draw order — the figures do not depend on the scheduling),
// and writes the figures (corpus.json), a table per group (corpus.md), one line per run (runs.csv)
// and the pictures of the first few draws.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim/cli/corpus/corpus_draw.h"
#include "sim/cli/corpus/corpus_run.h"
#include "sim/common/bench_json.h"

namespace sim::corpus {

struct CorpusOptions {
  std::size_t runs = 200;
  std::size_t first_draw = 0;   // runs draws first_draw … first_draw + runs − 1 (one draw alone: --draw K)
  std::uint64_t seed = 1;
  int jobs = 2;                 // runs at once (child processes); 1 = in this process
  bool timing = true;           // false: corpus.json is the same bit for bit for the same seed
  std::size_t pictures = 4;     // draws 0 … pictures−1 keep mml-sim's pictures under out_dir/draw_K
  std::string out_dir = "build/eval/corpus";
  bool progress = true;
  CorpusDrawOptions draws;
  CorpusRunOptions run;         // timing and picture_dir are set per run from the above
};

// False with *err when the output folder cannot be written; runs that fail are counted in the
// figures (corpus_runs_failed) with their errors in runs.csv, never dropped.
bool run_corpus(const CorpusOptions& opt, BenchJson* json, std::vector<CorpusRun>* runs, std::string* err);

}  // namespace sim::corpus
