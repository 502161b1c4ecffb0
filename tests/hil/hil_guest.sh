#!/bin/bash
# Runs INSIDE the guest (run-in-guest.sh: user-mode Linux or QEMU): every CAN peer must live in the same guest.
# hil_guest.sh WORKDIR BUILD_DIR — runs the SocketCAN unit tests, then each scenario listed in
# WORKDIR/scenarios (name iface config replay.log) : mmlfw on the interface, candump recording
# its pose/health frames, canplayer replaying the log; everything with timeouts.
set -u
W=$1
B=$2
rc=0
echo "hil-guest: kernel $(uname -r), $(nproc) CPU(s)"
ip -details link show vcan0 | head -2
timeout 120 "$B/hal/socketcan/hal_socketcan_test" > "$W/socketcan_test.log" 2>&1
src=$?
echo "hil-guest: hal_socketcan_test exit $src"
echo "$src" > "$W/socketcan_test.rc"
[ $src -ne 0 ] && { cat "$W/socketcan_test.log"; rc=1; }

while read -r name iface config replay; do
  [ -z "$name" ] && continue
  d="$W/$name"
  mkdir -p "$d"
  # Record only the firmware's output (pose 0x120.., health 0x130.., and their FD variants).
  candump -L "$iface,120:7F0,130:7F0,520:7F0,530:7F0" > "$d/capture.log" 2> "$d/candump.err" &
  cpid=$!
  "$B/firmware/app/mmlfw" --config "$config" --timing-report > "$d/mmlfw.out" 2> "$d/mmlfw.log" &
  fpid=$!
  # Start-up includes loading the map image (and filling the relation table when the image has none).
  for i in $(seq 1 600); do grep -q "mmlfw: running" "$d/mmlfw.log" 2>/dev/null && break; kill -0 $fpid 2>/dev/null || break; sleep 0.1; done
  echo "hil-guest: $name: mmlfw start-up took $((i / 10)).$((i % 10)) s"
  if ! grep -q "mmlfw: running" "$d/mmlfw.log" 2>/dev/null; then
    echo "hil-guest: $name: mmlfw not running after 60 s:"; cat "$d/mmlfw.log"; rc=1
    kill $fpid $cpid 2>/dev/null; wait $fpid $cpid 2>/dev/null
    continue
  fi
  if ! kill -0 $fpid 2>/dev/null; then
    echo "hil-guest: $name: mmlfw exited at start-up:"; cat "$d/mmlfw.log"; rc=1
    kill $cpid 2>/dev/null; wait $cpid 2>/dev/null
    continue
  fi
  t0=$(date +%s.%N)
  timeout 150 canplayer -I "$replay" "$iface=vcan0"
  prc=$?
  t1=$(date +%s.%N)
  echo "$prc" > "$d/canplayer.rc"
  echo "$t0 $t1" > "$d/replay_times"
  # Issue 60: the operator's commands with mml-ctl (replies decoded from the bus), scenario fd.
  if [ "$name" = fd ] && [ -x "$B/sim/mml-ctl" ]; then
    {
      timeout 10 "$B/sim/mml-ctl" --iface "$iface" --fd --seq 1 hint 1 2 0 0.2 5; echo "rc $?"
      timeout 10 "$B/sim/mml-ctl" --iface "$iface" --seq 2 hint 1 2 0 0.2 5 --map 7; echo "rc $?"
      timeout 10 "$B/sim/mml-ctl" --iface "$iface" --seq 3 select-map 3; echo "rc $?"
      timeout 10 "$B/sim/mml-ctl" --iface "$iface" --seq 4 dump-log; echo "rc $?"
    } > "$d/ctl.log" 2>&1
  fi
  # Let the firmware finish the scans still queued, then stop it the way a robot does.
  sleep 2
  kill -TERM $fpid
  for i in $(seq 1 100); do kill -0 $fpid 2>/dev/null || break; sleep 0.1; done
  if kill -0 $fpid 2>/dev/null; then echo "hil-guest: $name: mmlfw ignored SIGTERM"; kill -KILL $fpid; rc=1; fi
  wait $fpid
  echo "$?" > "$d/mmlfw.rc"
  sleep 0.3
  kill $cpid 2>/dev/null; wait $cpid 2>/dev/null
  echo "hil-guest: $name: canplayer $prc, mmlfw $(cat "$d/mmlfw.rc"), $(wc -l < "$d/capture.log") output frames"
done < "$W/scenarios"
exit $rc
