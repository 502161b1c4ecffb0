#!/bin/bash
# HIL test over virtual CAN (CTest label hil): prepares replay logs from ../shared/data, boots one
# guest (run-in-guest.sh: user-mode Linux where it starts, else QEMU) to run mmlfw + canplayer +
# candump on vcan0 (CAN FD) and vcan1 (classic), then scores the captured pose/health frames on the
# host (mml-candev, and independently with the DBC: dbc_decode.py) and asserts.
#   hil_vcan.sh BUILD_DIR   (results: BUILD_DIR/hil/vcan/results.json)
# No guest can start on this host: FAIL with the reasons. Exit 77 = skipped (CTest "Skipped") only
# when MMLFW_HIL=skip (explicit opt-out) or the aces log is absent (as every data test).
# MMLFW_HIL=uml|qemu forces the guest (default: chosen by run-in-guest.sh).
# Environment: HIL_SCANS (FD scenario scans, default 250), HIL_SPEED (replay speed-up, default 2),
#              HIL_LOCALIZER (mmlfw's default mml-track when the map can be built, else odom; mml,
#              handoff, mcl selectable), HIL_REQUIRE_LOCALIZED (0/1),
#              HIL_ALLOW_WRONG_LOCALIZED=1 (clean scenarios only warn about wrong `localized` poses;
#              the fault scenario always asserts none).
set -u
B=$(cd "$1" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
DATA=${MMLFW_DATA_DIR:-$here/../../../shared/data}
W=$B/hil/vcan
SCANS=${HIL_SCANS:-250}
CLASSIC_SCANS=${HIL_CLASSIC_SCANS:-100}
SPEED=${HIL_SPEED:-2}
DS=aces
fail=0
group=general          # the scenario the next checks belong to (fd, classic, fault, canplayer)
failed_groups=" "
say() { echo "hil_vcan: $*"; }
check() {  # check DESCRIPTION COMMAND...: records a failed assertion (and its scenario)
  if "${@:2}"; then say "ok   - $1"; else say "FAIL - $1"; fail=1; failed_groups+="$group "; fi
}
group_ok() { [[ "$failed_groups" != *" $1 "* ]] && echo true || echo false; }
rm -f "$W/results.json" "$W/guest"  # never leave an earlier run's figures for bench_hal to read

case "${MMLFW_HIL:-}" in
  skip) say "SKIP: MMLFW_HIL=skip (explicit opt-out: the vcan HIL did not run)"; exit 77 ;;
  uml|qemu|qemu-tcg|qemu-kvm) export HIL_GUEST=$MMLFW_HIL ;;
  "") ;;
  *) say "FAIL: MMLFW_HIL=$MMLFW_HIL (expected skip, uml or qemu)"; exit 1 ;;
esac
if [ ! -f "$DATA/$DS/$DS.clf.gz" ]; then say "SKIP: $DATA/$DS/$DS.clf.gz not found (set MMLFW_DATA_DIR)"; exit 77; fi
for t in candump canplayer cansend; do
  command -v $t >/dev/null || { say "FAIL: $t not installed (apt-get install can-utils; scripts/setup.sh)"; exit 1; }
done
for exe in firmware/app/mmlfw sim/devices/mml-candev hal/socketcan/hal_socketcan_test; do
  [ -x "$B/$exe" ] || { say "FAIL: $B/$exe not built"; exit 1; }
done
rm -rf "$W"; mkdir -p "$W"
export MMLFW_DATA_DIR=$DATA
CANDEV=$B/sim/devices/mml-candev

# The map for the localizer: built from the corrected log by mml-mapbuild, in the shared map cache
# (MMLFW_MAP_DIR, else <source>/build/maps, as sim::map_cache_dir()). The firmware runs its default
# localizer, mml-track (MML global localization, then tracking with a protection level).
LOC=${HIL_LOCALIZER:-}
MAPDIR=${MMLFW_MAP_DIR:-$here/../../build/maps}
MAP=$MAPDIR/$DS.mmap
if [ -z "$LOC" ]; then
  LOC=odom
  if [ -f "$MAP" ]; then LOC=mml-track
  elif [ -x "$B/sim/map/mml-mapbuild" ]; then
    mkdir -p "$MAPDIR"
    if timeout 300 "$B/sim/map/mml-mapbuild" --dataset $DS --out "$MAPDIR" > "$W/mapbuild.log" 2>&1 && [ -f "$MAP" ]; then
      LOC=mml-track
    else
      say "NOTE: mml-mapbuild failed (see $W/mapbuild.log); running with the odometry localizer"
    fi
  fi
