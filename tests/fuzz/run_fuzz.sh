#!/usr/bin/env bash
# run_fuzz.sh MODE EXE SEEDS_DIR REGRESSION_DIR WORK_DIR AMOUNT
#   smoke: replays every committed reproducer in REGRESSION_DIR (each must pass), then AMOUNT
#          mutations from the seeds with a fixed seed (deterministic; CTest label fuzz).
#   bench: fuzzes for AMOUNT seconds; prints "fuzz_result EXECS SECONDS CRASHED" as the last line.
# WORK_DIR is recreated: libFuzzer writes new corpus units into the first directory it is given,
# and the source tree must not change. Crashes are written to WORK_DIR/artifacts/.
set -uo pipefail
mode=$1 exe=$2 seeds=$3 regress=$4 work=$5 amount=$6
name=$(basename "$exe")
if [ ! -d "$seeds" ] || [ -z "$(ls -A "$seeds" 2>/dev/null)" ]; then
  echo "run_fuzz: $name: no seeds in $seeds (run the fuzz_seeds test first)" >&2; exit 1
fi
rm -rf "$work"; mkdir -p "$work/corpus" "$work/artifacts"
common=(-artifact_prefix="$work/artifacts/" -timeout=25 -rss_limit_mb=2560 -print_final_stats=1)

if [ -d "$regress" ] && [ -n "$(ls -A "$regress" 2>/dev/null)" ]; then
  n=$(ls -A "$regress" | wc -l)
  echo "run_fuzz: $name: replaying $n reproducer(s) from $regress"
  if ! "$exe" "${common[@]}" "$regress"/* > "$work/regress.log" 2>&1; then
    tail -40 "$work/regress.log"; echo "run_fuzz: $name: a reproducer fails again" >&2; exit 1
  fi
fi

case $mode in
  smoke) args=(-runs="$amount" -seed=1) ;;
  bench) args=(-max_total_time="$amount") ;;
  *) echo "run_fuzz: unknown mode $mode" >&2; exit 2 ;;
esac
start=$(date +%s)
"$exe" "${common[@]}" "${args[@]}" "$work/corpus" "$seeds" > "$work/fuzz.log" 2>&1
rc=$?
secs=$(( $(date +%s) - start ))
execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/fuzz.log" | tail -1)
crashed=0
if [ $rc -ne 0 ] || [ -n "$(ls -A "$work/artifacts" 2>/dev/null)" ]; then crashed=1; fi
grep -E '^#[0-9]+ +(INITED|DONE)' "$work/fuzz.log" | tail -2
if [ $crashed -ne 0 ]; then
  tail -60 "$work/fuzz.log"
  echo "run_fuzz: $name: FAILED (exit $rc); artifacts: $(ls "$work/artifacts" | tr '\n' ' ')" >&2
fi
echo "fuzz_result ${execs:-0} $secs $crashed"
exit $crashed
