#!/bin/sh
# Issue 60: the black box replays bit for bit. A run through the CAN drivers with a pose hint on the
# wire is recorded (--blackbox), then its received frames are fed back through the firmware's CanNode
# in lockstep (--replay-blackbox): the POSE frames must be identical. A black box whose frames were
# tampered with must not replay identical (the comparison can fail), and a broken file is an error.
# Usage: blackbox_replay_test.sh MML_SIM
set -eu
sim=$1
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
args="--world small-office --steps 150 --timing none --quiet --no-pictures"
# shellcheck disable=SC2086  # $args is a list of words
"$sim" $args --transport can --hint-at 60 --blackbox "$t/bb.log" --out "$t/rec" > "$t/rec.txt"
grep -q ' rx 140#' "$t/bb.log" || { echo "FAIL: the hint's frames are not in the black box"; exit 1; }
grep -q ' tx 120#' "$t/bb.log" || { echo "FAIL: no POSE frames in the black box"; exit 1; }
# shellcheck disable=SC2086
"$sim" $args --replay-blackbox "$t/bb.log" | tee "$t/replay.txt"
grep -q ': identical$' "$t/replay.txt"
# A robot's black box is replayed from its map alone (no world): the same poses. The world's
# wheel-noise option is given explicitly in both runs (a world run adds it itself, a map has no wheels).
# shellcheck disable=SC2086
"$sim" $args --transport can --opt odom_noise_per_step=0,0 --blackbox "$t/bb2.log" --out "$t/rec2" > /dev/null
"$sim" --replay-blackbox "$t/bb2.log" --map "$t/rec2/map.yaml" --opt odom_noise_per_step=0,0 --timing none --quiet \
  --no-pictures --out "$t/rep2" | tee "$t/replay2.txt"
grep -q ': identical$' "$t/replay2.txt"
# One received range byte flipped in the middle of the run (a scan's data segment): the replay sees
# another input and must not claim identical poses (or the scan is dropped: fewer poses).
awk 'BEGIN{n=0} / rx 118#/ {n++; if (n==4000) {sub(/#..../, "#0000FFFF")}} {print}' "$t/bb.log" > "$t/tampered.log"
# shellcheck disable=SC2086
if "$sim" $args --replay-blackbox "$t/tampered.log" > "$t/tampered.txt"; then
  echo "FAIL: a tampered black box replayed identical"; cat "$t/tampered.txt"; exit 1
fi
echo "junk" > "$t/broken.log"
# shellcheck disable=SC2086
if "$sim" $args --replay-blackbox "$t/broken.log" 2> "$t/broken.txt"; then echo "FAIL: a broken file replayed"; exit 1; fi
grep -q "broken.log:1" "$t/broken.txt"
echo "blackbox_replay_test: ok ($(wc -l < "$t/bb.log") frames)"