fi
say "localizer $LOC (map $MAP)"
# Localizers that run MML (global localization) use pRANSAM's relation table.
USES_MML=0
case "$LOC" in mml|mml-track|handoff) USES_MML=1 ;; esac
# The FD scenario runs on an image with the precomputed relation table (mml-mapc --relation-table,
# Sec. 5.5.2); the others on the plain image, where mmlfw fills the table at start-up.
TABLE_MAP=$MAP
if [ "$USES_MML" = 1 ]; then
  if "$B/sim/map/mml-mapc" --relation-table "${MAP%.mmap}.yaml" "$W/$DS-table.mmap" > "$W/mapc.log" 2>&1; then
    TABLE_MAP=$W/$DS-table.mmap
  else
    say "FAIL: mml-mapc --relation-table (see $W/mapc.log)"; fail=1
  fi
fi

write_config() {  # write_config FILE IFACE FD [MAP]
  {
    echo "laser = socketcan:$2"
    echo "can_fd = $3"
    echo "localizer = $LOC"
    [ "$LOC" != odom ] && echo "map = ${4:-$MAP}"
    echo "workers = 2"          # inside UML: 1 CPU, pinning degrades to core 0 with a warning
    echo "arena_mib = 96"
    echo "health_period_ms = 200"
  } > "$1"
}

# Scenario fd: CAN FD on vcan0, clean. classic: classic CAN on vcan1. fault: FD with corrupt,
# missing and duplicated segments and a bus-off burst (error frames with CAN_ERR_FLAG|CAN_ERR_BUSOFF:
# vcan has no controller, so bus-off is injected as the error frames a controller would report).
write_config "$W/fd.conf" vcan0 true "$TABLE_MAP"
write_config "$W/classic.conf" vcan1 false
write_config "$W/fault.conf" vcan0 true
echo "blackbox = $W/fd/blackbox.log" >> "$W/fd.conf"  # issue 60: written on DUMP_LOG and at exit
"$CANDEV" log2can --dataset $DS --count "$SCANS" --fd --speed "$SPEED" --out "$W/fd.replay" > "$W/fd.sent.json" || exit 1
"$CANDEV" log2can --dataset $DS --count "$CLASSIC_SCANS" --speed "$SPEED" --out "$W/classic.replay" > "$W/classic.sent.json" || exit 1
"$CANDEV" log2can --dataset $DS --first 1000 --count 120 --fd --speed "$SPEED" --corrupt-every 10 --drop-every 13 \
  --dup-every 17 --bus-off-at 60 --bus-off-burst 20 --out "$W/fault.replay" > "$W/fault.sent.json" || exit 1
{
  echo "fd vcan0 $W/fd.conf $W/fd.replay"
  echo "classic vcan1 $W/classic.conf $W/classic.replay"
  echo "fault vcan0 $W/fault.conf $W/fault.replay"
} > "$W/scenarios"

t0=$(date +%s)
HIL_GUEST_FILE=$W/guest HIL_GUEST_RW=$W HIL_GUEST_TIMEOUT=${HIL_GUEST_TIMEOUT:-${UML_TIMEOUT:-400}} \
  "$here/run-in-guest.sh" "$here/hil_guest.sh" "$W" "$B" 2>&1 | tee "$W/guest.log"
urc=${PIPESTATUS[0]}
GUEST=$(cat "$W/guest" 2>/dev/null || echo none)
echo "$(( $(date +%s) - t0 ))" > "$W/guest_seconds"
say "guest $GUEST: run took $(cat "$W/guest_seconds") s, exit $urc"
if [ "$urc" = 78 ] || [ "$urc" = 77 ]; then
  say "FAIL: no guest with vcan can start on this host (reasons above; scripts/setup.sh installs" \
      "user-mode-linux, qemu-system-x86 and linux-image-amd64). MMLFW_HIL=skip skips this test explicitly."
  exit 1
