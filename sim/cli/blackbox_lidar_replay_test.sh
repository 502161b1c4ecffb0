#!/bin/sh
# Issue 60: the black box of a Hokuyo (SCIP 2.0) or RPLIDAR laser replays bit for bit, as the
# SICK's does (blackbox_serial_replay_test.sh). A run through the firmware's HokuyoLaser /
# RplidarLaser (--transport hokuyo|rplidar: the simulated UTM-30LX / A1 answers the start-up
# handshake and sends the scans; the odometry and a pose hint on the CAN wire) is recorded
# (--blackbox) and replayed (--replay-blackbox: the handshake, never in a black box, answered again
# by the simulated device at the first serial line's time; every later byte is the file's): the
# POSE frames must be identical. A flipped byte must not replay identical (Hokuyo: a character of a
# SCIP line, caught by its sum; RPLIDAR: the start flag of a turn, so two turns run together); a
# cut line is an error naming the file and line. Another unit (--laser-model) replays identical when
# the replay names it.
# Usage: blackbox_lidar_replay_test.sh MML_SIM hokuyo|rplidar
set -eu
sim=$1
laser=$2
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
args="--world small-office --steps 150 --timing none --quiet --no-pictures"
# shellcheck disable=SC2086  # $args is a list of words
"$sim" $args --transport "$laser" --hint-at 60 --blackbox "$t/bb.log" --out "$t/rec" > "$t/rec.txt"
grep -q ' rx laser ' "$t/bb.log" || { echo "FAIL: no $laser bytes in the black box"; exit 1; }
grep -q ' tx laser ' "$t/bb.log" && { echo "FAIL: requests in the black box (the handshake is not recorded)"; exit 1; }
grep -q ' rx 100#' "$t/bb.log" || { echo "FAIL: no odometry frames in the black box"; exit 1; }
grep -q ' rx 140#' "$t/bb.log" || { echo "FAIL: the hint's frames are not in the black box"; exit 1; }
grep -q ' tx 120#' "$t/bb.log" || { echo "FAIL: no POSE frames in the black box"; exit 1; }
# The laser is told by the bytes (no --transport on the replay).
# shellcheck disable=SC2086
"$sim" $args --replay-blackbox "$t/bb.log" | tee "$t/replay.txt"
grep -q ' rx serial chunks, .*: identical$' "$t/replay.txt"
# One byte flipped in the middle of the run.
if [ "$laser" = hokuyo ]; then
  # The 11th byte of the 4000th serial line (a SCIP character: its line's sum no longer fits).
  awk 'BEGIN{n=0} / rx laser / {n++; if (n==4000) {i=index($0, "laser ")+6+20; b=substr($0,i,2); r=(b=="30")?"31":"30"; $0=substr($0,1,i-1) r substr($0,i+2)}} {print}' \
    "$t/bb.log" > "$t/tampered.log"
else
  # The first sample of the 70th turn (the first line of a read at a new time): its start flag S
  # and !S swapped, so that turn runs into the one before.
  awk 'BEGIN{n=0; last=""; m["1"]="2"; m["5"]="6"; m["9"]="A"; m["D"]="E"}
       / rx laser / {if ($1 != last) {n++; last=$1; i=index($0, "laser ")+7; d=substr($0,i,1);
                     if (n>=70 && (d in m) && !done) {$0=substr($0,1,i-1) m[d] substr($0,i+1); done=1}}} {print}' \
    "$t/bb.log" > "$t/tampered.log"
fi
cmp -s "$t/bb.log" "$t/tampered.log" && { echo "FAIL: nothing tampered"; exit 1; }
# shellcheck disable=SC2086
if "$sim" $args --replay-blackbox "$t/tampered.log" > "$t/tampered.txt"; then
  echo "FAIL: a tampered black box replayed identical"; cat "$t/tampered.txt"; exit 1
fi
tail -n 1 "$t/tampered.txt"
# A file cut in the middle of a serial line: an error naming the file and the line.
n=$(grep -n ' rx laser ' "$t/bb.log" | sed -n 100p | cut -d: -f1)
head -n "$n" "$t/bb.log" | sed '$ s/...$//' > "$t/cut.log"
# shellcheck disable=SC2086
if "$sim" $args --replay-blackbox "$t/cut.log" 2> "$t/cut.txt"; then echo "FAIL: a cut file replayed"; exit 1; fi
grep -q "cut.log:$n: not a black box line" "$t/cut.txt" || { cat "$t/cut.txt"; exit 1; }
# Another unit (--laser-model): its replay's handshake must be answered by that unit too.
if [ "$laser" = hokuyo ]; then model=urg-04lx; else model=a2; fi
short="--world small-office --steps 40 --timing none --quiet --no-pictures"
# shellcheck disable=SC2086
"$sim" $short --transport "$laser" --laser-model "$model" --blackbox "$t/model.log" --out "$t/model" > /dev/null
# shellcheck disable=SC2086
"$sim" $short --transport "$laser" --laser-model "$model" --replay-blackbox "$t/model.log" | tee "$t/model.txt"
grep -q ': identical$' "$t/model.txt" || { echo "FAIL: a $model black box did not replay identical"; exit 1; }
echo "blackbox_lidar_replay_test $laser: ok ($(wc -l < "$t/bb.log") lines, $(wc -c < "$t/bb.log") bytes)"
