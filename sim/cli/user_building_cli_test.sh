#!/bin/sh
# The user's own building, end to end, through the tools only (issue 12 item 4).
#   user_building_cli_test.sh errors TOOLS...   every tool: --help, bad arguments are clear errors that
#                                              name the argument, non-zero exit (no data needed: tiny
#                                              logs generated here)
#   user_building_cli_test.sh path TOOLS...     the README's path on a slice of a real log (intel's first
#                                              3000 scans): raw log + corrected log -> mml-carmen
#                                              reference -> mml-mapbuild -> mml-mapc --relation-table ->
#                                              mml-sim --map IMAGE / mml-eval --log --map --reference;
#                                              and mml-carmen synth-odom for a corrected-only log (fr101).
#                                              Exit 77 (skipped) when MMLFW_DATA_DIR has no data.
# TOOLS: the paths of mml-eval mml-sim mml-carmen mml-mapbuild mml-mapc, in this order.
set -u
mode="$1"
eval_="$2"
sim="$3"
carmen="$4"
mapbuild="$5"
mapc="$6"
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
# expect NAME STATUS PATTERN COMMAND...: exit status STATUS and PATTERN in stderr (stdout for status 0).
expect() {
  name=$1 want=$2 pattern=$3
  shift 3
  timeout 120 "$@" >"$t/out" 2>"$t/err" </dev/null
  rc=$?
  if [ $rc -ne "$want" ]; then fail "$name: exit status $rc (expected $want): $(head -c 600 "$t/err")"; return; fi
  where="$t/err"
  [ "$want" -eq 0 ] && where="$t/out"
  grep -qF -- "$pattern" "$where" || fail "$name: $(basename "$where") lacks '$pattern': $(head -c 600 "$where")"
}