fi
check "guest run completed (exit $urc)" test "$urc" = 0
check "SocketCAN backend tests pass inside the guest ($GUEST)" test "$(cat "$W/socketcan_test.rc" 2>/dev/null)" = 0

jget() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$1" "$2" 2>/dev/null || echo NA; }
summary() { grep -o '{.*}' <(grep "mmlfw summary:" "$W/$1/mmlfw.log") > "$W/$1/summary.json" && cat "$W/$1/summary.json"; }

for s in fd classic fault; do
  first=0; count=$SCANS
  [ $s = classic ] && count=$CLASSIC_SCANS
  [ $s = fault ] && { first=1000; count=120; }
  group=$s
  check "$s: mmlfw stopped cleanly on SIGTERM" test "$(cat "$W/$s/mmlfw.rc" 2>/dev/null)" = 0
  group=canplayer
  check "$s: canplayer replayed the log" test "$(cat "$W/$s/canplayer.rc" 2>/dev/null)" = 0
  group=$s
  summary $s > /dev/null || { say "FAIL - $s: no mmlfw summary"; fail=1; failed_groups+="$s "; continue; }
  "$CANDEV" score --dataset $DS --first $first --count $count --capture "$W/$s/capture.log" --bound 1.0 \
    --json "$W/$s/score.json" --dump "$W/$s/poses.txt" > /dev/null 2> "$W/$s/score.err" \
    || { say "FAIL - $s: scoring failed"; cat "$W/$s/score.err"; fail=1; failed_groups+="$s "; continue; }
  # The same capture decoded with the DBC alone (what a robot integrator reads), against the codec.
  python3 "$here/dbc_decode.py" "$here/../../hal/can/mmlfw.dbc" "$W/$s/capture.log" "$W/$s/poses.txt" \
    > "$W/$s/dbc.json" 2> "$W/$s/dbc.err"
  check "$s: the DBC decodes every pose as the codec does ($(jget "$W/$s/dbc.json" poses) poses, $(jget "$W/$s/dbc.json" mismatches) mismatches)" \
    test "$(jget "$W/$s/dbc.json" matches_codec)" = True
  sent=$(jget "$W/$s.sent.json" scans_sent); intact=$(jget "$W/$s.sent.json" scans_intact)
  ok=$(jget "$W/$s/summary.json" can_scans_ok); dropped=$(jget "$W/$s/summary.json" can_scans_dropped)
  processed=$(jget "$W/$s/summary.json" scans_processed); poses=$(jget "$W/$s/score.json" poses)
  say "$s: sent $sent (intact $intact), decoded $ok, dropped $dropped, processed $processed, pose frames $poses, health frames $(jget "$W/$s/score.json" health)"
  check "$s: every intact scan decoded ($ok == $intact)" test "$ok" = "$intact"
  check "$s: every faulty scan counted ($dropped == $((sent - intact)))" test "$dropped" = "$((sent - intact))"
  check "$s: a pose frame per processed scan ($poses == $processed)" test "$poses" = "$processed"
  # A localizer slower than the sensor (1 CPU in UML, shared with canplayer and candump) makes the
  # firmware skip to the newest scan; every skipped scan must be accounted for.
  over=$(jget "$W/$s/summary.json" can_scans_overwritten); ldrop=$(jget "$W/$s/summary.json" dropped_scans)
  pend=$(( ok - processed - over - ldrop ))
  check "$s: decoded scans all accounted for (processed $processed + skipped $over + loop-dropped $ldrop, $pend pending)" \
    test "$pend" -ge 0 -a "$pend" -le 1
  check "$s: at least a quarter of the decoded scans processed ($processed >= $ok/4)" test $((processed * 4)) -ge "$ok"
  check "$s: health frames present" test "$(jget "$W/$s/score.json" health)" -ge 1
  check "$s: status frames follow the protocol (0 violations)" test "$(jget "$W/$s/score.json" violations)" = 0
  wrong=$(jget "$W/$s/score.json" wrong_localized)
  if [ "${HIL_ALLOW_WRONG_LOCALIZED:-0}" = 1 ] && [ "$s" != fault ]; then
    [ "$wrong" != 0 ] && say "WARNING - $s: $wrong wrong 'localized' poses (> 1 m; allowed by HIL_ALLOW_WRONG_LOCALIZED=1)"
  else
    check "$s: no wrong 'localized' pose (> 1 m from the reference; $wrong)" test "$wrong" = 0
  fi
