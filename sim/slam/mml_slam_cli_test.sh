#!/bin/sh
# mml-slam's bad arguments: each is refused (exit 2) with a message naming the option and the value,
# before any log is read; a missing log is an error naming the path. Usage: mml_slam_cli_test.sh MML_SLAM
set -u
slam=$1
fail=0
expect() {  # expect CODE MESSAGE ARGS...
  code=$1 msg=$2
  shift 2
  err=$("$slam" "$@" 2>&1 >/dev/null)
  rc=$?
  if [ "$rc" -ne "$code" ] || ! printf '%s\n' "$err" | grep -qF -- "$msg"; then
    echo "FAIL: mml-slam $*: exit $rc (want $code), stderr: $err (want: $msg)"
    fail=1
  fi
}
expect 2 "--front: 'bogus' is not fused, fused-filter or rbsm" --log /nonexistent --front bogus
expect 2 "--optimizer: 'x' is not aco or lm" --log /nonexistent --optimizer x
expect 2 "--edge-model: 'y' is not sensor or motion" --log /nonexistent --edge-model y
expect 2 "--traversal: 'z' is not off, on or tracked" --log /nonexistent --traversal z
expect 2 "--final-refine: 'maybe' is not on or off" --log /nonexistent --final-refine maybe
expect 2 "--pair-closures: 'yes' is not on or off" --log /nonexistent --pair-closures yes
expect 2 "--pair-isolation: '1' is not on or off" --log /nonexistent --pair-isolation 1
expect 2 "--gate-isolation: 'no' is not on or off" --log /nonexistent --gate-isolation no
expect 2 "--ants: '0' is not an integer in 1..1024" --log /nonexistent --ants 0
expect 2 "unknown option '--bogus'" --log /nonexistent --front fused-filter --bogus 1
# Every accepted front end gets as far as the log, which names itself.
for f in fused fused-filter rbsm; do
  err=$("$slam" --log /nonexistent/raw.clf --front "$f" 2>&1 >/dev/null)
  rc=$?
  if [ "$rc" -eq 0 ] || ! printf '%s\n' "$err" | grep -qF "/nonexistent/raw.clf"; then
    echo "FAIL: mml-slam --front $f on a missing log: exit $rc, stderr: $err"
    fail=1
  fi
done
[ "$fail" -eq 0 ] && echo "mml-slam CLI: every bad argument refused"
exit "$fail"
