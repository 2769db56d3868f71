#!/bin/sh
# Runs a command inside a small virtual machine whose kernel has SocketCAN and vcan, for
# the hardware-in-the-loop tests (this build machine's kernel may have no CAN at all).
#
#   run_in_vm.sh --cache DIR --work DIR [--timeout S] [--file SRC[:NAME]]... -- COMMAND
#
# The machine: qemu-system-x86_64 with TCG (no KVM needed), 512 MiB, serial console only.
# Kernel: the vmlinuz of the Debian package linux-image-amd64 depends on, fetched once
# with `apt-get download` into the cache DIR and unpacked with `dpkg -x`. Initramfs (cpio
# newc, gzip): busybox-static, the kernel's can, can-raw, can-dev and vcan modules
# (decompressed when the package ships .ko.xz; busybox insmod loads them in that order),
# and every --file under /test/NAME. /init mounts proc/sys/dev, loads the modules, runs
# COMMAND with /bin/sh -c in /test, prints "@@HIL-EXIT <status>@@" on the console and
# powers off. This script prints the console output and exits with COMMAND's status;
# 77 (skipped) when qemu, busybox, cpio or the kernel package cannot be had; 124 when
# the machine does not finish within the timeout (default 300 s).
set -eu

cache=""
work=""
timeout_s=300
files=""
while [ $# -gt 0 ]; do
  case "$1" in
    --cache) cache=$2; shift 2 ;;
    --work) work=$2; shift 2 ;;
    --timeout) timeout_s=$2; shift 2 ;;
    --file) files="$files $2"; shift 2 ;;
    --) shift; break ;;
    *) echo "run_in_vm.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
