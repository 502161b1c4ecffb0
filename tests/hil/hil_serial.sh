#!/bin/bash
# Serial HIL on the host (CTest label hil): a socat pty pair, the SICK LMS2xx device model
# (mml-sickdev) streaming aces scans at 75 Hz and 500 kBd with corrupted telegrams and garbage
# on one end, mmlfw reading the other end (laser = serial:PTY@500000, odometry none, output log).
#   hil_serial.sh BUILD_DIR   (results: BUILD_DIR/hil/serial/results.json); exit 77 = skipped.
set -u
B=$(cd "$1" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
DATA=${MMLFW_DATA_DIR:-$here/../../../shared/data}
W=$B/hil/serial
N=${HIL_SERIAL_SCANS:-150}
say() { echo "hil_serial: $*"; }
command -v socat >/dev/null || { say "SKIP: socat not installed"; exit 77; }
[ -f "$DATA/aces/aces.clf.gz" ] || { say "SKIP: aces log not found under $DATA"; exit 77; }
rm -rf "$W"; mkdir -p "$W"
export MMLFW_DATA_DIR=$DATA
socat -d -d pty,raw,echo=0,link=$W/ttyA pty,raw,echo=0,link=$W/ttyB 2> "$W/socat.log" &
sp=$!
trap 'kill $sp 2>/dev/null; wait $sp 2>/dev/null' EXIT
for i in $(seq 1 100); do [ -e "$W/ttyA" ] && [ -e "$W/ttyB" ] && break; sleep 0.05; done
[ -e "$W/ttyB" ] || { say "FAIL: socat made no pty pair"; cat "$W/socat.log"; exit 1; }
printf 'localizer = odom\nlaser = serial:%s@500000\nodometry = none\noutput = log\nworkers = 1\narena_mib = 16\nlog_level = warning\n' \
  "$W/ttyB" > "$W/serial.conf"
"$B/sim/devices/mml-sickdev" --device "$W/ttyA" --dataset aces --count "$N" --rate 75 --corrupt-every 25 \
  --garbage-every 40 --wait 10 > "$W/sent.json" 2> "$W/sickdev.err" &
dp=$!
timeout 60 "$B/firmware/app/mmlfw" --config "$W/serial.conf" --duration $(( N / 75 + 3 )) 2> "$W/mmlfw.log"
frc=$?
wait $dp; drc=$?
grep -o '{.*}' <(grep "mmlfw summary:" "$W/mmlfw.log") > "$W/summary.json"
python3 - "$W" "$frc" "$drc" <<'PY'
import json, sys
w, frc, drc = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
try:
    sent, s = json.load(open(f"{w}/sent.json")), json.load(open(f"{w}/summary.json"))
except Exception as e:
    print(f"hil_serial: FAIL - no results ({e}); mmlfw exit {frc}, mml-sickdev exit {drc}")
    print(open(f"{w}/mmlfw.log").read()[-2000:])
    sys.exit(1)
good = sent["telegrams_sent"] - sent["corrupted"]
checks = [
    ("mmlfw exit 0", frc == 0), ("device model exit 0", drc == 0),
    ("host request for continuous output seen by the device", sent["requested"]),
    (f"all {good} intact telegrams became scans (got {s['serial_scans']})", s["serial_scans"] == good),
    (f"bad CRCs counted (>= {sent['corrupted']}, got {s['serial_crc_errors']})", s["serial_crc_errors"] >= sent["corrupted"]),
    (f"scans processed by the loop ({s['scans_processed']} >= 90% of {good})", s["scans_processed"] * 10 >= good * 9),
]
ok = all(c for _, c in checks)
for name, c in checks:
    print(f"hil_serial: {'ok  ' if c else 'FAIL'} - {name}")
json.dump({"serial_pty_ok": ok, "serial_scans_sent": sent["telegrams_sent"], "serial_scans_received": s["serial_scans"],
           "serial_crc_errors": s["serial_crc_errors"]}, open(f"{w}/results.json", "w"))
sys.exit(0 if ok else 1)
PY
