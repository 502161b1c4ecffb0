#!/bin/bash
# run-in-qemu.sh COMMAND [ARGS...]: runs COMMAND with the same cwd and exported environment inside
# a QEMU guest (qemu-system-x86_64, TCG; KVM only when HIL_QEMU_ACCEL=kvm) booting Debian's own
# kernel from the host's /boot, with vcan0 (FD, MTU 72) and vcan1 (classic, MTU 16). Same contract
# as run-in-uml.sh; see ../shared/notes/vcan-qemu.md and tests/hil/README.md.
#
# Root fs of the guest = the host's / over 9p, READ-ONLY; writable: tmpfs on /tmp /var/tmp /run
# /dev/shm, and the host directories $PWD and those in HIL_GUEST_RW (colon-separated) over 9p
# read-write (the test's outputs land there). Exit status is COMMAND's; 124 = timeout
# (HIL_GUEST_TIMEOUT, default 900 s); 125 = the guest never reported; 78 = no usable QEMU guest on
# this host (reason on stderr).
# Environment: HIL_QEMU_ACCEL (tcg | kvm, default tcg), HIL_QEMU_SMP (default 2 on a multi-core host: the boot
# is 2-4x slower with both host cores busy (6 -> 16-30 s), but mmlfw's workers get a CPU each and the
# HIL localizes sooner; 1 boots in ~7 s), HIL_QEMU_MEM
# (MiB, default 2048), HIL_GUEST_CACHE (where the prepared kernel and initramfs are kept, default
# <source>/build/hil-guest), HIL_QEMU_KERNEL (a vmlinuz to use instead of the newest in /boot).
set -u
here=$(cd "$(dirname "$0")" && pwd)
CACHE=${HIL_GUEST_CACHE:-$here/../../build/hil-guest}
ACCEL=${HIL_QEMU_ACCEL:-tcg}
nogo() { echo "run-in-qemu: no guest: $*" >&2; exit 78; }

command -v qemu-system-x86_64 >/dev/null 2>&1 ||
  nogo "qemu-system-x86_64 not installed (apt-get install qemu-system-x86; scripts/setup.sh)"
[ "$(uname -m)" = x86_64 ] || nogo "host is $(uname -m); only x86_64 hosts are wired up (see tests/hil/README.md)"
[ -x /bin/busybox ] && file -L /bin/busybox 2>/dev/null | grep -q static ||
  nogo "no static /bin/busybox for the initramfs (apt-get install busybox-static)"

# The kernel: HIL_QEMU_KERNEL, else the newest readable /boot/vmlinuz-V whose modules
# (/lib/modules/V) have 9p and vcan — Debian's linux-image-amd64 gives both.
kernel=${HIL_QEMU_KERNEL:-}
[ -z "$kernel" ] || [ -r "$kernel" ] || nogo "HIL_QEMU_KERNEL=$kernel is not readable"
if [ -z "$kernel" ]; then
  for k in $(ls -1 /boot/vmlinuz-* 2>/dev/null | sort -rV); do
    v=${k#/boot/vmlinuz-}
    [ -r "$k" ] || continue
    [ -n "$(find "/lib/modules/$v" -name '9p.ko*' -print -quit 2>/dev/null)" ] || continue
    [ -n "$(find "/lib/modules/$v" -name 'vcan.ko*' -print -quit 2>/dev/null)" ] || continue
    kernel=$k; break
  done
fi
[ -n "$kernel" ] || nogo "no readable /boot/vmlinuz-* with 9p and vcan modules in /lib/modules (apt-get install linux-image-amd64; scripts/setup.sh)"
kver=${kernel##*/vmlinuz-}
[ -d "/lib/modules/$kver" ] || nogo "$kernel has no /lib/modules/$kver"

# Prepared once per kernel (about 2 s): the ELF vmlinux (QEMU boots it via PVH, saving the TCG
# decompression, ~2.5 s per boot) and an initramfs of busybox + the virtio/9p/CAN modules.
prep=$CACHE/$kver
if [ ! -f "$prep/ready" ] || [ "$kernel" -nt "$prep/ready" ] || [ "$here/run-in-qemu.sh" -nt "$prep/ready" ] || [ "$here/qemu-init.sh" -nt "$prep/ready" ]; then
  rm -rf "$prep"; mkdir -p "$prep/root/bin" "$prep/root/mods" "$prep/root/host" "$prep/root/proc" "$prep/root/sys" "$prep/root/dev" ||
    nogo "cannot create $prep"
  if ! python3 - "$kernel" "$prep/vmlinux" <<'PY' 2>"$prep/vmlinux.err"; then
import lzma, sys
d = open(sys.argv[1], "rb").read()
i = d.find(b"\xfd7zXZ\x00")
if i < 0: sys.exit("not an XZ-compressed bzImage")
open(sys.argv[2], "wb").write(lzma.LZMADecompressor().decompress(d[i:]))
PY
    cp "$kernel" "$prep/vmlinux"  # another compression: boot the bzImage itself (slower)
  fi
  cp /bin/busybox "$prep/root/bin/busybox"
  : > "$prep/root/mods/order"
  for m in virtio_pci 9pnet_virtio 9p can_raw can_bcm vcan; do
    modprobe -S "$kver" --show-depends "$m" 2>/dev/null | awk '$1 == "insmod" {print $2}'
  done | awk '!seen[$0]++' | while read -r ko; do
    b=$(basename "$ko"); b=${b%.xz}; b=${b%.zst}
    case "$ko" in
      *.xz) xz -dc "$ko" > "$prep/root/mods/$b" ;;
      *.zst) zstd -qdc "$ko" > "$prep/root/mods/$b" ;;
      *) cp "$ko" "$prep/root/mods/$b" ;;
    esac
    echo "$b" >> "$prep/root/mods/order"
  done
  grep -q '^9p.ko$' "$prep/root/mods/order" && grep -q '^vcan.ko$' "$prep/root/mods/order" ||
    nogo "modprobe -S $kver --show-depends gave no 9p/vcan modules (kmod installed?)"
  cp "$here/qemu-init.sh" "$prep/root/init" && chmod +x "$prep/root/init"
  (cd "$prep/root" && find . | /bin/busybox cpio -o -H newc 2>/dev/null | gzip -1 > "$prep/initrd.gz") ||
    nogo "cannot pack the initramfs"
  touch "$prep/ready"
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/qemu-run.XXXXXX")
trap 'rm -rf "$work"' EXIT
{
  echo '#!/bin/bash'
  export -p | grep -vE '^declare -x (HOME|PWD|OLDPWD|SHLVL|_|TERM)='
  echo 'export HOME=/tmp'
  printf 'cd %q || exit 126\n' "$PWD"
  printf 'exec'; printf ' %q' "$@"; printf '\n'
} > "$work/test.sh"
chmod +x "$work/test.sh"