[ -n "$cache" ] && [ -n "$work" ] && [ $# -ge 1 ] || { echo "usage: see the header of $0" >&2; exit 2; }
command_line=$*

skip() { echo "SKIP: $*"; exit 77; }

for tool in qemu-system-x86_64 cpio gzip dpkg; do
  command -v "$tool" >/dev/null 2>&1 || skip "$tool not found (Debian packages qemu-system-x86, cpio; tools/quickstart.sh test installs them)"
done
busybox=""
for b in /bin/busybox /usr/bin/busybox; do
  if [ -x "$b" ] && file -L "$b" 2>/dev/null | grep -q 'statically linked'; then busybox=$b; fi
done
if [ -z "$busybox" ] && [ -x /bin/busybox ] && ! ldd /bin/busybox >/dev/null 2>&1; then busybox=/bin/busybox; fi
[ -n "$busybox" ] || skip "no statically linked busybox (Debian package busybox-static)"

# ---- kernel: the package linux-image-amd64 depends on, cached
mkdir -p "$cache" "$work"
cache=$(cd "$cache" && pwd)
work=$(cd "$work" && pwd)
pkg=$(apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-[0-9]/ {print $2; exit}')
if [ -z "$pkg" ]; then
  # No package index: fall back to whatever kernel is already in the cache.
  pkg=$(ls "$cache" 2>/dev/null | grep '^linux-image-[0-9].*-amd64$' | tail -n 1 || true)
fi
[ -n "$pkg" ] || skip "cannot tell which kernel package linux-image-amd64 depends on (no apt index, empty cache $cache)"
kroot=$cache/$pkg
if [ ! -d "$kroot/boot" ]; then
  ( cd "$cache" && rm -f "$pkg"_*.deb && apt-get download "$pkg" >"$cache/download.log" 2>&1 ) ||
    skip "apt-get download $pkg failed (no network or mirror?): $(tail -n 1 "$cache/download.log")"
  deb=$(ls "$cache"/"$pkg"_*.deb | head -n 1)
  rm -rf "$kroot.tmp"
  dpkg -x "$deb" "$kroot.tmp" && mv "$kroot.tmp" "$kroot"
  rm -f "$deb"
fi
vmlinuz=$(ls "$kroot"/boot/vmlinuz-* | head -n 1)
kver=${vmlinuz##*/vmlinuz-}
version=$(cat "$kroot.version" 2>/dev/null || true)
if [ -z "$version" ]; then
  version=$(apt-cache policy "$pkg" 2>/dev/null | awk '/Candidate:/ {print $2}')
  echo "$version" >"$kroot.version"
fi
echo "HIL machine: kernel $pkg ${version:-?} ($kver), qemu $(qemu-system-x86_64 --version | head -n 1 | awk '{print $4}')"

# ---- initramfs
root=$work/initramfs
rm -rf "$root"
mkdir -p "$root/bin" "$root/sbin" "$root/proc" "$root/sys" "$root/dev" "$root/tmp" "$root/lib/modules" "$root/test"
cp "$busybox" "$root/bin/busybox"
for m in net/can/can net/can/can-raw drivers/net/can/dev/can-dev drivers/net/can/vcan; do
  src=$kroot/lib/modules/$kver/kernel/$m
  name=${m##*/}
  if [ -f "$src.ko" ]; then cp "$src.ko" "$root/lib/modules/$name.ko"
  elif [ -f "$src.ko.xz" ]; then xz -dc "$src.ko.xz" >"$root/lib/modules/$name.ko"
  elif [ -f "$src.ko.zst" ]; then zstd -dc "$src.ko.zst" >"$root/lib/modules/$name.ko"
  else skip "kernel package $pkg has no module $m"
  fi
done
for f in $files; do
  src=${f%%:*}
  name=${f#*:}
  [ "$name" = "$f" ] && name=${src##*/}
  [ -f "$src" ] || { echo "run_in_vm.sh: --file $src does not exist" >&2; exit 2; }
  cp "$src" "$root/test/$name"
done
printf '%s\n' "$command_line" >"$root/test/command"
cat >"$root/init" <<'INIT'
#!/bin/busybox sh
/bin/busybox --install -s /bin
mount -t proc proc /proc
mount -t sysfs sys /sys
mount -t devtmpfs dev /dev 2>/dev/null
for m in can can-raw can-dev vcan; do
  insmod /lib/modules/$m.ko || echo "init: insmod $m failed"
done
ip link set lo up
cd /test
echo "@@HIL-START@@"
/bin/sh -c "$(cat /test/command)"
rc=$?
echo "@@HIL-EXIT $rc@@"
poweroff -f
INIT
chmod +x "$root/init"
( cd "$root" && find . | cpio -o -H newc --quiet | gzip -1 ) >"$work/initramfs.cpio.gz"

# ---- boot
console=$work/console.log
start=$(date +%s.%N)
set +e
timeout -k 5 "$timeout_s" qemu-system-x86_64 -accel tcg -m 512M -nographic -no-reboot \
  -kernel "$vmlinuz" -initrd "$work/initramfs.cpio.gz" \
  -append "console=ttyS0 quiet loglevel=3 panic=-1" </dev/null >"$console" 2>&1
qemu_rc=$?
set -e
end=$(date +%s.%N)
tr -d '\r' <"$console" | sed -n '/@@HIL-START@@/,/@@HIL-EXIT/p' | grep -v '@@HIL-' || true  # the command may print nothing
elapsed=$(awk -v a="$start" -v b="$end" 'BEGIN {printf "%.1f", b - a}')
rc=$(tr -d '\r' <"$console" | sed -n 's/.*@@HIL-EXIT \([0-9]*\)@@.*/\1/p' | tail -n 1)
if [ -z "$rc" ]; then
  echo "FAIL: the machine gave no exit status (qemu status $qemu_rc after ${elapsed} s); console tail:"
  tr -d '\r' <"$console" | tail -n 30
  [ "$qemu_rc" = 124 ] && exit 124
  exit 1
fi
echo "HIL machine: command exited $rc; boot to power-off ${elapsed} s"
exit "$rc"
