#!/usr/bin/env bash
# scripts/bench.sh [NAME]: builds the release preset and runs benchmark NAME (all when omitted, except
# the hour-long soak; fuzz builds the fuzz preset instead). faults: fault campaign (faults.json, with the
# soak's figures once `bench.sh soak` has run and the sanitizer stages' results of scripts/test.sh).
# Each benchmark writes a flat JSON object of named figures to build/bench/NAME.json and prints it.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
bash scripts/setup.sh >/dev/null
# The pRANSAM benchmark compares with PCL (FPFH + SampleConsensusPrerejective, K-4PCS): Debian's
# libpcl-dev, installed here only when missing (the normal build and the tests never need it).
if [ "${1:-}" = "" ] || [ "${1:-}" = "pransam" ]; then
  if ! dpkg-query -W -f='${Status}' libpcl-dev 2>/dev/null | grep -q "install ok installed"; then
    echo "bench: installing libpcl-dev for the PCL comparison"
    SUDO=""; if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
    export DEBIAN_FRONTEND=noninteractive
    $SUDO apt-get update -qq
    $SUDO apt-get install -y -qq --no-install-recommends libpcl-dev
  fi
fi
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
# global (issue 58; part of "all"): bench_global, the global step in mml-eval --global ref / live-deadline on
# the bench logs and the corpus's largest buildings (build/bench/global.json, firmware/runtime/README.md).
# deploy (issue 61; only when named): the Debian packages of the release, aarch64 and armhf presets
# (own build dirs build/deploy-*), lintian, the systemd unit, --check-config, the watchdog, and an
# install/start/stop/watchdog/remove run in a user-mode Linux guest booting systemd
# (scripts/packaging/deploy_check.sh; build/bench/deploy.json, logs in build/bench/deploy/).
if [ "${1:-}" = deploy ]; then
  echo "=== bench deploy"
  bash scripts/packaging/deploy_check.sh build/bench/deploy.json
  exit $?
fi
# peers (issue 58; only when named): LaMa's Loc2D and AMCL's core built from ../shared/peers (never
# vendored) in their own build dir build/peers (-DMMLFW_BUILD_PEERS=ON, passed only here), beside
# mml-track on intel, aces, fr079 (MMLFW_PEERS_DATASETS): build/bench/peers.json
# (sim/eval/peers/README.md).
if [ "${1:-}" = peers ]; then
  PEERS_DIR=${MMLFW_PEERS_DIR:-$(cd "$ROOT/.." && pwd)/shared/peers}
  if [ ! -d "$PEERS_DIR" ]; then
    echo "bench.sh: no $PEERS_DIR: the peers are not built and not measured" >&2; exit 77
  fi
  cmake --preset release -B build/peers -DMMLFW_BUILD_PEERS=ON -DMMLFW_PEERS_DIR="$PEERS_DIR" >/dev/null
  cmake --build build/peers --target bench_peers -j "$(nproc)"
  if [ ! -x build/peers/bench/bench_peers ]; then
    echo "bench.sh: bench_peers was not built (see the configure messages of build/peers)" >&2; exit 1
  fi
  echo "=== bench peers ==="
  build/peers/bench/bench_peers build/bench/peers.json
  echo "--- build/bench/peers.json"; cat build/bench/peers.json; echo
  exit 0
fi
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)"

# Each benchmark is an executable build/release/bench/bench_NAME taking the JSON output path.
# pransam_pcl is not a benchmark of its own: bench_pransam runs first, then it adds the PCL peers'
# figures to build/bench/pransam.json (issue 17).
mapfile -t available < <(ls build/release/bench 2>/dev/null | sed -n 's/^bench_\(.*\)$/\1/p' | grep -v '^pransam_pcl$' | sort)
# soak (60 minutes; MMLFW_SOAK_MINUTES shortens it) runs only when named.
if [ $# -ge 1 ]; then names=("$1"); else mapfile -t names < <(printf '%s\n' "${available[@]}" | grep -vx soak); fi
if [ ${#names[@]} -eq 0 ]; then echo "bench.sh: no benchmarks built" >&2; exit 1; fi
for n in "${names[@]}"; do
  exe="build/release/bench/bench_$n"
  if [ ! -x "$exe" ]; then
    echo "bench.sh: unknown benchmark '$n' (available: ${available[*]:-none})" >&2; exit 2
  fi
  echo "=== bench $n ==="
  if [ "$n" = "realtime" ]; then
    # Issue 14: the budget check must fail when broken (a tiny deadline, each limit out of reach).
    build/release/tests/hil/replay_budget_test --gtest_filter='*BudgetCheckFailsWhenBroken*' \
      > build/bench/realtime_broken.log 2>&1 || true
    "$exe" "build/bench/$n.json" build/bench/realtime_broken.log
  else
    "$exe" "build/bench/$n.json"
  fi
  if [ "$n" = "pransam" ]; then
    if [ -x build/release/bench/bench_pransam_pcl ]; then
      build/release/bench/bench_pransam_pcl "build/bench/$n.json"
    else
      echo "bench.sh: bench_pransam_pcl not built (PCL not found): no pcl_* figures" >&2
    fi
  fi
  # ground (issue 55, item 6): the table and the picture are written beside the JSON.
  if [ "$n" = "ground" ]; then echo "--- build/bench/ground.md, build/bench/ground.svg"; fi
  echo "--- build/bench/$n.json"; cat "build/bench/$n.json"; echo
done
