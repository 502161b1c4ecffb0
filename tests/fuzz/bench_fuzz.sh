#!/usr/bin/env bash
# bench_fuzz.sh FUZZ_BUILD_DIR OUT.json: every fuzz target for FUZZ_SECONDS (default 300) seconds
# from the seeds (+ committed reproducers replayed first); writes fuzz_targets, fuzz_execs_total,
# fuzz_crashes, fuzz_seconds_per_target and per-target execs. Called by scripts/bench.sh fuzz.
set -uo pipefail
B=$(cd "$1" && pwd)
out=$2
here=$(cd "$(dirname "$0")" && pwd)
secs=${FUZZ_SECONDS:-300}
targets=(can_decoder sick_telegram scip rplidar map_image app_config carmen_log pgm ros_map relations)
total=0 crashes=0 n=0 extra=""
for t in "${targets[@]}"; do
  echo "=== fuzz $t for $secs s"
  line=$(bash "$here/run_fuzz.sh" bench "$B/tests/fuzz/fuzz_$t" "$B/fuzz/seeds/$t" "$here/regressions/$t" \
           "$B/fuzz/bench/$t" "$secs" | tee /dev/stderr | grep '^fuzz_result' | tail -1)
  read -r _ execs took crashed <<< "${line:-fuzz_result 0 0 1}"
  echo "fuzz $t: $execs executions in $took s, crashed $crashed"
  total=$((total + execs)); crashes=$((crashes + crashed)); n=$((n + 1))
  extra="$extra  \"fuzz_execs_$t\": $execs,\n"
done
{
  echo "{"
  echo "  \"fuzz_targets\": $n,"
  echo "  \"fuzz_execs_total\": $total,"
  echo "  \"fuzz_crashes\": $crashes,"
  printf "%b" "$extra"
  echo "  \"fuzz_seconds_per_target\": $secs"
  echo "}"
} > "$out"
cat "$out"
[ "$crashes" = 0 ]
