#!/usr/bin/env bash
# Runs every test: host release build + CTest (unit, data, symbol check, allocation counter,
# HIL inside a user-mode Linux kernel), then the aarch64 cross build with its unit tests under
# qemu-aarch64. Exit status is non-zero if anything fails.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)

bash scripts/setup.sh

JOBS=${JOBS:-$(nproc)}
export MMLFW_DATA_DIR=${MMLFW_DATA_DIR:-$(cd "$ROOT/.." && pwd)/shared/data}
if [ ! -d "$MMLFW_DATA_DIR" ]; then
  echo "test.sh: NOTE: $MMLFW_DATA_DIR is absent; tests that need the real logs will be skipped"
fi

echo "=== host (release) build ==="
cmake --preset release >/dev/null
cmake --build --preset release -j "$JOBS"
echo "=== host (release) tests ==="
ctest --preset release -j "$JOBS" --timeout 1200

echo "=== aarch64 cross build ==="
cmake --preset aarch64 >/dev/null
cmake --build --preset aarch64 -j "$JOBS"
echo "=== aarch64 tests under qemu-aarch64 ==="
ctest --preset aarch64 -j "$JOBS" --timeout 1200

echo "test.sh: all test stages passed"
