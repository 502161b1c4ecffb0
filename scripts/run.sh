#!/usr/bin/env bash
# The main job: set up, build (release), then tell the product's whole story on the built-in large
# office (81 x 47 m, three bare 81 m corridors, 72 rooms, most of them identical):
#   1. the robot is switched on somewhere (seed 1) and knows nothing: MML global localization;
#   2. first fix: `localized`, published with a protection level; from then on mml-track tracks
#      the pose on the global map at every scan through the corridors;
#   3. at scan 400 the robot is carried to another place (kidnapped: the wheels do not turn, the
#      odometry sees nothing);
#   4. the integrity monitor sees the scans contradict the pose (no longer `localized`), MML
#      searches again from a fresh local map and re-fixes.
# Writes build/run/ (steps.csv, summary.json, run.svg/run.png). Extra arguments go to mml-sim and
# override the defaults (e.g. --kidnap-at 300, --seed 2, --via-unknown); another source
# (--dataset intel, --world corridor, --log FILE) replaces the large office and the kidnapping.
# The last line is mml-sim's summary: time to first fix, availability, integrity failures,
# protection level, kidnap detection and re-fix, final error.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)"
mkdir -p build/run
# Another source (--world, --dataset, --log) replaces the story's world and kidnapping.
for a in "$@"; do
  case "$a" in
    --world|--dataset|--log)
      exec ./build/release/sim/mml-sim --seed 1 --out build/run "$@" ;;
  esac
done
echo "run.sh: large office, seed 1: switched on anywhere -> global fix -> tracking -> kidnapped at scan 400 -> detected -> re-fix"
exec ./build/release/sim/mml-sim --world large-office --seed 1 --kidnap-at 400 --out build/run "$@"
