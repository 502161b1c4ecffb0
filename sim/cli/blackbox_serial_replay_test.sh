#!/bin/sh
# Issue 60: the black box of a serial laser replays bit for bit. A run through the SICK driver
# (--transport sick: telegrams on the hal/sim serial port; the odometry and a pose hint on the CAN
# wire, as on a robot with `odometry = socketcan:…`) is recorded (--blackbox): the serial bytes as
# "(T) rx laser HEX" lines, the CAN frames as candump lines, in one file. Its inputs are fed back
# through the same SickLaser and CanNode in lockstep (--replay-blackbox): the POSE frames must be
# identical. A flipped byte in a telegram must not replay identical; a cut or damaged file is an
# error naming the file and line, never a crash.
# Usage: blackbox_serial_replay_test.sh MML_SIM
set -eu
sim=$1
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
args="--world small-office --steps 150 --timing none --quiet --no-pictures"
# shellcheck disable=SC2086  # $args is a list of words
"$sim" $args --transport sick --hint-at 60 --blackbox "$t/bb.log" --out "$t/rec" > "$t/rec.txt"
grep -q ' rx laser 02' "$t/bb.log" || { echo "FAIL: no SICK telegrams in the black box"; exit 1; }
grep -q ' rx 100#' "$t/bb.log" || { echo "FAIL: no odometry frames in the black box"; exit 1; }
grep -q ' rx 140#' "$t/bb.log" || { echo "FAIL: the hint's frames are not in the black box"; exit 1; }
grep -q ' tx 120#' "$t/bb.log" || { echo "FAIL: no POSE frames in the black box"; exit 1; }
# shellcheck disable=SC2086
"$sim" $args --replay-blackbox "$t/bb.log" | tee "$t/replay.txt"
grep -q ' rx serial chunks, .*: identical$' "$t/replay.txt"
# One range byte of a telegram in the middle of the run flipped: the CRC drops that scan, so the
# replay must not claim identical poses.
awk 'BEGIN{n=0} / rx laser 0280/ {n++; if (n==70) {i=index($0, "laser ")+6; $0=substr($0,1,i+19) "5A" substr($0,i+22)}} {print}' \
  "$t/bb.log" > "$t/tampered.log"
cmp -s "$t/bb.log" "$t/tampered.log" && { echo "FAIL: nothing tampered"; exit 1; }
# shellcheck disable=SC2086
if "$sim" $args --replay-blackbox "$t/tampered.log" > "$t/tampered.txt"; then
  echo "FAIL: a tampered black box replayed identical"; cat "$t/tampered.txt"; exit 1
fi
# A file cut in the middle of a serial line: an error naming the file and the line.
n=$(grep -n ' rx laser ' "$t/bb.log" | sed -n 100p | cut -d: -f1)
head -n "$n" "$t/bb.log" | sed '$ s/...$//' > "$t/cut.log"
# shellcheck disable=SC2086
if "$sim" $args --replay-blackbox "$t/cut.log" 2> "$t/cut.txt"; then echo "FAIL: a cut file replayed"; exit 1; fi
grep -q "cut.log:$n: not a black box line" "$t/cut.txt" || { cat "$t/cut.txt"; exit 1; }
printf '(1.000000) rx laser 0Z\n' > "$t/bad.log"
# shellcheck disable=SC2086
if "$sim" $args --replay-blackbox "$t/bad.log" 2> "$t/bad.txt"; then echo "FAIL: a bad file replayed"; exit 1; fi
grep -q "bad.log:1: .*is not hex" "$t/bad.txt" || { cat "$t/bad.txt"; exit 1; }
echo "blackbox_serial_replay_test: ok ($(wc -l < "$t/bb.log") lines, $(wc -c < "$t/bb.log") bytes)"