if [ "$mode" = errors ]; then
  # A tiny log: 20 scans of 30 beams, driving 0.1 m per scan; readings up to 3 m, PARAM maximum 2 m.
  awk 'BEGIN {
    print "PARAM robot_front_laser_max 2.0 nohost 0";
    for (i = 0; i < 20; i++) {
      s = "FLASER 30";
      for (j = 0; j < 30; j++) s = s " " sprintf("%.3f", (j < 10 ? 2.5 + 0.05 * j : 1.0 + 0.01 * i + 0.001 * j));
      x = 0.1 * i;
      s = s " " x " 0 0 " x " 0 0 " (100 + i * 0.2) " host " (i * 0.2);
      print s
    }
  }' >"$t/tiny.clf"
  grep -v PARAM "$t/tiny.clf" | sed 's/^FLASER 30 2.500/FLASER 30 9.000/' >"$t/other.clf"

  # mml-eval
  expect "eval --help" 0 "--log LOG.clf[.gz] --map MAP.yaml|MAP.mmap --reference" "$eval_" --help
  expect "eval --help: --steps default" 0 "--steps 200" "$eval_" --help
  expect "eval unknown dataset" 2 "--datasets: unknown dataset 'NAME' (known: intel, fr079, aces" \
    "$eval_" --datasets intel,NAME --out "$t/ev"
  grep -q "mml-eval: mml-eval:" "$t/err" && fail "eval unknown dataset: doubled prefix: $(cat "$t/err")"
  [ -s "$t/out" ] && fail "eval unknown dataset: figures printed after the error: $(head -c 300 "$t/out")"
  expect "eval --steps abc" 2 "bad value for --steps: 'abc'" "$eval_" --steps abc
  expect "eval --datasets without value" 2 "missing value for --datasets" "$eval_" --datasets
  expect "eval unknown argument" 2 "unknown argument '--bogus'" "$eval_" --bogus
  expect "eval --log alone" 2 "--log, --map and --reference go together" "$eval_" --log "$t/tiny.clf"
  expect "eval missing file" 1 "mml-eval: $t/nope.yaml: file not found" \
    "$eval_" --log "$t/tiny.clf" --map "$t/nope.yaml" --reference "$t/tiny.clf" --out "$t/ev"
  grep -q "mml-eval: mml-eval:" "$t/err" && fail "eval missing file: doubled prefix: $(cat "$t/err")"

  # mml-sim
  expect "sim --help" 0 "--start N" "$sim" --help
  expect "sim --help: map image" 0 "compiled" "$sim" --help
  expect "sim --help: threads" 0 "(default 2, as mml-eval" "$sim" --help
  expect "sim --start abc" 2 "--start: 'abc' is not a non-negative integer" "$sim" --log "$t/tiny.clf" --start abc
  expect "sim world option with a log" 2 "--people is an option of synthetic worlds" \
    "$sim" --log "$t/tiny.clf" --people 3
  expect "sim --start with a world" 2 "--start is for --log" "$sim" --world corridor --start 3
  expect "sim --odom-noise malformed" 2 "--odom-noise: 'x' is not T,R" "$sim" --log "$t/tiny.clf" --odom-noise x
  expect "sim --start beyond the log" 1 "--start 25: the log '$t/tiny.clf' has only 20 scans" \
    "$sim" --log "$t/tiny.clf" --start 25 --localizer odom --out "$t/run" --quiet
  expect "sim --kidnap-at beyond the log" 1 "--kidnap-at 30: after the end of the log" \
    "$sim" --log "$t/tiny.clf" --kidnap-at 30 --localizer odom --out "$t/run" --quiet
  expect "sim --kidnap-at nowhere to go" 1 "--kidnap-at 5: no scan of the log lies 5.0 m or more" \
    "$sim" --log "$t/tiny.clf" --kidnap-at 5 --localizer odom --out "$t/run" --quiet
  printf 'MMLFWMAP but not a map image\n' >"$t/bad.mmap"
  expect "sim corrupt map image" 1 "bad.mmap" \
    "$sim" --log "$t/tiny.clf" --map "$t/bad.mmap" --localizer odom --out "$t/run" --quiet
  expect "sim --start runs" 0 "odom, 15 steps" \
    "$sim" --log "$t/tiny.clf" --start 5 --localizer odom --out "$t/run" --quiet --no-pictures

  # mml-carmen
  expect "carmen --help" 0 "mml-carmen reference RAW CORRECTED OUT" "$carmen" --help
  expect "carmen reference --help" 0 "flaser_index ipc_timestamp logger_timestamp x y theta" "$carmen" reference --help
  expect "carmen synth-odom --help" 0 "0.05" "$carmen" synth-odom --help
  expect "carmen unknown command" 2 "unknown command 'bogus'" "$carmen" bogus
  expect "carmen reference arity" 2 "reference needs RAW CORRECTED OUT (got 2" "$carmen" reference a b
  expect "carmen --seed abc" 2 "--seed 'abc' is not a non-negative integer" "$carmen" synth-odom a b --seed abc
  expect "carmen --seed elsewhere" 2 "--seed is an option of synth-odom only" "$carmen" info a --seed 1
  expect "carmen info arity" 2 "info needs LOG (got 0" "$carmen" info
  expect "carmen reference no match" 1 "none of its 20 scans has the range readings" \
    "$carmen" reference "$t/tiny.clf" "$t/other.clf" "$t/ref.txt"
  expect "carmen synth-odom" 0 "20 scans with synthesised odometry (seed 3" \
    "$carmen" synth-odom "$t/tiny.clf" "$t/synth.clf" --seed 3
  expect "carmen reference of the synthetic log" 0 "20 rows; 20 of 20 corrected scans associated" \
    "$carmen" reference "$t/synth.clf" "$t/tiny.clf" "$t/ref.txt"
  "$carmen" synth-odom "$t/tiny.clf" "$t/synth2.clf" --seed 3 >/dev/null 2>&1
  cmp -s "$t/synth.clf" "$t/synth2.clf" || fail "carmen synth-odom: not deterministic per seed"
  "$carmen" synth-odom "$t/tiny.clf" "$t/synth4.clf" --seed 4 >/dev/null 2>&1
  cmp -s "$t/synth.clf" "$t/synth4.clf" && fail "carmen synth-odom: --seed has no effect"
  expect "carmen reference --every-scan" 0 "20 rows" \
    "$carmen" reference "$t/synth.clf" "$t/tiny.clf" "$t/ref_all.txt" --every-scan

  # mml-mapbuild
  expect "mapbuild --help" 0 "--laser-max-range M" "$mapbuild" --help
  expect "mapbuild --max-range abc" 2 "--max-range: 'abc' is not a number > 0" \
    "$mapbuild" --log "$t/tiny.clf" --name x --max-range abc
  expect "mapbuild --resolution -1" 2 "--resolution: '-1' is not a number > 0" \
    "$mapbuild" --log "$t/tiny.clf" --name x --resolution -1
  expect "mapbuild --name missing" 2 "--log needs --name NAME" "$mapbuild" --log "$t/tiny.clf"
  expect "mapbuild nothing" 2 "nothing to build" "$mapbuild"
  expect "mapbuild value missing" 2 "--out needs a value" "$mapbuild" --log "$t/tiny.clf" --out
  expect "mapbuild unknown argument" 2 "unknown argument '--bogus'" "$mapbuild" --bogus
  expect "mapbuild --max-range with --dataset" 2 "--max-range is for --log" "$mapbuild" --dataset intel --max-range 30
  expect "mapbuild PARAM maximum warns" 0 "200 (33.3 %) beyond it" \
    "$mapbuild" --log "$t/tiny.clf" --name tiny --out "$t/maps"
  grep -qF "200 of 600 beams (33.3 %) read beyond the laser maximum range 2.00 m (PARAM robot_front_laser_max)" \
    "$t/err" || fail "mapbuild PARAM maximum: no warning with counts: $(cat "$t/err")"
  grep -qF "readings used up to 25.0 m (default" "$t/out" || fail "mapbuild: default range is not 25 m: $(cat "$t/out")"
  expect "mapbuild --laser-max-range honoured" 0 "laser maximum range 5.00 m (from --laser-max-range)" \
    "$mapbuild" --log "$t/tiny.clf" --name tiny --out "$t/maps" --laser-max-range 5
  [ -s "$t/err" ] && fail "mapbuild --laser-max-range: still warns: $(cat "$t/err")"

  # mml-mapc
  expect "mapc --help" 0 "usage" "$mapc" --help
