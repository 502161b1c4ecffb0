#!/bin/busybox sh
# /init of the QEMU guest's initramfs (packed by run-in-qemu.sh; busybox + modules only).
# Kernel-cmdline env: QWORK=<host dir holding test.sh and rw (9p tags of the writable dirs)>.
# Mounts the host's / read-only over 9p at /host, tmpfs on its writable scratch dirs, the
# read-write 9p exports at their host paths, creates vcan0 (FD) and vcan1 (classic), runs
# QWORK/test.sh chrooted in /host, writes its status to QWORK/status and powers off.
# Never exit: PID 1 exiting panics the guest.
/bin/busybox --install -s /bin
export PATH=/bin
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev
stty -onlcr 2>/dev/null < /dev/console
halt() {
  sync
  echo 0 > /proc/sys/kernel/printk
  # isa-debug-exit: qemu exits with (byte << 1) | 1; the status file is what counts.
  printf '\001' | dd of=/dev/port bs=1 seek=244 count=1 2>/dev/null
  poweroff -f
  echo o > /proc/sysrq-trigger
  sleep 30
}
while read -r m; do insmod "/mods/$m" || echo "qemu-init: insmod $m failed"; done < /mods/order
H=/host
if ! mount -t 9p -o ro,trans=virtio,version=9p2000.L,msize=512000,cache=none hostroot $H; then
  echo "qemu-init: cannot mount the host's / over 9p"; halt
fi
# Writable: tmpfs scratch dirs, then the host's read-write dirs (QWORK first) at their own paths.
for d in tmp var/tmp run; do mount -t tmpfs -o mode=1777 tmpfs "$H/$d"; done
mount -t proc proc $H/proc
mount -t sysfs sysfs $H/sys
mount -t devtmpfs devtmpfs $H/dev
mkdir -p $H/dev/shm $H/dev/pts
mount -t tmpfs -o mode=1777 tmpfs $H/dev/shm
mount -t devpts -o ptmxmode=666,gid=5,mode=620 devpts $H/dev/pts
ln -sf /proc/self/fd $H/dev/fd 2>/dev/null
# rw0 is QWORK (its file rw lists the tags: "rw0 QWORK", "rw1 PATH", ...); a 9p tag mounts once.
mount9p() {
  mkdir -p "$H$2" 2>/dev/null  # under a tmpfs (e.g. /tmp) the directory must be made
  mount -t 9p -o trans=virtio,version=9p2000.L,msize=512000,cache=none "$1" "$H$2"
}
mount9p rw0 "$QWORK" || { echo "qemu-init: cannot mount the work dir $QWORK"; halt; }
while read -r tag path; do
  [ "$tag" = rw0 ] && continue
  mount9p "$tag" "$path" || echo "qemu-init: cannot mount $path read-write"
done < "$H$QWORK/rw"
# The host's iproute2 (busybox's ip does not know every link type).
ip() { chroot $H /sbin/ip "$@"; }
ip link set lo up
ip link add dev vcan0 type vcan && ip link set vcan0 mtu 72 && ip link set vcan0 up   # CAN FD
ip link add dev vcan1 type vcan && ip link set vcan1 mtu 16 && ip link set vcan1 up   # classic only
touch "$H$QWORK/started"
if [ -x "$H$QWORK/test.sh" ]; then
  { chroot $H /bin/bash "$QWORK/test.sh" </dev/null; echo "$?" > "$H$QWORK/status"; } 2>&1 | cat
fi
halt
