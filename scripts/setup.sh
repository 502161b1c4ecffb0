#!/usr/bin/env bash
# Installs the Debian packages the build, the tests and the HIL runs need — only those missing.
# Idempotent: a second run installs nothing. Called by scripts/run.sh and scripts/test.sh.
set -euo pipefail

PACKAGES=(
  build-essential g++ cmake ninja-build pkg-config git
  libeigen3-dev libgtest-dev libbenchmark-dev zlib1g-dev libpng-dev
  g++-aarch64-linux-gnu g++-arm-linux-gnueabihf qemu-user
  can-utils socat iproute2 kmod busybox-static user-mode-linux
  binutils file python3
  clang libclang-rt-14-dev
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages present"
  exit 0
fi

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
