#!/bin/sh
# Drivers in every simulation (issue 16): mml-sim through the firmware's drivers (--transport can:
# our CAN encoder -> hal/sim loopback bus -> CanNode; --transport sick: SICK LMS2xx telegrams ->
# hal/sim serial port -> SickLaser) gives the same steps.csv as the direct path fed the same sensor
# values, byte for byte, with --timing none: plain --transport none for can (its sensors report the
# CAN wire's values by default), --transport none --sensor-resolution sick for sick; byte faults are
# dropped, counted and reported, never a crash. Exit 77 (skipped) without the data directory.
# Usage: transport_test.sh MML_SIM can|sick SOURCE-ARGS...   (e.g. can --world small-office --steps 150)
set -eu
sim=$1
tr=$2
shift 2
if [ "$1" = "--dataset" ] && [ ! -d "${MMLFW_DATA_DIR:-/nonexistent}" ]; then
  echo "SKIP: no data directory (MMLFW_DATA_DIR=${MMLFW_DATA_DIR:-unset})"
  exit 77
fi
case $tr in
  can) dropped_key=decoder_scans_dropped; rate=0.01 ;;   # per CAN frame (126 per 361-beam scan)
  sick) dropped_key=sick_scans_dropped; rate=0.05 ;;     # per telegram (one per scan)
  *) echo "transport can or sick"; exit 2 ;;
esac
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
if [ "$tr" = can ]; then res=""; else res="--sensor-resolution $tr"; fi
# shellcheck disable=SC2086  # $res is empty or two words
"$sim" "$@" --transport none $res --timing none --quiet --no-pictures --out "$t/none" > "$t/none.txt"
"$sim" "$@" --transport "$tr" --timing none --quiet --no-pictures --out "$t/drv" > "$t/drv.txt"
grep -q "\"transport\": \"$tr\"" "$t/drv/summary.json"
grep -q "\"$dropped_key\": 0[,]*\$" "$t/drv/summary.json"
if ! cmp "$t/none/steps.csv" "$t/drv/steps.csv"; then
  diff "$t/none/steps.csv" "$t/drv/steps.csv" | head -20
  echo "FAIL: --transport $tr differs from --transport none $res"
  exit 1
fi
echo "identical: $(wc -l < "$t/none/steps.csv") lines of steps.csv, $(md5sum < "$t/none/steps.csv" | cut -c1-32)"
grep -o "transport $tr:.*" "$t/drv.txt"

# Byte faults: 1 % of the CAN frames / 5 % of the SICK telegrams dropped or bit-flipped. The run completes (exit 0), the
# drops are counted in summary.json and named in the summary line.
"$sim" "$@" --transport "$tr" --byte-fault-rate "$rate" --seed 5 --timing none --quiet --no-pictures --out "$t/faults" > "$t/faults.txt"
grep -o "transport $tr:.*" "$t/faults.txt"
dropped=$(sed -n "s/.*\"$dropped_key\": \([0-9]*\).*/\1/p" "$t/faults/summary.json")
injected=$(sed -n 's/.*"transport_faults_frames_corrupted": \([0-9]*\),.*/\1/p' "$t/faults/summary.json")
[ "$dropped" -gt 0 ] || { echo "FAIL: faults injected but no scan dropped"; exit 1; }
[ "$injected" -gt 0 ] || { echo "FAIL: nothing corrupted"; exit 1; }
grep -q 'dropped (CRC' "$t/faults.txt"
echo "faults: $injected corrupted, $dropped scans dropped by the firmware's driver, run completed"
