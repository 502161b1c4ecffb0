#!/bin/bash
# mmlfw --check-config (issue 61) against the real binary (CTest mmlfw_check_config_test, label unit):
# good configs say "ok" with the static memory and exit 0 without starting the loop; every bad
# config and map is rejected (exit 1) with a message naming the input and the problem.
#   check_config_test.sh BUILD_DIR [SUMMARY_FILE]
# SUMMARY_FILE (optional, for scripts/bench.sh deploy): "good_ok G of G2" and "bad_rejected B of N".
set -u
B=$(cd "$1" && pwd)
SUMMARY=${2:-}
W=$B/check_config_test
rm -rf "$W"; mkdir -p "$W"
MMLFW=$B/firmware/app/mmlfw MAPC=$B/sim/map/mml-mapc
fail=0 good=0 good_n=0 bad=0 bad_n=0
say() { echo "check_config_test: $*"; }
check() { if "${@:2}"; then say "ok   - $1"; else say "FAIL - $1"; fail=1; fi; }
# good NAME PATTERN: exit 0, "ok" line on stdout, no loop started.
good() {
  local n=$1 pat=$2; good_n=$((good_n + 1))
  timeout 30 "$MMLFW" --check-config "$W/$n.conf" > "$W/$n.out" 2> "$W/$n.err"; local rc=$?
  if [ $rc = 0 ] && grep -q "check-config '.*$n.conf': ok, static memory [0-9.]* MiB" "$W/$n.out" \
     && grep -q -- "$pat" "$W/$n.out" && ! grep -q "running" "$W/$n.err"; then
    good=$((good + 1)); say "ok   - good config $n: $(cat "$W/$n.out")"
  else
    say "FAIL - good config $n (exit $rc)"; cat "$W/$n.out" "$W/$n.err"; fail=1
  fi
}
# bad NAME PATTERN...: exit 1, every PATTERN on stderr, the problem count line, no loop started.
bad() {
  local n=$1; shift; bad_n=$((bad_n + 1))
  timeout 30 "$MMLFW" --check-config "$W/$n.conf" > "$W/$n.out" 2> "$W/$n.err"; local rc=$?
  local ok=1 p
  [ $rc = 1 ] || ok=0
  for p in "$@" "check-config '.*$n.conf': [0-9] problem(s)"; do grep -q -- "$p" "$W/$n.err" || ok=0; done
  grep -q "running" "$W/$n.err" && ok=0
  grep -q ": ok, static memory" "$W/$n.out" && ok=0
  if [ $ok = 1 ]; then
    bad=$((bad + 1)); say "ok   - bad input $n rejected: $(grep -v '^info:' "$W/$n.err" | head -1)"
  else
    say "FAIL - bad input $n (exit $rc; wanted: $*)"; cat "$W/$n.out" "$W/$n.err"; fail=1
  fi
}
conf() { local n=$1; shift; printf '%s\n' "$@" > "$W/$n.conf"; }

# A 6 x 4 m room with two walls inside, compiled with pRANSAM's relation table.
python3 - "$W" <<'PY'
import sys
w = sys.argv[1]
W, H = 120, 80
px = bytearray([254]) * (W * H)
for x in range(10, 110):
    for y in (10, 69): px[y * W + x] = 0
for y in range(10, 70):
    for x in (10, 109): px[y * W + x] = 0
