#!/usr/bin/env bash
# Installs the Debian packages the build, the tests and the HIL runs need — only those missing.
# Idempotent: a second run installs nothing. Called by scripts/run.sh and scripts/test.sh.
# The vcan HIL's guest (tests/hil/run-in-guest.sh): user-mode Linux where it starts (probed once
# per host kernel, ~3 s), else QEMU — then qemu-system-x86, and linux-image-amd64 when /boot has
# no readable Debian kernel with 9p and vcan modules. MMLFW_HIL=skip installs no guest.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential g++ cmake ninja-build pkg-config git
  libeigen3-dev libgtest-dev libbenchmark-dev zlib1g-dev libpng-dev libyaml-cpp-dev
  g++-aarch64-linux-gnu g++-arm-linux-gnueabihf qemu-user
  can-utils socat iproute2 kmod busybox-static user-mode-linux
  binutils file python3
  clang libclang-rt-14-dev
)

installed() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }
install() {  # install PACKAGE...: the missing ones
  local missing=() p
  for p in "$@"; do installed "$p" || missing+=("$p"); done
  if [ ${#missing[@]} -eq 0 ]; then return 0; fi
  echo "setup: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "setup: need root (or sudo) to install: ${missing[*]}" >&2; exit 1
  fi
fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
  echo "setup: done"
}
install "${PACKAGES[@]}"

# The vcan HIL's guest. QEMU only where user-mode Linux cannot start (or MMLFW_HIL=qemu).
guest_kernel() {  # a readable /boot/vmlinuz-V with 9p and vcan modules (what run-in-qemu.sh boots)
  local k v
  for k in /boot/vmlinuz-*; do
    v=${k#/boot/vmlinuz-}
    [ -r "$k" ] && [ -n "$(find "/lib/modules/$v" -name 'vcan.ko*' -print -quit 2>/dev/null)" ] &&
      [ -n "$(find "/lib/modules/$v" -name '9p.ko*' -print -quit 2>/dev/null)" ] && return 0
  done
  return 1
}
case "${MMLFW_HIL:-}" in
  skip) echo "setup: MMLFW_HIL=skip: no HIL guest installed" ;;
  *)
    if [ "${MMLFW_HIL:-}" != qemu ] && uml=$(bash tests/hil/run-in-guest.sh --probe-uml 2>/dev/null); then
      echo "setup: vcan HIL guest: user-mode Linux (${uml#uml: })"
    else
      echo "setup: vcan HIL guest: QEMU (${uml:-MMLFW_HIL=qemu})"
      case "$(uname -m)" in
        x86_64)
          install qemu-system-x86
          guest_kernel || install linux-image-amd64
          guest_kernel || echo "setup: WARNING: still no readable /boot/vmlinuz-* with 9p and vcan modules" >&2 ;;
        *) echo "setup: WARNING: the QEMU guest is wired up for x86_64 hosts only (tests/hil/README.md)" >&2 ;;
      esac
    fi ;;
esac
