#!/bin/bash
# Serial HIL for the Hokuyo and RPLIDAR drivers on the host (CTest label hil, issue 59): a socat pty
# pair, the device model (mml-hokuyodev / mml-rplidardev) streaming aces scans on one end, mmlfw
# reading the other (laser = hokuyo:PTY / rplidar:PTY, localizer odom, output log).
#   hil_serial_lidar.sh BUILD_DIR hokuyo|rplidar [clean|faults|replug]
# clean:  line faults only (bad sums / check bits, garbage): every intact answer / turn becomes a
#         scan, every damaged one is counted.
# faults: a truncated answer / lost bytes, a device reset in the middle of a scan (RPLIDAR also:
#         the motor stopping for 2.5 s and a health error at start-up; Hokuyo also: the 24-bit clock
#         wrapping): mmlfw keeps running, asks again, and scans resume; nothing crashes or hangs.
# replug: half the scans, then the cable is pulled (socat and both pty ends vanish) and plugged in
#         again with a fresh device: HEALTH laser-disconnected, the port reopened with back-off, the
#         handshake repeated, the second half arrives.
# Results: BUILD_DIR/hil/serial-SENSOR-MODE/results.json; exit 77 = skipped (no socat / no data).
set -u
B=$(cd "$1" && pwd)
S=$2
M=${3:-clean}
here=$(cd "$(dirname "$0")" && pwd)
DATA=${MMLFW_DATA_DIR:-$here/../../../shared/data}
W=$B/hil/serial-$S-$M
say() { echo "hil_serial_lidar[$S $M]: $*"; }
command -v socat >/dev/null || { say "SKIP: socat not installed"; exit 77; }
[ -f "$DATA/aces/aces.clf.gz" ] || { say "SKIP: aces log not found under $DATA"; exit 77; }
case "$S" in hokuyo|rplidar) ;; *) say "FAIL: sensor '$S' is not hokuyo or rplidar"; exit 2 ;; esac
rm -rf "$W"; mkdir -p "$W"
export MMLFW_DATA_DIR=$DATA
socat_up() {
  socat -d -d pty,raw,echo=0,link=$W/ttyA pty,raw,echo=0,link=$W/ttyB 2>> "$W/socat.log" &
  sp=$!
  for _ in $(seq 1 100); do [ -e "$W/ttyA" ] && [ -e "$W/ttyB" ] && break; sleep 0.05; done
  [ -e "$W/ttyB" ] || { say "FAIL: socat made no pty pair"; cat "$W/socat.log"; exit 1; }
}
socat_up
trap 'kill $sp 2>/dev/null; wait $sp 2>/dev/null' EXIT
printf 'localizer = odom\nlaser = %s:%s@115200\nodometry = none\noutput = log\nworkers = 1\narena_mib = 16\nlog_level = info\n' \
  "$S" "$W/ttyB" > "$W/serial.conf"
if [ "$S" = hokuyo ]; then
  N=120; RATE=40; DEV=$B/sim/devices/mml-hokuyodev
  if [ "$M" = clean ]; then F="--corrupt-every 9 --garbage-every 13"
  elif [ "$M" = faults ]; then F="--truncate-every 17 --reset-at 50 --timestamp-start 16776000 --corrupt-every 23"
  else F=""; fi
else
  N=40; RATE=10; DEV=$B/sim/devices/mml-rplidardev  # an A1 at its fastest (10 Hz, 200 samples a turn)
  if [ "$M" = clean ]; then F="--corrupt-every 7 --garbage-every 11"
  elif [ "$M" = faults ]; then F="--truncate-every 9 --reset-at 15 --motor-stop-at 28 --motor-stop-s 2.5 --health-error 1"
  else F=""; fi
fi
dur=$(( N / RATE + 3 )); [ "$M" = faults ] && dur=$(( dur + 6 )); [ "$M" = replug ] && dur=$(( dur + 5 ))
if [ "$M" != replug ]; then
  # shellcheck disable=SC2086
  "$DEV" --device "$W/ttyA" --dataset aces --count "$N" --rate "$RATE" $F --wait 10 > "$W/sent.json" 2> "$W/device.err" &
  dp=$!
  timeout 60 "$B/firmware/app/mmlfw" --config "$W/serial.conf" --duration "$dur" 2> "$W/mmlfw.log"
  frc=$?
  wait $dp; drc=$?
