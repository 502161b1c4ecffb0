#!/bin/sh
# PID 1 inside User-Mode Linux (see ../shared/notes/vcan-uml.md). Root fs = host / via hostfs.
# Kernel-cmdline env: UML_WORK=<host dir holding test.sh; status is written there>.
# Never let this script exit: PID 1 exiting panics the guest (linux.uml then exits 134).
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin
stty -onlcr 2>/dev/null
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mountpoint -q /dev || mount -t devtmpfs devtmpfs /dev
mkdir -p /dev/shm /dev/pts
mount -t tmpfs -o mode=1777 tmpfs /dev/shm
mount -t devpts -o ptmxmode=666,gid=5,mode=620 devpts /dev/pts
ln -sf /proc/self/fd /dev/fd 2>/dev/null
ip link set lo up
K=/usr/lib/uml/modules/$(uname -r)/kernel
for m in net/can/can.ko net/can/can-raw.ko net/can/can-bcm.ko \
         drivers/net/can/dev/can-dev.ko drivers/net/can/vcan.ko; do
  { command -v insmod >/dev/null && insmod "$K/$m"; } || busybox insmod "$K/$m" \
    || echo "uml-init: insmod $m failed"
done
ip link add dev vcan0 type vcan && ip link set vcan0 mtu 72 && ip link set vcan0 up   # CAN FD
ip link add dev vcan1 type vcan && ip link set vcan1 mtu 16 && ip link set vcan1 up   # classic only
touch "$UML_WORK/started"  # the guest ran a process (run-in-uml.sh tells a host that cannot from a failure)
if [ -x "$UML_WORK/test.sh" ]; then
  { "$UML_WORK/test.sh" </dev/null; echo "$?" > "$UML_WORK/status"; } 2>&1 | cat
fi
rc=$(cat "$UML_WORK/status" 2>/dev/null || echo 125)
echo "$rc" > /proc/exitcode
sync
echo 0 > /proc/sys/kernel/printk
busybox poweroff -f 2>/dev/null || poweroff -f -f 2>/dev/null || echo o > /proc/sysrq-trigger
sleep 30
