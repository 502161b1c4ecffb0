#!/bin/bash
# Issue 13 reproducers against the real binaries (CTest mmlfw_cli_test, label unit):
#   - degenerate map (3 occupied cells): mmlfw start-up, mml-mapc --relation-table and mml-sim --map
#     fail fast (they spun ~64 s in the relation table fill) with an error naming the problem;
#   - mmlfw --memory-report exits non-zero with the reason when the hardware cannot run the config
#     (it exited 0), and 0 when it can;
#   - config errors through the binary (baud overflow, duplicate key) and a map image truncated on disk.
#   mmlfw_cli_test.sh BUILD_DIR
set -u
B=$(cd "$1" && pwd)
W=$B/cli_test
rm -rf "$W"; mkdir -p "$W"
MMLFW=$B/firmware/app/mmlfw MAPC=$B/sim/map/mml-mapc SIM=$B/sim/mml-sim
fail=0
say() { echo "mmlfw_cli_test: $*"; }
check() { if "${@:2}"; then say "ok   - $1"; else say "FAIL - $1"; fail=1; fi; }
has() { grep -q -- "$2" "$1" || { echo "--- $1:"; cat "$1"; return 1; }; }
# run NAME TIMEOUT CMD...: records exit code and seconds in $W/NAME.rc / .sec, stderr in .err
run() {
  local n=$1 t=$2; shift 2
  local t0=$(date +%s.%N)
  timeout "$t" "$@" > "$W/$n.out" 2> "$W/$n.err"; echo $? > "$W/$n.rc"
  python3 -c "import sys; print(round(float(sys.argv[2]) - float(sys.argv[1]), 2))" "$t0" "$(date +%s.%N)" > "$W/$n.sec"
  say "$n: exit $(cat "$W/$n.rc") after $(cat "$W/$n.sec") s"
}
fast() { python3 -c "import sys; sys.exit(0 if float(open(sys.argv[1]).read()) < float(sys.argv[2]) else 1)" "$W/$1.sec" "$2"; }
rc() { cat "$W/$1.rc"; }

# A 40 x 40 map at 0.05 m with 3 occupied cells, and a short CARMEN log for mml-sim.
python3 - "$W" <<'PY'
import sys, math
w = sys.argv[1]
W = H = 40
px = bytearray([254]) * (W * H)
for x, y in [(10, 10), (11, 10), (10, 11)]:
    px[y * W + x] = 0
