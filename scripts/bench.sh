#!/usr/bin/env bash
# scripts/bench.sh [NAME]: builds the release preset and runs benchmark NAME (all when omitted).
# Each benchmark writes a flat JSON object of named figures to build/bench/NAME.json and prints it.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
bash scripts/setup.sh >/dev/null
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)"
mkdir -p build/bench
export MMLFW_DATA_DIR=${MMLFW_DATA_DIR:-$(cd "$ROOT/.." && pwd)/shared/data}

# Each benchmark is an executable build/release/bench/bench_NAME taking the JSON output path.
mapfile -t available < <(ls build/release/bench 2>/dev/null | sed -n 's/^bench_\(.*\)$/\1/p' | sort)
if [ $# -ge 1 ]; then names=("$1"); else names=("${available[@]}"); fi
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