# 9p exports: tag hostroot = / read-only; rw0 = the work dir; rw1.. = $PWD and HIL_GUEST_RW.
fsargs=(-fsdev "local,id=fs0,path=/,security_model=none,readonly=on,multidevs=remap"
        -device virtio-9p-pci,fsdev=fs0,mount_tag=hostroot)
n=0
: > "$work/rw"
IFS=: read -r -a extra <<< "${HIL_GUEST_RW:-}"
for d in "$work" "$PWD" "${extra[@]}"; do
  [ -n "$d" ] && [ -d "$d" ] || continue
  d=$(cd "$d" && pwd -P)
  grep -qxF "$d" <(cut -d' ' -f2- "$work/rw") && continue
  fsargs+=(-fsdev "local,id=rw$n,path=$d,security_model=none,multidevs=remap"
           -device "virtio-9p-pci,fsdev=rw$n,mount_tag=rw$n")
  echo "rw$n $d" >> "$work/rw"
  n=$((n + 1))
done

accel=(-accel tcg,thread=multi)
cpu=()
if [ "$ACCEL" = kvm ]; then accel=(-accel kvm); cpu=(-cpu "${HIL_QEMU_CPU:-max}"); fi
t0=$(date +%s.%N)
timeout -k 10 "${HIL_GUEST_TIMEOUT:-900}" qemu-system-x86_64 "${accel[@]}" "${cpu[@]}" \
  -smp "${HIL_QEMU_SMP:-$(( $(nproc) >= 2 ? 2 : 1 ))}" -m "${HIL_QEMU_MEM:-2048}" \
  -kernel "$prep/vmlinux" -initrd "$prep/initrd.gz" \
  -append "console=ttyS0 quiet loglevel=3 panic=-1 QWORK=$work" \
  -nodefaults -display none -monitor none -serial stdio -no-reboot \
  -device isa-debug-exit,iobase=0xf4,iosize=0x04 \
  "${fsargs[@]}" </dev/null 2> "$work/qemu.err" | tr -d '\r'
qrc=${PIPESTATUS[0]}
echo "run-in-qemu: guest ($ACCEL, kernel $kver) ran $(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN{printf "%.1f", b-a}') s" >&2
grep -v "warning: 9p: Multiple devices\|since paths are not unique\|^$" "$work/qemu.err" >&2
[ "$qrc" = 124 ] && { echo "run-in-qemu: timeout after ${HIL_GUEST_TIMEOUT:-900}s" >&2; exit 124; }
if [ -f "$work/status" ]; then exit "$(cat "$work/status")"; fi
if [ -f "$work/started" ]; then
  echo "run-in-qemu: guest started but reported no status (qemu exit $qrc)" >&2; exit 125
fi
echo "run-in-qemu: guest never started a process (qemu exit $qrc)" >&2
exit 125
