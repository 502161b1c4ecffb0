#!/bin/bash
# deploy_check.sh OUT.json: the deployment checks of issue 61 (scripts/bench.sh deploy).
#   1. packages: cmake --preset release|aarch64|armhf in build/deploy-{amd64,arm64,armhf} (or the
#      DEPLOY_BUILD_AMD64 / _ARM64 / _ARMHF directories), cpack -G DEB; each package checked for
#      architecture, Depends, contents and conffile; its binary run (amd64 natively, arm64 and
#      armhf under qemu-user): --help, --check-config on a good and on a broken config.
#   2. lintian on every package (errors and warnings counted, the warning tags listed).
#   3. --check-config on good and bad configs and maps (firmware/app/check_config_test.sh), on CAN
#      interfaces in the HIL's guest kernel (vcan), and the sd_notify / watchdog test against a real
#      socket (firmware/app/watchdog_test.py).
#   4. a Debian bookworm root with systemd (debootstrap, once, in build/deploy-guest/root): the amd64
#      package installed with dpkg --root (maintainer scripts chrooted) and its unit checked with
#      systemd-analyze verify (which must also reject a planted broken copy); then a fresh copy
#      booted in user-mode Linux with systemd as PID 1: install, start, stop, a stalled loop
#      restarted by the watchdog, remove and purge (guest_systemd_test.sh).
# Packages are built from HEAD (git archive to build/deploy-src; DEPLOY_SRC=worktree: the working
# tree). Every key of OUT.json comes from a check that can fail; a check that could not run is null
# (and named in "not_run"), never true. DEPLOY_GUEST_DIR overrides build/deploy-guest.
set -u
cd "$(dirname "$0")/../.."
ROOT=$(pwd)
OUT=${1:-build/bench/deploy.json}
L=$ROOT/build/bench/deploy
rm -rf "$L"; mkdir -p "$L"
K=$L/keys.txt; : > "$K"
key() { echo "$1 $2" >> "$K"; echo "deploy: $1 = $2"; }
say() { echo "deploy: $*"; }
need_pkg() {  # Debian packages this bench needs beyond scripts/setup.sh
  local missing=()
  for p in "$@"; do dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p"); done
  [ ${#missing[@]} = 0 ] && return 0
  say "installing ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO=sudo
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" > "$L/apt.log" 2>&1 ||
    { DEBIAN_FRONTEND=noninteractive $SUDO apt-get update -qq >> "$L/apt.log" 2>&1
      DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >> "$L/apt.log" 2>&1; }
}
need_pkg lintian debootstrap dpkg-dev file qemu-user user-mode-linux systemd

declare -A DIR=([amd64]=${DEPLOY_BUILD_AMD64:-build/deploy-amd64} [arm64]=${DEPLOY_BUILD_ARM64:-build/deploy-arm64}
                [armhf]=${DEPLOY_BUILD_ARMHF:-build/deploy-armhf})
declare -A PRESET=([amd64]=release [arm64]=aarch64 [armhf]=armhf)
declare -A TRIPLET=([amd64]="" [arm64]=aarch64-linux-gnu [armhf]=arm-linux-gnueabihf)
declare -A QEMU=([amd64]="" [arm64]=qemu-aarch64 [armhf]=qemu-arm)
declare -A ELF=([amd64]="x86-64" [arm64]="ARM aarch64" [armhf]="ARM, EABI5")
TOOLS="mml-mapc mml-mapbuild mml-slam mml-sim mml-eval mml-carmen mml-candev mml-sickdev"
declare -A DEB

# --- 1. build the packages ---------------------------------------------------------------------------
# From the committed tree (HEAD exported with git archive to build/deploy-src): a package is what
# was committed, not whatever else the working tree holds. DEPLOY_SRC=worktree builds the working
# tree instead (with the DEPLOY_BUILD_* directories of a normal configure).
head=$(git rev-parse HEAD)  # others may commit while this runs: one commit throughout
version="0.0.$(git rev-list --count "$head")+g$(git rev-parse --short=9 "$head")"
vargs=()
SRC=$ROOT
if [ "${DEPLOY_SRC:-head}" != worktree ]; then
  SRC=$ROOT/build/deploy-src
  rm -rf "$SRC"; mkdir -p "$SRC"
  git archive --format=tar "$head" | tar -x -C "$SRC"
  vargs=(-DMMLFW_PACKAGE_VERSION_OVERRIDE="$version" -DMMLFW_PACKAGE_DATE_OVERRIDE="$(git log -1 --format=%cD "$head")")
  say "building from HEAD ${head:0:9} exported to $SRC (version $version)"
fi
for a in amd64 arm64 armhf; do
  d=${DIR[$a]}; [[ "$d" = /* ]] || d=$ROOT/$d; DIR[$a]=$d
  targets=mmlfw; [ $a = amd64 ] && targets="mmlfw $TOOLS"
  say "building ${PRESET[$a]} in $d ($targets)"
  if (cd "$SRC" && cmake --preset "${PRESET[$a]}" -B "$d" "${vargs[@]}") > "$L/configure-$a.log" 2>&1 &&
     nice -n 10 cmake --build "$d" -j2 --target $targets > "$L/build-$a.log" 2>&1; then
    rm -f "$d"/*.deb
    (cd "$d" && cpack -G DEB) > "$L/cpack-$a.log" 2>&1
    DEB[$a]=$(ls "$d"/mmlfw_*_"$a".deb 2>/dev/null | head -1)
  fi
  [ -n "${DEB[$a]:-}" ] || say "no $a package: see $L/{configure,build,cpack}-$a.log"
done
AMD=${DIR[amd64]}
MAPC=$AMD/sim/map/mml-mapc

# A map for the binaries' checks (mml-mapc of the amd64 build; the image format is the same on
# every target), a good config and one with a broken map.
W=$L/work; mkdir -p "$W"
python3 - "$W" <<'PY'
import sys
w = sys.argv[1]; W, H = 120, 80
px = bytearray([254]) * (W * H)
for x in range(10, 110):
    for y in (10, 69): px[y * W + x] = 0
for y in range(10, 70):
    for x in (10, 109): px[y * W + x] = 0
for y in range(10, 40): px[y * W + 50] = 0
open(f"{w}/room.pgm", "wb").write(b"P5\n%d %d\n255\n" % (W, H) + bytes(px))
open(f"{w}/room.yaml", "w").write("image: room.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
                                  "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
PY
[ -x "$MAPC" ] && "$MAPC" --relation-table "$W/room.yaml" "$W/room.mmap" > "$W/mapc.log" 2>&1
cp "$W/room.mmap" "$W/bad.mmap" 2>/dev/null && printf '\x55' | dd of="$W/bad.mmap" bs=1 seek=300 conv=notrunc status=none
printf 'laser = serial:/dev/ptmx\nodometry = none\noutput = log\nmap = %s\nworkers = 1\narena_mib = 64\n' "$W/room.mmap" > "$W/good.conf"
printf 'laser = serial:/dev/ptmx\nodometry = none\noutput = log\nmap = %s\nworkers = 1\narena_mib = 64\n' "$W/bad.mmap" > "$W/bad.conf"

# deb_check ARCH: 0 when every check of that package passes (each failure is printed).
deb_check() {
  local a=$1 deb=${DEB[$1]:-} x=$W/x-$1 bad=0 run=()
  [ -n "$deb" ] || { say "$a: no package"; return 1; }
  fail() { say "$a: FAIL $*"; bad=1; }
  [ "$(dpkg-deb -f "$deb" Architecture)" = "$a" ] || fail "Architecture is '$(dpkg-deb -f "$deb" Architecture)'"
  [ "$(dpkg-deb -f "$deb" Package)" = mmlfw ] || fail "Package is not mmlfw"
  dpkg-deb -f "$deb" Depends | grep -q 'libc6 (>= ' || fail "Depends without libc6: $(dpkg-deb -f "$deb" Depends)"
  dpkg-deb -f "$deb" Version | grep -qE '^0\.0\.[0-9]+\+g[0-9a-f]+$' || fail "Version $(dpkg-deb -f "$deb" Version)"
  dpkg-deb -c "$deb" | awk '{print $6}' > "$W/contents-$a.txt"
  for f in ./usr/bin/mmlfw ./etc/mmlfw/mmlfw.conf ./lib/systemd/system/mmlfw.service ./var/lib/mmlfw/maps/ \
           ./usr/share/mmlfw/mmlfw.dbc ./usr/share/man/man1/mmlfw.1.gz ./usr/share/doc/mmlfw/copyright; do
    grep -qxF "$f" "$W/contents-$a.txt" || fail "missing $f"
  done
  # Nothing outside the usual places.
  grep -vE '^\./(usr/(bin|share)/|etc/mmlfw/|lib/systemd/system/|var/lib/mmlfw/)|^\./(usr|etc|lib|lib/systemd|var|var/lib)/$|^\./$' \
    "$W/contents-$a.txt" | sed 's/^/unexpected: /' | grep . && fail "files outside the usual places"
  dpkg-deb --ctrl-tarfile "$deb" | tar -xO ./conffiles 2>/dev/null | grep -qx /etc/mmlfw/mmlfw.conf || fail "conffile not declared"
  rm -rf "$x"; dpkg -x "$deb" "$x"
  file -L "$x/usr/bin/mmlfw" | grep -q "${ELF[$a]}" || fail "binary is $(file -L "$x/usr/bin/mmlfw")"
  [ -n "${QEMU[$a]}" ] && run=("${QEMU[$a]}" -L "/usr/${TRIPLET[$a]}")
  "${run[@]}" "$x/usr/bin/mmlfw" --help > "$W/help-$a.txt" 2>&1 && grep -q -- "--check-config FILE" "$W/help-$a.txt" ||
    fail "--help"
  "${run[@]}" "$x/usr/bin/mmlfw" --check-config "$W/good.conf" > "$W/good-$a.out" 2> "$W/good-$a.err" &&
    grep -q ": ok, static memory" "$W/good-$a.out" || fail "--check-config good.conf: $(cat "$W/good-$a.out" "$W/good-$a.err" | grep -v ^info | head -2)"
  "${run[@]}" "$x/usr/bin/mmlfw" --check-config "$W/bad.conf" > "$W/bad-$a.out" 2> "$W/bad-$a.err"
  [ $? = 1 ] && grep -q "occupancy section CRC mismatch" "$W/bad-$a.err" || fail "--check-config bad.conf not rejected"
  say "$a: $(head -1 "$W/good-$a.out")"
  if [ $a = amd64 ]; then
    local tools; tools=$(ls "${DIR[amd64]}"/mmlfw-tools_*_amd64.deb 2>/dev/null | head -1)
    [ -n "$tools" ] || fail "no mmlfw-tools package"
    if [ -n "$tools" ]; then
      [ "$(dpkg-deb -f "$tools" Architecture)" = amd64 ] || fail "mmlfw-tools Architecture"
      dpkg-deb -c "$tools" | awk '{print $6}' > "$W/contents-tools.txt"
      for t in $TOOLS; do grep -qxF "./usr/bin/$t" "$W/contents-tools.txt" || fail "mmlfw-tools without $t"; done
      DEB[tools]=$tools
    fi
  fi
  return $bad
}
for a in amd64 arm64 armhf; do
  if deb_check $a; then key deb_${a}_ok true; else key deb_${a}_ok false; fi
done

# --- 2. lintian ------------------------------------------------------------------------------------------
debs=(); for k in amd64 tools arm64 armhf; do [ -n "${DEB[$k]:-}" ] && debs+=("${DEB[$k]}"); done
if [ ${#debs[@]} -gt 0 ] && command -v lintian > /dev/null; then
  lintian --tag-display-limit 0 "${debs[@]}" > "$L/lintian.txt" 2>&1
  key lintian_errors "$(grep -c '^E: ' "$L/lintian.txt")"
  key lintian_warnings "$(grep -c '^W: ' "$L/lintian.txt")"
  key lintian_warning_tags "\"$(grep '^W: ' "$L/lintian.txt" | sed 's/^W: //' | paste -sd';' | sed 's/;/; /g')\""
  key lintian_packages "${#debs[@]}"
else
  key lintian_errors null; key lintian_warnings null
fi

# --- 3. --check-config and the notify/watchdog test -------------------------------------------------------
if [ -x "$AMD/firmware/app/mmlfw" ] && [ -x "$MAPC" ]; then
  bash "$SRC/firmware/app/check_config_test.sh" "$AMD" "$L/check_config.txt" > "$L/check_config.log" 2>&1
  rc=$?
  read -r _ g gn < <(awk '/^good_ok/ {print $1, $2, $4}' "$L/check_config.txt" 2>/dev/null) || true
  read -r _ b bn < <(awk '/^bad_rejected/ {print $1, $2, $4}' "$L/check_config.txt" 2>/dev/null) || true
  if [ -n "${g:-}" ] && [ "$g" = "$gn" ] && [ $rc = 0 ]; then key check_config_ok true; else key check_config_ok false; fi
  key check_config_good_ok "${g:-null}"
  key check_config_bad_inputs_rejected "${b:-null}"
  key check_config_bad_inputs_tried "${bn:-null}"
  nice -n 10 cmake --build "$AMD" -j2 --target mml-sickdev > "$L/build-sickdev.log" 2>&1
  python3 "$SRC/firmware/app/watchdog_test.py" "$AMD/firmware/app/mmlfw" --summary "$L/watchdog.txt" \
    --sickdev "$AMD/sim/devices/mml-sickdev" --mapc "$MAPC" > "$L/watchdog.log" 2>&1
  key notify_ready_status_watchdog_ok "$(awk '/^healthy_ok/ {print ($2 == 1 ? "true" : "false")}' "$L/watchdog.txt" 2>/dev/null || echo null)"
  key notify_watchdog_stops_on_stall "$(awk '/^stall_stops_watchdog/ {print ($2 == 1 ? "true" : "false")}' "$L/watchdog.txt" 2>/dev/null || echo null)"
  wd() { local v; v=$(awk -v k="$1" '$1 == k {print ($2 == 1 ? "true" : "false")}' "$L/watchdog.txt" 2>/dev/null); echo "${v:-null}"; }
  key notify_watchdog_fed_while_steps_keep_deadline "$(wd scans_fed)"
  key notify_watchdog_withheld_when_every_step_late "$(wd late_steps_stop_watchdog)"
else
  key check_config_ok null; key check_config_bad_inputs_rejected null
fi

# The board's CAN interface through --check-config in a kernel that has CAN (this one may not):
# vcan0 (FD) ok, a missing interface and an FD config on the classic vcan1 rejected, inside the
# HIL's guest (tests/hil/run-in-guest.sh: user-mode Linux, else QEMU).
if [ -x "$AMD/firmware/app/mmlfw" ]; then
  printf 'laser = socketcan:vcan0\nlocalizer = odom\narena_mib = 8\n' > "$W/vcan0.conf"
  printf 'laser = socketcan:mmlfwcan9\nlocalizer = odom\narena_mib = 8\n' > "$W/nocan.conf"
  printf 'laser = socketcan:vcan1\nlocalizer = odom\ncan_fd = true\narena_mib = 8\n' > "$W/fdclassic.conf"
  amd_abs=$(cd "$AMD" && pwd)
  cat > "$W/can_check.sh" <<CAN
#!/bin/bash
for c in vcan0 nocan fdclassic; do "$amd_abs/firmware/app/mmlfw" --check-config "$W/\$c.conf" > "$W/can-\$c.out" 2>&1; echo \$? > "$W/can-\$c.rc"; done
CAN
  chmod +x "$W/can_check.sh"
  rm -f "$W"/can-*.rc
  timeout 300 "$SRC/tests/hil/run-in-guest.sh" "$W/can_check.sh" > "$L/can_check.log" 2>&1
  if [ -f "$W/can-vcan0.rc" ]; then
    if [ "$(cat "$W/can-vcan0.rc")" = 0 ] && grep -q ": ok, static memory" "$W/can-vcan0.out" &&
       [ "$(cat "$W/can-nocan.rc")" = 1 ] && grep -q "socketcan 'mmlfwcan9': no such interface" "$W/can-nocan.out" &&
       [ "$(cat "$W/can-fdclassic.rc")" = 1 ] && grep -q "CAN FD required but interface MTU is 16" "$W/can-fdclassic.out"; then
      key check_config_can_interface_ok true
    else key check_config_can_interface_ok false; fi
  else
    say "no guest for the CAN interface check (see $L/can_check.log)"; key check_config_can_interface_ok null
  fi
fi

# --- 4. a Debian root with systemd: dpkg --root install, unit verify, the guest ------------------------------
G=${DEPLOY_GUEST_DIR:-$ROOT/build/deploy-guest}
# The root's package set; a root made with another set is made again.
GUEST_PKGS=systemd,systemd-sysv,adduser,dbus,iproute2,kmod,init-system-helpers,can-utils
if [ ! -x "$G/root/lib/systemd/systemd" ] || [ "$(cat "$G/root.packages" 2>/dev/null)" != "$GUEST_PKGS" ]; then
  say "debootstrap of a bookworm root with systemd into $G/root (once; Debian's packages)"
  rm -rf "$G/root" "$G/root.packages"; mkdir -p "$G"
  mirror=$(grep -hE '^(URIs:|deb )' /etc/apt/sources.list.d/*.sources /etc/apt/sources.list 2>/dev/null | grep -v security |
           head -1 | awk '{print $2}')
  if nice debootstrap --variant=minbase --include=$GUEST_PKGS \
       bookworm "$G/root" "${mirror:-http://deb.debian.org/debian}" > "$L/debootstrap.log" 2>&1; then
    echo "$GUEST_PKGS" > "$G/root.packages"
  else
    say "debootstrap failed (see $L/debootstrap.log)"; rm -rf "$G/root"
  fi
fi
if [ -x "$G/root/lib/systemd/systemd" ] && [ -n "${DEB[amd64]:-}" ]; then
  V=$G/verify; rm -rf "$V"; cp -a "$G/root" "$V"
  dpkg --root="$V" -i "${DEB[amd64]}" > "$L/dpkg-root-install.log" 2>&1; rc=$?
  if [ $rc = 0 ] && grep -q '^mmlfw:' "$V/etc/passwd"; then key dpkg_root_install_ok true; else key dpkg_root_install_ok false; fi
  if command -v systemd-analyze > /dev/null; then
    systemd-analyze verify --root="$V" --man=no /lib/systemd/system/mmlfw.service > "$L/unit-verify.log" 2>&1; vrc=$?
    # The check must be able to fail: a planted copy with a bad Type= and a missing binary.
    sed -e 's/^Type=notify/Type=notifyy/' -e 's|^ExecStart=/usr/bin/mmlfw|ExecStart=/usr/bin/mmlfw-missing|' \
      "$V/lib/systemd/system/mmlfw.service" > "$V/lib/systemd/system/mmlfw-broken.service"
    systemd-analyze verify --root="$V" --man=no /lib/systemd/system/mmlfw-broken.service > "$L/unit-verify-broken.log" 2>&1; brc=$?
    if [ $vrc = 0 ] && [ ! -s "$L/unit-verify.log" ] && [ $brc != 0 ]; then key unit_verify_ok true
    else key unit_verify_ok false; say "unit verify: exit $vrc ($(head -3 "$L/unit-verify.log")); broken copy exit $brc"; fi
  else
    key unit_verify_ok null
  fi
  rm -rf "$V"
  # For the run on vcan: aces as CAN FD traffic (mml-candev, twice the log's speed) and its map.
  DATA=${MMLFW_DATA_DIR:-$(cd "$ROOT/.." && pwd)/shared/data}
  can_args=()
  if [ -f "$DATA/aces/aces.clf.gz" ] && [ -x "$AMD/sim/map/mml-mapbuild" ] && [ -x "$AMD/sim/devices/mml-candev" ]; then
    MMLFW_DATA_DIR=$DATA "$AMD/sim/map/mml-mapbuild" --dataset aces --out "$W/maps" > "$L/aces-map.log" 2>&1 &&
      "$MAPC" --relation-table "$W/maps/aces.yaml" "$W/aces-table.mmap" >> "$L/aces-map.log" 2>&1 &&
      MMLFW_DATA_DIR=$DATA "$AMD/sim/devices/mml-candev" log2can --dataset aces --count 400 --fd --speed 2 \
        --out "$W/aces.replay" > "$L/aces-replay.json" 2>> "$L/aces-map.log" &&
      can_args=("$W/aces.replay" "$W/aces-table.mmap")
  fi
  [ ${#can_args[@]} = 0 ] && say "no aces map or replay (log under $DATA?): the guest's CAN run is left out"
  if bash "$SRC/scripts/packaging/guest_systemd_test.sh" "$G/root" "${DEB[amd64]}" "$W/room.mmap" "$G/run" "$L/guest.txt" \
       "${can_args[@]}" > "$L/guest.log" 2>&1 ||
     [ -s "$L/guest.txt" ]; then
    v() { awk -v k="$1" '$1 == k {print $2}' "$L/guest.txt"; }
    all() { local k; for k in "$@"; do [ "$(v "$k")" = 1 ] || return 1; done; }
    zero() { local k; for k in "$@"; do [ "$(v "$k")" = 0 ] || return 1; done; }
    key guest "\"uml+systemd($(v pid1))\""
    key guest_seconds "$(v guest_seconds)"
    if zero install_rc check_config_rc start_rc stop_rc remove_rc purge_rc restarts_healthy &&
       all user_created unit_enabled hint_printed not_started_unchecked active_after_start runs_as_mmlfw alive_after_5s \
           inactive_after_stop summary_in_journal binary_removed unit_removed && [ "$(v stop_result)" = success ]; then
      key install_start_stop_ok true
    else key install_start_stop_ok false; fi
    key realtime_in_service "$(all sched_fifo memory_locked && echo true || echo false)"
    key start_seconds "$(v start_seconds)"
    key service_status_text "$(awk '$1 == "status_text" {$1=""; sub(/^ /, ""); print}' "$L/guest.txt")"
    if all watchdog_timeout_logged watchdog_restarted; then key watchdog_restart_ok true; else key watchdog_restart_ok false; fi
    key watchdog_restart_seconds "$(v watchdog_restart_seconds)"
    if [ -n "$(v can_start_rc)" ]; then
      if zero can_check_config_rc can_start_rc canplayer_rc can_restarts && all localized_under_systemd can_alive_after_replay; then
        key localized_under_systemd_ok true
      else key localized_under_systemd_ok false; fi
      key localized_status_text "$(awk '$1 == "localized_status_text" {$1=""; sub(/^ /, ""); print}' "$L/guest.txt")"
      key can_scans_processed "$(v can_scans_processed)"
    else
      key localized_under_systemd_ok null
    fi
    if all conffile_kept conffile_kept_edited binary_removed unit_removed dpkg_status_config_files conffile_purged; then
      key remove_keeps_conffile_ok true
    else key remove_keeps_conffile_ok false; fi
  else
    say "the guest did not run (see $L/guest.log)"
    key install_start_stop_ok null; key watchdog_restart_ok null; key remove_keeps_conffile_ok null
  fi
else
  key dpkg_root_install_ok null; key unit_verify_ok null
  key install_start_stop_ok null; key watchdog_restart_ok null; key remove_keeps_conffile_ok null
fi
key version "\"$(dpkg-deb -f "${DEB[amd64]:-/dev/null}" Version 2>/dev/null)\""
key built_from "\"$([ "$SRC" = "$ROOT" ] && echo "working tree" || echo "HEAD (git archive)")\""
key commit "\"${head:0:9}\""

# --- the JSON ------------------------------------------------------------------------------------------
python3 - "$K" "$OUT" <<'PY'
import json, sys
keys = {}
for line in open(sys.argv[1]):
    k, _, v = line.rstrip("\n").partition(" ")
    v = v.strip()
    if v in ("true", "false", "null"): keys[k] = {"true": True, "false": False, "null": None}[v]
    elif v.startswith('"'): keys[k] = v.strip('"')
    else:
        try: keys[k] = int(v)
        except ValueError:
            try: keys[k] = float(v)
            except ValueError: keys[k] = v if v else None
keys["not_run"] = sorted(k for k, v in keys.items() if v is None)
json.dump(keys, open(sys.argv[2], "w"), indent=1)
PY
cat "$OUT"; echo
targets_met=$(python3 -c "
import json,sys; d=json.load(open('$OUT'))
ok = all(d.get(k) is True for k in ['deb_amd64_ok','deb_arm64_ok','deb_armhf_ok','unit_verify_ok','install_start_stop_ok',
  'watchdog_restart_ok','check_config_ok']) and d.get('lintian_errors') == 0 and \
  d.get('check_config_bad_inputs_rejected') == d.get('check_config_bad_inputs_tried')
print('yes' if ok else 'no')")
say "targets met: $targets_met"
[ "$targets_met" = yes ]
