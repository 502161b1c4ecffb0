#!/bin/sh
# Drivers in every simulation (issue 16): mml-sim through the CAN drivers (--transport can: our
# encoder -> hal/sim loopback bus -> the firmware's CanNode) gives the same steps.csv as the direct
# path fed the same sensor values (--sensor-resolution wire: what the wire carries, mm / µrad / µs),
# byte for byte, with --timing none; byte faults are dropped, counted and reported, never a crash.
# Usage: transport_test.sh MML_SIM SOURCE-ARGS...   (e.g. --world small-office --steps 150)
set -eu
sim=$1
shift
if [ "$1" = "--dataset" ] && [ ! -d "${MMLFW_DATA_DIR:-/nonexistent}" ]; then
  echo "no data dir: skipped"
  exit 0
fi
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
"$sim" "$@" --transport none --sensor-resolution wire --timing none --quiet --no-pictures --out "$t/none" > "$t/none.txt"
"$sim" "$@" --transport can --timing none --quiet --no-pictures --out "$t/can" > "$t/can.txt"
grep -q '"transport": "can"' "$t/can/summary.json"
grep -q '"decoder_scans_dropped": 0,' "$t/can/summary.json"
if ! cmp "$t/none/steps.csv" "$t/can/steps.csv"; then
  diff "$t/none/steps.csv" "$t/can/steps.csv" | head -20
  echo "FAIL: --transport can differs from --transport none"
  exit 1
fi
echo "identical: $(wc -l < "$t/none/steps.csv") lines of steps.csv, $(md5sum < "$t/none/steps.csv" | cut -c1-32)"
grep -o 'transport can:.*' "$t/can.txt"

# Byte faults: 1 % of the frames dropped or bit-flipped. The run completes (exit 0), the decoder's
# drops are counted in summary.json and named in the summary line.
"$sim" "$@" --transport can --byte-fault-rate 0.01 --seed 5 --timing none --quiet --no-pictures --out "$t/faults" > "$t/faults.txt"
grep -o 'transport can:.*' "$t/faults.txt"
dropped=$(sed -n 's/.*"decoder_scans_dropped": \([0-9]*\),.*/\1/p' "$t/faults/summary.json")
injected=$(sed -n 's/.*"transport_faults_frames_corrupted": \([0-9]*\),.*/\1/p' "$t/faults/summary.json")
[ "$dropped" -gt 0 ] || { echo "FAIL: faults injected but no scan dropped"; exit 1; }
[ "$injected" -gt 0 ] || { echo "FAIL: no frame corrupted"; exit 1; }
grep -q 'dropped (CRC' "$t/faults.txt"
echo "faults: $injected frames corrupted, $dropped scans dropped by the decoder, run completed"
