#!/usr/bin/env bash
# The main job: set up, build (release), then run the simulator on a built-in world: a robot is
# switched on somewhere in the large office (ambiguous corridors) and must find its pose.
# Writes a picture of the run to build/run/. Extra arguments go to mml-sim.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)"
mkdir -p build/run
exec ./build/release/sim/mml-sim --world large-office --seed 1 --out build/run "$@"