elif [ "$mode" = path ]; then
  d="${MMLFW_DATA_DIR:-}"
  if [ ! -f "$d/intel/intel.clf.gz" ] || [ ! -f "$d/fr101/freiburg-101-corrected.log.gz" ]; then
    echo "SKIP: the user-building path needs the data sets (intel, fr101) under MMLFW_DATA_DIR='$d'"
    exit 77
  fi
  # "My building": the first 3000 scans of intel's raw log and the corrected scans among them.
  zcat "$d/intel/intel.clf.gz" | awk '/^FLASER/ { n++ } n > 3000 { exit } { print }' >"$t/raw.clf"
  k=$(grep -v '^#' "$d/intel/intel.corrected-poses.txt" | awk '$1 < 3000' | wc -l)
  zcat "$d/intel/intel-corrected.log.gz" | awk -v k="$k" '/^FLASER/ { n++ } n > k { exit } { print }' >"$t/corrected.log"
  expect "reference" 0 "$k of $k corrected scans associated" \
    "$carmen" reference "$t/raw.clf" "$t/corrected.log" "$t/ref.txt"
  expect "mapbuild" 0 "wrote $t/maps/mybuilding.{yaml,pgm,png,mmap}" \
    "$mapbuild" --log "$t/corrected.log" --name mybuilding --out "$t/maps"
  expect "mapc" 0 "relation table 2D" "$mapc" --relation-table "$t/maps/mybuilding.yaml" "$t/maps/mybuilding.mmap"
  expect "sim on the map image" 0 "first fix at step" \
    "$sim" --log "$t/raw.clf" --map "$t/maps/mybuilding.mmap" --reference "$t/ref.txt" --start 200 --steps 300 \
    --out "$t/run" --no-pictures
  grep -qF "relation table: in the image" "$t/err" || fail "sim: the image's relation table not used: $(cat "$t/err")"
  grep -qF "integrity failures 0" "$t/out" || fail "sim: integrity failures: $(cat "$t/out")"
  expect "sim kidnapped in the log" 0 "kidnap at step 100" \
    "$sim" --log "$t/raw.clf" --map "$t/maps/mybuilding.mmap" --reference "$t/ref.txt" --start 200 --steps 250 \
    --kidnap-at 100 --odom-noise 0.005,0.5 --out "$t/run" --no-pictures
  expect "eval --log --map --reference" 0 "wrote $t/ev/" \
    "$eval_" --log "$t/raw.clf" --map "$t/maps/mybuilding.yaml" --reference "$t/ref.txt" --name mybuilding \
    --whole-runs 1 --fix-trials 1 --kidnap-runs 0 --mcl-trials 0 --steps 300 --out "$t/ev"
  grep -q '"mybuilding_first_fix_success": 1' "$t/ev/localize.json" ||
    fail "eval: first-fix success not 1: $(grep first_fix "$t/ev/localize.json")"
  expect "eval on the map image" 0 "wrote $t/ev2/" \
    "$eval_" --log "$t/raw.clf" --map "$t/maps/mybuilding.mmap" --reference "$t/ref.txt" --name mybuilding \
    --whole-runs 1 --fix-trials 0 --kidnap-runs 0 --mcl-trials 0 --steps 200 --out "$t/ev2"
  # A building with corrected poses only: odometry synthesised, then the same path.
  expect "synth-odom" 0 "292 scans with synthesised odometry (seed 1" \
    "$carmen" synth-odom "$d/fr101/freiburg-101-corrected.log.gz" "$t/fr101.clf"
  expect "reference of the synthetic log" 0 "292 of 292 corrected scans associated" \
    "$carmen" reference "$t/fr101.clf" "$d/fr101/freiburg-101-corrected.log.gz" "$t/fr101-ref.txt"
  expect "mapbuild fr101" 0 "the laser's no-echo value" \
    "$mapbuild" --log "$d/fr101/freiburg-101-corrected.log.gz" --name fr101 --out "$t/maps"
  expect "sim on fr101" 0 "first fix at step" \
    "$sim" --log "$t/fr101.clf" --map "$t/maps/fr101.mmap" --reference "$t/fr101-ref.txt" --out "$t/run" --no-pictures
else
  echo "usage: user_building_cli_test.sh errors|path MML-EVAL MML-SIM MML-CARMEN MML-MAPBUILD MML-MAPC"
  exit 2
fi
if [ $fails -ne 0 ]; then
  echo "$fails check(s) failed"
  exit 1
fi
echo "all checks passed ($mode)"