else
  H=$(( N / 2 ))
  "$DEV" --device "$W/ttyA" --dataset aces --count "$H" --rate "$RATE" --wait 10 > "$W/sent1.json" 2> "$W/device1.err" &
  dp=$!
  timeout 60 "$B/firmware/app/mmlfw" --config "$W/serial.conf" --duration "$dur" 2> "$W/mmlfw.log" &
  fp=$!
  wait $dp; drc=$?
  sleep 0.3; kill $sp; wait $sp 2>/dev/null   # the cable is pulled: both pty ends vanish
  sleep 1.5; socat_up                          # and plugged in again: a fresh device behind the same name
  "$DEV" --device "$W/ttyA" --dataset aces --first "$H" --count "$H" --rate "$RATE" --wait 10 > "$W/sent2.json" 2> "$W/device2.err"
  drc=$(( drc + $? ))
  wait $fp; frc=$?
  python3 -c "import json,sys; a,b=(json.load(open(f)) for f in sys.argv[1:3]); json.dump({k:(a[k]+b[k] if isinstance(a[k],(int,float)) and not isinstance(a[k],bool) else a[k]) for k in a}, open(sys.argv[3],'w'))" \
    "$W/sent1.json" "$W/sent2.json" "$W/sent.json"
fi
grep -o '{.*}' <(grep "mmlfw summary:" "$W/mmlfw.log") > "$W/summary.json"
python3 - "$W" "$S" "$M" "$frc" "$drc" <<'PY'
import json, sys
w, s, m, frc, drc = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5])
tag = f"hil_serial_lidar[{s} {m}]"
try:
    sent, r = json.load(open(f"{w}/sent.json")), json.load(open(f"{w}/summary.json"))
except Exception as e:
    print(f"{tag}: FAIL - no results ({e}); mmlfw exit {frc}, device model exit {drc}")
    print(open(f"{w}/mmlfw.log").read()[-2000:])
    sys.exit(1)
scans, bad = r["serial_scans"], r["serial_crc_errors"]
if s == "hokuyo":
    units, intact, damaged = sent["answers_sent"], sent["intact"], sent["corrupted"] + sent["truncated"]
    # Answers with a wrong sum, cut short or (faults) the one the reset cut and the one it ran into.
    lost_allowed = 0 if m == "clean" else 2 * sent["resets"]
else:
    units, intact, damaged = sent["turns_sent"], sent["intact_turns"], sent["corrupted"] + sent["truncated"]
    # A damaged sample does not cost the turn (it is resampled without it); the turn cut by a reset
    # and the turns the handshake costs after it / after the motor stop are lost.
    lost_allowed = 0 if m == "clean" else 3 * (sent["resets"] + sent["motor_stops"]) + 1
checks = [("mmlfw exit 0", frc == 0), ("device model exit 0", drc == 0), ("the device was asked", sent["requests"] >= 1)]
if m == "replug":
    lost = int(open(f"{w}/mmlfw.log").read().count("laser-disconnected") > 0)
    checks += [(f"HEALTH laser-disconnected while unplugged", lost == 1),
               (f"the port was reopened ({r['serial_reconnects']})", r["serial_reconnects"] >= 1),
               (f"both halves arrived ({scans} >= {intact} - 2)", scans >= intact - 2)]
elif m == "clean":
    want = intact if s == "hokuyo" else units
    checks += [(f"every intact {'answer' if s == 'hokuyo' else 'turn'} became a scan ({scans} of {want})", scans == want),
               (f"damage counted (>= {damaged}, got {bad} + dropped {r['serial_dropped']})", bad + r["serial_dropped"] >= damaged)]
else:
    checks += [(f"scans resumed after the faults ({scans} >= {intact} - {lost_allowed})", scans >= intact - lost_allowed),
               (f"the device was asked again ({sent['requests']} requests, {r['serial_device_restarts']} restarts)",
                sent["requests"] >= 2 and r["serial_device_restarts"] >= 1),
               (f"damage counted ({bad} + dropped {r['serial_dropped']} >= {damaged})", bad + r["serial_dropped"] >= damaged)]
checks.append((f"scans processed by the loop ({r['scans_processed']} >= 90% of {scans})", r["scans_processed"] * 10 >= scans * 9))
ok = all(c for _, c in checks)
for name, c in checks:
    print(f"{tag}: {'ok  ' if c else 'FAIL'} - {name}")
json.dump({f"{s}_{m}_ok": ok, f"{s}_{m}_units_sent": units, f"{s}_{m}_intact": intact, f"{s}_{m}_scans": scans,
           f"{s}_{m}_checksum_errors": bad, f"{s}_{m}_dropped": r["serial_dropped"],
           f"{s}_{m}_device_restarts": r["serial_device_restarts"], f"{s}_{m}_crash": frc >= 128 and frc != 143,
           f"{s}_{m}_hang": frc == 124}, open(f"{w}/results.json", "w"))
sys.exit(0 if ok else 1)
PY
