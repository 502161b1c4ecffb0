#!/bin/sh
# Issue 60: a black box of the threaded global search (mmlfw's global_context = thread, here
# mml-sim --opt global=thread) replays bit for bit: the file's "global take|drop" records name the
# scan each MML result was taken at and pRANSAM's deadline rounds, and --replay-blackbox runs each
# job inline and hands its result over at that scan. The run is paced (MML on its thread needs wall
# time between scans to return results at all); the replay is lockstep. A record moved to a scan
# the robot could not have taken it at is named with file and line and the replay is not identical;
# a cut line or a bad field is an error naming file and line; records without global=thread too.
# Usage: blackbox_thread_replay_test.sh MML_SIM
set -eu
sim=$1
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
args="--world small-office --steps 150 --timing none --quiet --no-pictures"
# shellcheck disable=SC2086  # $args is a list of words
"$sim" $args --transport can --opt global=thread --paced --speed 10 --blackbox "$t/bb.log" --out "$t/rec" > "$t/rec.txt"
takes=$(grep -c ' global take ' "$t/bb.log" || true)
[ "$takes" -ge 10 ] || { echo "FAIL: $takes global results taken (expected >= 10)"; exit 1; }
# shellcheck disable=SC2086
"$sim" $args --opt global=thread --replay-blackbox "$t/bb.log" | tee "$t/replay.txt"
grep -q ': identical$' "$t/replay.txt" || { echo "FAIL: the threaded run did not replay identical"; exit 1; }
# The 5th take moved onto its own job's scan: before its window (result_delay_scans) closed.
n=$(grep -n ' global take ' "$t/bb.log" | sed -n 5p | cut -d: -f1)
awk -v n="$n" 'NR==n {sub(/^\([0-9.]+\)/, "(" $4 ")")} {print}' "$t/bb.log" > "$t/tampered.log"
# shellcheck disable=SC2086
if "$sim" $args --opt global=thread --replay-blackbox "$t/tampered.log" > "$t/tampered.txt" 2> "$t/tampered.err"; then
  echo "FAIL: a tampered global record replayed identical"; cat "$t/tampered.txt"; exit 1
fi
grep -q "tampered.log:$n: global record" "$t/tampered.err" || { echo "FAIL: not named"; cat "$t/tampered.err"; exit 1; }
# A cut line and a bad field: errors naming file and line, no crash (exit 1).
awk -v n="$n" 'NR==n {$NF=""} {print}' "$t/bb.log" | sed 's/ *$//' > "$t/cut.log"
awk -v n="$n" 'NR==n {$NF="x7"} {print}' "$t/bb.log" > "$t/field.log"
for f in cut field; do
  # shellcheck disable=SC2086
  set +e; "$sim" $args --opt global=thread --replay-blackbox "$t/$f.log" > /dev/null 2> "$t/$f.err"; rc=$?; set -e
  [ "$rc" -eq 1 ] || { echo "FAIL: $f.log exit $rc (expected 1)"; cat "$t/$f.err"; exit 1; }
  grep -q "$f.log:$n: not a black box line" "$t/$f.err" || { echo "FAIL: $f.log not named"; cat "$t/$f.err"; exit 1; }
done
# Records replayed without the threaded schedule: an error that says what to do.
# shellcheck disable=SC2086
if "$sim" $args --replay-blackbox "$t/bb.log" > /dev/null 2> "$t/ref.err"; then echo "FAIL: replayed inline"; exit 1; fi
grep -q "bb.log:[0-9]*: a global record .*--opt global=thread" "$t/ref.err" || { cat "$t/ref.err"; exit 1; }
echo "blackbox_thread_replay_test: ok ($takes results taken; $(grep -c ' global drop ' "$t/bb.log" || true) dropped; $(grep -c ' tx 12' "$t/bb.log") POSE frames identical)"