for y in range(10, 40): px[y * W + 50] = 0
for x in range(70, 90): px[50 * W + x] = 0
open(f"{w}/room.pgm", "wb").write(b"P5\n%d %d\n255\n" % (W, H) + bytes(px))
open(f"{w}/room.yaml", "w").write("image: room.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
                                  "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
PY
"$MAPC" --relation-table "$W/room.yaml" "$W/room.mmap" > "$W/mapc.log" 2>&1
check "mml-mapc compiles the test room" test -s "$W/room.mmap"
# Broken copies: a flipped byte in the occupancy payload and in the relation table (CRC), another
# format version, cut short, not a map image at all, an empty file.
poke() { cp "$W/room.mmap" "$W/$1.mmap"; printf "$3" | dd of="$W/$1.mmap" bs=1 seek="$2" conv=notrunc status=none; }
poke crc_grid 300 '\x55'
poke crc_table 100000 '\xa5'
poke version 8 '\x02'
cp "$W/room.mmap" "$W/cut.mmap"; truncate -s 40000 "$W/cut.mmap"
echo "not a map image" > "$W/text.mmap"
: > "$W/empty.mmap"
base=(laser=serial:/dev/ptmx odometry=none output=log workers=1)

# --- good ----------------------------------------------------------------------------------------
conf ok "${base[@]}" "map = $W/room.mmap" arena_mib=64
good ok "map '.*room.mmap' 120x80 cells at 0.050 m"
conf ok_odom "${base[@]}" localizer=odom arena_mib=8
good ok_odom "localizer odom"

# Several maps (issue 60): each in its own slot, listed by id; a broken map.1 is named. MML's working
# memory (~26 MiB) is one block for all maps: two maps and a reload spare, or three maps, fit the
# 64 MiB budget (one ~35 MiB localizer per map did not: 2 x 34 + spare needed arena_mib 128).
conf two_maps "${base[@]}" "map = $W/room.mmap" "map.1 = $W/room.mmap" map_reload=true arena_mib=64
good two_maps "map '.*room.mmap' 120x80 cells at 0.050 m (slot [0-9.]* MiB), map.1 '.*room.mmap' 120x80 cells at 0.050 m (slot [0-9.]* MiB), reload spare [0-9.]* MiB, MML working memory shared by the maps [0-9.]* MiB"
conf three_maps "${base[@]}" "map = $W/room.mmap" "map.1 = $W/room.mmap" "map.2 = $W/room.mmap" arena_mib=64
good three_maps "map.2 '.*room.mmap' 120x80 cells at 0.050 m (slot [0-9.]* MiB), MML working memory shared"
conf bad_map1 "${base[@]}" "map = $W/room.mmap" "map.1 = $W/crc_grid.mmap" arena_mib=128
bad bad_map1 "crc_grid.mmap: occupancy section CRC mismatch"
conf gap_map2 "${base[@]}" "map = $W/room.mmap" "map.2 = $W/room.mmap" arena_mib=128
bad gap_map2 "key 'map.2' is set but 'map.1' is not"

# --- bad configs ----------------------------------------------------------------------------------
bad no_such_config "config '.*no_such_config.conf': No such file or directory"
conf unknown_key "${base[@]}" "map = $W/room.mmap" "bogus = 1"
bad unknown_key "line 6: unknown key 'bogus'"
conf no_laser localizer=odom
bad no_laser "key 'laser' is required"
conf arena_zero "${base[@]}" localizer=odom arena_mib=0
bad arena_zero "key 'arena_mib': '0' is not an integer in 1..4096"
conf arena_small "${base[@]}" "map = $W/room.mmap" arena_mib=1
bad arena_small "arena exhausted" "arena_mib = 1 is too small for this map and localizer"
conf no_serial "laser = serial:/nonexistent/ttyUSB9@500000" odometry=none output=log localizer=odom arena_mib=8
bad no_serial "problem: board: serial .*/nonexistent/ttyUSB9"
conf no_can "laser = socketcan:mmlfwnosuch0" localizer=odom arena_mib=8
bad no_can "problem: board: socketcan 'mmlfwnosuch0'"
conf no_map "${base[@]}" "map = $W/nonexistent.mmap" arena_mib=64
bad no_map "map image '.*nonexistent.mmap': cannot open"
# --- bad maps --------------------------------------------------------------------------------------
conf crc_grid "${base[@]}" "map = $W/crc_grid.mmap" arena_mib=64
bad crc_grid "crc_grid.mmap: occupancy section CRC mismatch"
conf crc_table "${base[@]}" "map = $W/crc_table.mmap" arena_mib=64
bad crc_table "crc_table.mmap: .*CRC mismatch"
conf version "${base[@]}" "map = $W/version.mmap" arena_mib=64
bad version "version.mmap: format version 2, this firmware reads version 1"
conf cut "${base[@]}" "map = $W/cut.mmap" arena_mib=64
bad cut "cut.mmap': header says .* bytes, the file has 40000"
conf text "${base[@]}" "map = $W/text.mmap" arena_mib=64
bad text "text.mmap': truncated: 16 bytes, the header needs 32"
conf empty "${base[@]}" "map = $W/empty.mmap" arena_mib=64
bad empty "empty.mmap': empty file"
# Two problems at once: both named, counted.
conf two "laser = socketcan:mmlfwnosuch0" "map = $W/crc_grid.mmap" arena_mib=64
bad two "problem: board: socketcan 'mmlfwnosuch0'" "occupancy section CRC mismatch" "2 problem(s)"
# A missing argument is a usage error (2), not a check result.
timeout 10 "$MMLFW" --check-config > /dev/null 2> "$W/usage.err"
check "--check-config without FILE: usage error (exit 2)" test $? = 2

say "good configs ok: $good of $good_n; bad inputs rejected: $bad of $bad_n"
if [ -n "$SUMMARY" ]; then printf 'good_ok %d of %d\nbad_rejected %d of %d\n' "$good" "$good_n" "$bad" "$bad_n" > "$SUMMARY"; fi
[ $fail = 0 ] && say "all passed" || say "FAILED"
exit $fail
