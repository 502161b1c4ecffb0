// The `--corpus` mode of mml-eval (issue 55):
//   mml-eval --corpus N [--seed S] [--jobs J] [--out DIR] [--pictures K] [--no-timing] [--draw K]
//            [--opt KEY=VALUE]...
// (--draw K: draw K of the corpus alone, in this process, with its pictures; --opt: mml-track's
// options for every run, as mml-sim --opt, to measure what a rule buys)
// draws N runs of the generated corpus for seed S and measures mml-track on them
// (corpus_runner.h); writes DIR/corpus.json, corpus.md, runs.csv and draw_K/ pictures.
#pragma once

namespace sim::corpus {

// True when argv holds --corpus (mml-eval then hands the whole command line here).
bool wants_corpus(int argc, char** argv);
// Exit status: 0 done, 1 a run error that stops the corpus (output folder), 2 a bad argument.
int corpus_main(int argc, char** argv);

}  // namespace sim::corpus
