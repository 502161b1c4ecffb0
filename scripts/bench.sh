#!/usr/bin/env bash
# scripts/bench.sh [NAME]: builds the release preset and runs benchmark NAME (all when omitted, except
# the hour-long soak; fuzz builds the fuzz preset instead). faults: fault campaign (faults.json, with the
# soak's figures once `bench.sh soak` has run and the sanitizer stages' results of scripts/test.sh).
# Each benchmark writes a flat JSON object of named figures to build/bench/NAME.json and prints it.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
bash scripts/setup.sh >/dev/null
export MMLFW_DATA_DIR=${MMLFW_DATA_DIR:-$(cd "$ROOT/.." && pwd)/shared/data}
mkdir -p build/bench

# fuzz: the libFuzzer targets (fuzz preset, clang) for FUZZ_SECONDS each (default 300; shorter for a
# trial), seeds made from the real logs first. Not part of "all" (40 minutes).
if [ "${1:-}" = fuzz ]; then
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz -j "$(nproc)"
  ctest --preset fuzz -R '^fuzz_seeds$' >/dev/null
  echo "=== bench fuzz (${FUZZ_SECONDS:-300} s per target)"
  bash tests/fuzz/bench_fuzz.sh build/fuzz build/bench/fuzz.json
  exit $?
fi
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)"

# Each benchmark is an executable build/release/bench/bench_NAME taking the JSON output path.
mapfile -t available < <(ls build/release/bench 2>/dev/null | sed -n 's/^bench_\(.*\)$/\1/p' | sort)
# soak (60 minutes; MMLFW_SOAK_MINUTES shortens it) runs only when named.
if [ $# -ge 1 ]; then names=("$1"); else mapfile -t names < <(printf '%s\n' "${available[@]}" | grep -vx soak); fi
if [ ${#names[@]} -eq 0 ]; then echo "bench.sh: no benchmarks built" >&2; exit 1; fi
for n in "${names[@]}"; do
  exe="build/release/bench/bench_$n"
  if [ ! -x "$exe" ]; then
    echo "bench.sh: unknown benchmark '$n' (available: ${available[*]:-none})" >&2; exit 2
  fi
  echo "=== bench $n ==="
  "$exe" "build/bench/$n.json"
  echo "--- build/bench/$n.json"; cat "build/bench/$n.json"; echo
done