done
# Fault scenario: the counters reach the health frame.
f=$W/fault
group=fault
check "fault: CRC errors counted ($(jget $f/summary.json can_crc_errors) == $(jget $W/fault.sent.json scans_corrupted))" \
  test "$(jget $f/summary.json can_crc_errors)" = "$(jget $W/fault.sent.json scans_corrupted)"
check "fault: duplicate segments counted" test "$(jget $f/summary.json can_duplicate_segments)" = "$(jget $W/fault.sent.json scans_duplicated)"
check "fault: lost segments counted" test "$(jget $f/summary.json can_lost_segments)" -ge "$(jget $W/fault.sent.json scans_missing_segment)"
check "fault: bus-off burst counted ($(jget $f/summary.json can_bus_off) == 20)" test "$(jget $f/summary.json can_bus_off)" = 20
check "fault: health frame reports bus-off" test "$(jget $f/score.json health_bus_off)" = 20
check "fault: health frame reports CRC errors" test "$(jget $f/score.json health_crc_errors)" = "$(jget $W/fault.sent.json scans_corrupted)"
check "fault: the DBC-decoded health reports the bus-off burst" \
  python3 -c "import json,sys; sys.exit(json.load(open('$f/dbc.json'))['max_health']['BusOff'] != 20)"
group=classic
check "classic: runs on a classic-only bus (no FD frames in the capture)" bash -c "! grep -q '##' '$W/classic/capture.log'"
group=fd
check "fd: pose frames are CAN FD" grep -q '520##' "$W/fd/capture.log"
# Issue 60: commands answered on the bus (mml-ctl in the guest), the black box written.
check "fd: SET_POSE_HINT accepted" grep -q "seq 1 SET_POSE_HINT: accepted" "$W/fd/ctl.log"
check "fd: a hint for an unknown map refused" grep -q "seq 2 SET_POSE_HINT: unknown-map" "$W/fd/ctl.log"
check "fd: SELECT_MAP of an unknown map refused" grep -q "seq 3 SELECT_MAP: unknown-map" "$W/fd/ctl.log"
check "fd: DUMP_LOG done" grep -q "seq 4 DUMP_LOG: done" "$W/fd/ctl.log"
check "fd: the black box holds the scans received, the poses sent and the commands" \
  bash -c "grep -q ' rx 518##' '$W/fd/blackbox.log' && grep -q ' tx 520##' '$W/fd/blackbox.log' && grep -q ' rx 149#04' '$W/fd/blackbox.log'"
if [ "$USES_MML" = 1 ]; then
  check "fd: mmlfw used the image's precomputed relation table" grep -q "precomputed relation table" "$W/fd/mmlfw.log"
  # The global job's window is the scan interval mmlfw sees (firmware/track/scan_window.h), not the
  # 75 Hz period: at least half the replay's mean scan interval (canplayer's wall time / scans).
  win=$(sed -n 's/.*global: last window \([0-9.]*\) ms.*/\1/p' "$W/fd/mmlfw.log" | tail -1)
  per=$(awk -v n="$SCANS" '{printf "%.3f", ($2 - $1) * 1000 / n}' "$W/fd/replay_times" 2>/dev/null)
  check "fd: the global window follows the scan interval (${win:-none} ms, replay ${per:-?} ms a scan)" \
    awk -v w="${win:-0}" -v p="${per:-0}" 'BEGIN { exit !(w > 0 && p > 0 && w >= 0.5 * p) }'
  check "classic: mmlfw filled the relation table at start-up" grep -q "filling it at start-up" "$W/classic/mmlfw.log"
fi