open(f"{w}/three.pgm", "wb").write(b"P5\n%d %d\n255\n" % (W, H) + bytes(px))
open(f"{w}/three.yaml", "w").write("image: three.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
                                   "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
with open(f"{w}/tiny.clf", "w") as f:
    for k in range(5):
        t = 1.0 + 0.1 * k
        f.write("ODOM %.3f 1.0 0.0 0 0 0 %.3f host %.3f\n" % (1.0 + 0.01 * k, t, t))
        f.write("FLASER 181 " + " ".join("1.0" for _ in range(181)) + " %.3f 1.0 0.0 %.3f 1.0 0.0 %.3f host %.3f\n"
                % (1.0 + 0.01 * k, 1.0 + 0.01 * k, t, t))
PY
printf 'laser = serial:/dev/ptmx\nodometry = none\noutput = log\nlocalizer = mml-track\nmap = %s\nworkers = 1\narena_mib = 128\n' \
  "$W/three.mmap" > "$W/three.conf"

# --- degenerate map -------------------------------------------------------------------------
run mapc_plain 30 "$MAPC" "$W/three.yaml" "$W/three.mmap"
check "mml-mapc compiles the 3-cell map without a table" test "$(rc mapc_plain)" = 0
run mapc_table 30 "$MAPC" --relation-table "$W/three.yaml" "$W/three-table.mmap"
check "mml-mapc --relation-table on 3 cells: exit 1" test "$(rc mapc_table)" = 1
check "mml-mapc --relation-table on 3 cells: fails fast (< 5 s)" fast mapc_table 5
check "mml-mapc --relation-table on 3 cells: says why" has "$W/mapc_table.err" "too few occupied points"
run mmlfw_three 30 "$MMLFW" --config "$W/three.conf" --duration 1
check "mmlfw on a 3-cell map: start-up fails (exit 1)" test "$(rc mmlfw_three)" = 1
check "mmlfw on a 3-cell map: fails fast (< 5 s)" fast mmlfw_three 5
check "mmlfw on a 3-cell map: says why" has "$W/mmlfw_three.err" "too few occupied points"
run sim_three 30 "$SIM" --log "$W/tiny.clf" --map "$W/three.yaml" --out "$W/sim"
check "mml-sim --map on a 3-cell map: exit 1" test "$(rc sim_three)" = 1
check "mml-sim --map on a 3-cell map: fails fast (< 5 s)" fast sim_three 5
check "mml-sim --map on a 3-cell map: says why" has "$W/sim_three.err" "too few occupied points"

# --- memory report: a pre-flight check with a verdict --------------------------------------
printf 'laser = socketcan:mmlfwnosuch0\nlocalizer = odom\narena_mib = 16\n' > "$W/nobus.conf"
run report_nobus 30 "$MMLFW" --config "$W/nobus.conf" --memory-report
check "--memory-report, CAN interface missing: exit 1" test "$(rc report_nobus)" = 1
check "--memory-report, CAN interface missing: still prints the report" has "$W/report_nobus.out" "footprint:"
check "--memory-report, CAN interface missing: names the reason" has "$W/report_nobus.err" "cannot run: board: socketcan 'mmlfwnosuch0'"
printf 'laser = serial:/nonexistent/ttyUSB9@500000\nlocalizer = odom\narena_mib = 16\n' > "$W/nodev.conf"
run report_nodev 30 "$MMLFW" --config "$W/nodev.conf" --memory-report
check "--memory-report, serial device missing: exit 1 naming the device" \
  bash -c "test $(rc report_nodev) = 1 && grep -q 'cannot run: board: serial .*/nonexistent/ttyUSB9' '$W/report_nodev.err'"
printf 'laser = serial:/dev/ptmx\nlocalizer = odom\narena_mib = 16\n' > "$W/ok.conf"
run report_ok 30 "$MMLFW" --config "$W/ok.conf" --memory-report
check "--memory-report, runnable config: exit 0" test "$(rc report_ok)" = 0
# --- config and map file reproducers through the binary ------------------------------------
printf 'laser = serial:/dev/ptmx@4295005696\nlocalizer = odom\n' > "$W/baud.conf"
run baud 10 "$MMLFW" --config "$W/baud.conf" --memory-report
check "baud 4295005696: config error (exit 2) naming line and key" \
  bash -c "test $(rc baud) = 2 && grep -q \"line 1: key 'laser': baud '4295005696'\" '$W/baud.err'"
printf 'laser = serial:/dev/ptmx\nlocalizer = odom\nlaser = socketcan:vcan0\n' > "$W/dup.conf"
run dup 10 "$MMLFW" --config "$W/dup.conf" --memory-report
check "duplicate laser key: config error naming both lines" \
  bash -c "test $(rc dup) = 2 && grep -q \"line 3: key 'laser' set again (first set on line 1)\" '$W/dup.err'"
cp "$W/three.mmap" "$W/cut.mmap" && truncate -s 4096 "$W/cut.mmap"
printf 'laser = serial:/dev/ptmx\nlocalizer = mcl\nmap = %s\nworkers = 1\narena_mib = 64\n' "$W/cut.mmap" > "$W/cut.conf"
run cut 30 "$MMLFW" --config "$W/cut.conf" --memory-report
check "map image truncated on disk: exit 1 naming the file and sizes" \
  bash -c "test $(rc cut) = 1 && grep -q \"cut.mmap': header says .* bytes, the file has 4096\" '$W/cut.err'"

[ $fail = 0 ] && say "all passed" || say "FAILED"
exit $fail
