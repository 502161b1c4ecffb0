#!/bin/bash
# run-in-guest.sh COMMAND [ARGS...]: runs COMMAND (same cwd, same exported environment) inside a
# Linux guest that has vcan0 (CAN FD, MTU 72) and vcan1 (classic, MTU 16), choosing the guest:
#   1. user-mode Linux (run-in-uml.sh), if it starts on this host — a probe boot running `true`;
#   2. else QEMU (run-in-qemu.sh): KVM if /dev/kvm is usable and a probe boot reports within
#      HIL_KVM_PROBE_S seconds (default 8; a present /dev/kvm may not work), else TCG.
# The probe results are kept per host kernel in HIL_GUEST_CACHE (default <source>/build/hil-guest),
# so the probes cost their seconds once; HIL_GUEST_REPROBE=1 redoes them.
# HIL_GUEST=uml|qemu|qemu-tcg|qemu-kvm forces a guest. The choice ("uml", "qemu-tcg", "qemu-kvm")
# is printed on stderr and written to the file HIL_GUEST_FILE when set.
# Exit status: COMMAND's; 124 timeout; 125 the guest never reported; 78 = no guest can start on
# this host, with every reason on stderr (callers fail on it; see hil_vcan.sh, MMLFW_HIL=skip).
# `run-in-guest.sh --choose` only chooses (prints the choice); `--probe-uml` only probes UML (exit 0
# when it starts).
set -u
here=$(cd "$(dirname "$0")" && pwd)
CACHE=${HIL_GUEST_CACHE:-$here/../../build/hil-guest}
export HIL_GUEST_CACHE=$CACHE
mkdir -p "$CACHE" 2>/dev/null
probe_file=$CACHE/probe-$(uname -r)
# Stale when a guest's software or a runner changed after the probe.
for f in /usr/bin/linux.uml "$(command -v qemu-system-x86_64 2>/dev/null)" "$here/run-in-uml.sh" "$here/uml-init.sh" \
         "$here/run-in-qemu.sh" "$here/qemu-init.sh" /boot; do
  [ -n "$f" ] && [ -e "$f" ] && [ "$f" -nt "$probe_file" ] && rm -f "$probe_file"
done
[ "${HIL_GUEST_REPROBE:-0}" = 1 ] && rm -f "$probe_file"
probed() { grep -m1 "^$1 " "$probe_file" 2>/dev/null | cut -d' ' -f2-; }
record() { echo "$1 $2" >> "$probe_file"; }

probe_uml() {
  local r t0=$SECONDS out
  if [ -z "$(probed uml)" ]; then
    out=$(UML_TIMEOUT=30 UML_MEM=64M "$here/run-in-uml.sh" true 2>&1 </dev/null); r=$?
    if [ $r = 0 ]; then record uml "ok (probe boot $((SECONDS - t0)) s)"
    else record uml "no: $(echo "$out" | grep -m1 -E 'SKIP|run-in-uml|panic' | sed 's/^run-in-uml: //') (exit $r)"; fi
  fi
  [[ "$(probed uml)" == ok* ]]
}
probe_kvm() {
  local r t0=$SECONDS out
  if [ -z "$(probed kvm)" ]; then
    if [ ! -r /dev/kvm ] || [ ! -w /dev/kvm ]; then record kvm "no: /dev/kvm absent or not usable by $(id -un)"
    else
      out=$(HIL_QEMU_ACCEL=kvm HIL_GUEST_TIMEOUT=${HIL_KVM_PROBE_S:-8} HIL_QEMU_SMP=1 HIL_QEMU_MEM=256 \
              "$here/run-in-qemu.sh" true 2>&1 </dev/null); r=$?
      if [ $r = 0 ]; then record kvm "ok (probe boot $((SECONDS - t0)) s)"
      else record kvm "no: the probe boot did not report within ${HIL_KVM_PROBE_S:-8} s (exit $r${out:+: $(echo "$out" | grep -m1 -E 'error|timeout|no guest' | sed 's/^[a-z0-9_-]*: //')})"; fi
    fi
  fi
  [[ "$(probed kvm)" == ok* ]]
}

if [ "${1:-}" = --probe-uml ]; then  # for scripts/setup.sh: does user-mode Linux start here?
  probe_uml; r=$?; echo "uml: $(probed uml)"; exit $r
fi
guest=${HIL_GUEST:-}
case "$guest" in
  "") if probe_uml; then guest=uml
      elif probe_kvm; then guest=qemu-kvm
      else guest=qemu-tcg; fi ;;
  uml|qemu-tcg|qemu-kvm) ;;
  qemu) if probe_kvm; then guest=qemu-kvm; else guest=qemu-tcg; fi ;;
  *) echo "run-in-guest: HIL_GUEST=$guest: expected uml, qemu, qemu-tcg or qemu-kvm" >&2; exit 2 ;;
esac
why="uml: $(probed uml | grep . || echo not probed)${HIL_GUEST:+; forced by HIL_GUEST=$HIL_GUEST}"
[ "$guest" != uml ] && why="$why; kvm: $(probed kvm)"
echo "run-in-guest: guest $guest ($why)" >&2
[ -n "${HIL_GUEST_FILE:-}" ] && echo "$guest" > "$HIL_GUEST_FILE"
[ "${1:-}" = --choose ] && { echo "$guest"; exit 0; }
[ $# -ge 1 ] || { echo "usage: run-in-guest.sh COMMAND [ARGS...] | --choose" >&2; exit 2; }

if [ "$guest" = uml ]; then
  UML_TIMEOUT=${HIL_GUEST_TIMEOUT:-${UML_TIMEOUT:-900}} "$here/run-in-uml.sh" "$@"
  rc=$?
  # run-in-uml.sh says 77 when UML cannot run here: a probe said it could, so it is no skip.
  [ $rc = 77 ] && { echo "run-in-guest: user-mode Linux did not start (its probe had passed)" >&2; exit 78; }
  exit $rc
fi
HIL_QEMU_ACCEL=${guest#qemu-} "$here/run-in-qemu.sh" "$@"
rc=$?
if [ $rc = 78 ]; then
  echo "run-in-guest: no guest can start on this host: uml: $(probed uml); qemu: see above" >&2
fi
exit $rc