# Availability of `localized` in the captured poses (mml-candev score --dump: one line per scored
# pose, "index status x y ref_x ref_y err", in arrival order): the share of the poses after the
# first `localized` one that are `localized`, as mml-sim and the replay count it.
availability() {
  awk 'fix { n++; if ($2 == "localized") l++ } $2 == "localized" { fix = 1 }
       END { if (n > 0) printf "%.4f", l / n; else print "null" }' "$1" 2>/dev/null || echo null
}
AVAIL=$(availability "$W/fd/poses.txt")
LOCALIZED=$(jget "$W/fd/score.json" localized)
if [ "$LOC" != odom ]; then
  say "fd: $LOC localized on $LOCALIZED of $(jget "$W/fd/score.json" poses) captured poses, first after $(jget "$W/fd/score.json" first_localized_scan) scans, availability after the first fix $AVAIL, mean error while localized $(jget "$W/fd/score.json" mean_err_localized_m) m"
  if [ "${HIL_REQUIRE_LOCALIZED:-1}" = 1 ]; then
    check "fd: the robot localizes ($LOC)" test "$LOCALIZED" -ge 1
  fi
else
  say "NOTE: odometry localizer: localization is not asserted (status is always 'searching')"
fi

python3 - "$W" "$LOC" "$AVAIL" "$(availability "$W/classic/poses.txt")" "$GUEST" "$(cat "$W/guest_seconds")" \
  "$(group_ok classic)" "$(group_ok canplayer)" "$(group_ok fault)" "$(group_ok fd)" <<'PY'
import json, sys
w, loc = sys.argv[1], sys.argv[2]
guest, guest_s, classic_ok, player_ok, faults_ok, fd_ok = sys.argv[5:11]
avail = lambda a: None if a in ("", "null") else float(a)
j = lambda p: json.load(open(p))
fd, fds, fs = j(f"{w}/fd/score.json"), j(f"{w}/fd/summary.json"), j(f"{w}/fd.sent.json")
cl = j(f"{w}/classic/summary.json")
fa, fas, fsent = j(f"{w}/fault/score.json"), j(f"{w}/fault/summary.json"), j(f"{w}/fault.sent.json")
out = {
  "hil_vcan_guest": guest.split("-")[0],
  "hil_vcan_guest_accel": guest.split("-")[1] if "-" in guest else None,
  "hil_vcan_guest_seconds": int(guest_s),
  "hil_localizer": loc,
  "hil_vcan_scans_sent": fs["scans_sent"],
  "hil_vcan_scans_decoded": fds["can_scans_ok"],
  "hil_vcan_scans_processed": fds["scans_processed"],
  "hil_vcan_localized": fd["localized"] > 0,
  "hil_vcan_localized_scans": fd["localized"],
  "hil_vcan_pose_err_m": fd["mean_err_localized_m"] if fd["localized"] else None,
  "hil_vcan_pose_err_all_m": fd["mean_err_m"],
  "hil_vcan_first_localized_scan": fd["first_localized_scan"] if fd["localized"] else None,
  "hil_vcan_availability": avail(sys.argv[3]),
  "hil_classic_availability": avail(sys.argv[4]),
  "hil_fd_ok": fds["can_scans_ok"] == fs["scans_sent"] and fd["violations"] == 0 and fd_ok == "true",
  "hil_classic_ok": classic_ok == "true",
  "hil_canplayer_ok": player_ok == "true",
  "hil_faults_passed": faults_ok == "true",
  "hil_dbc_poses_decoded": sum(j(f"{w}/{s}/dbc.json")["poses"] for s in ("fd", "classic", "fault")),
  "hil_classic_scans_decoded": cl["can_scans_ok"],
  "corrupt_segments_counted": fas["can_crc_errors"] + fas["can_duplicate_segments"] + fas["can_lost_segments"],
  "fault_scans_dropped_counted": fas["can_scans_dropped"],
  "fault_scans_faulty": fsent["scans_sent"] - fsent["scans_intact"],
  "fault_crc_errors": fas["can_crc_errors"],
  "fault_bus_off": fas["can_bus_off"],
  "fault_wrong_localized": fa["wrong_localized"],
}
json.dump(out, open(f"{w}/results.json", "w"), indent=1)
print(json.dumps(out))
PY
if [ $fail -ne 0 ]; then say "FAILED (details in $W)"; exit 1; fi
say "PASSED"
