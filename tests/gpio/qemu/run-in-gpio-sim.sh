#!/usr/bin/env bash
# run-in-gpio-sim.sh TEST_BINARY [ARGS...]
#
# Runs TEST_BINARY inside a qemu guest (TCG, no KVM) whose Debian kernel has the
# real gpio-sim driver loaded, with one simulated chip set up through configfs, and
# exits with the test's own exit code. See README.md beside this file.
#
# Exit status: the test's exit code; 1 when the guest did not report one (timeout,
# kernel panic, setup failure in the guest, qemu error); 77 with one line
# "SKIPPED: <reason>" when this machine cannot run the test at all.
set -euo pipefail

readonly PROG=run-in-gpio-sim
readonly SKIP_CODE=77

skip() { echo "SKIPPED: $*"; exit "$SKIP_CODE"; }
fail() { echo "$PROG: ERROR: $*" >&2; exit 1; }
note() { echo "$PROG: $*" >&2; }

if [[ $# -lt 1 ]]; then
  echo "usage: $0 TEST_BINARY [ARGS...]" >&2
  exit 2
fi
test_arg=$1
shift
[[ -f $test_arg ]] || fail "test binary not found: $test_arg"
[[ -x $test_arg ]] || fail "test binary is not executable: $test_arg"
test_bin=$(readlink -f -- "$test_arg")

cache_root=${PLCFI_GPIO_QEMU_CACHE:-/var/cache/plcfi/gpio-qemu}
qemu_timeout=${PLCFI_GPIO_QEMU_TIMEOUT:-300}
is_root=false
if [[ $(id -u) -eq 0 ]]; then is_root=true; fi

# Temporary directories, removed on any exit (skip, failure or the test's result).
tmp_dirs=()
# shellcheck disable=SC2317  # called from the trap
cleanup() { if [[ ${#tmp_dirs[@]} -gt 0 ]]; then rm -rf "${tmp_dirs[@]}"; fi; }
trap cleanup EXIT
# On INT/TERM/HUP: stop the guest (qemu_pid_file, once it runs), then exit 1 through
# the EXIT trap. Without these traps bash would die without cleaning up, leaving qemu.
qemu_pid_file=
# shellcheck disable=SC2317  # called from the traps
on_signal() {
  trap - INT TERM HUP
  if [[ -n $qemu_pid_file && -s $qemu_pid_file ]]; then
    kill -TERM "$(<"$qemu_pid_file")" 2>/dev/null || true
    wait 2>/dev/null || true
  fi
  echo "$PROG: ERROR: interrupted by SIG$1" >&2
  exit 1
}
trap 'on_signal INT' INT
trap 'on_signal TERM' TERM
trap 'on_signal HUP' HUP

# ---------------------------------------------------------------- host tools
command -v qemu-system-x86_64 >/dev/null 2>&1 ||
  skip "qemu-system-x86_64 not found (Debian package qemu-system-x86; scripts/install-deps installs it)"
for tool in timeout flock ldd apt-cache dpkg-query dpkg-deb tar; do
  command -v "$tool" >/dev/null 2>&1 || skip "host tool '$tool' not found"
done

apt_install() {
  # apt-get install, waiting for a dpkg lock held by another apt rather than failing;
  # once more after apt-get update when the package lists were stale.
  local i
  for i in 1 2; do
    if DEBIAN_FRONTEND=noninteractive apt-get -o DPkg::Lock::Timeout=300 install -y \
        --no-install-recommends "$@" >&2; then
      return 0
    fi
    if [[ $i -eq 1 ]]; then apt-get -o DPkg::Lock::Timeout=300 update >&2 || true; fi
  done
  return 1
}

pkg_version() {  # installed version of a package, empty if not installed
  local st
  st=$(dpkg-query -W -f='${db:Status-Abbrev} ${Version}' "$1" 2>/dev/null || true)
  if [[ $st == ii* ]]; then echo "${st##* }"; fi
}

# busybox-static provides the guest's userland and the cpio writer on the host.
busybox=/bin/busybox
if ! [[ -x $busybox ]] || [[ -z $(pkg_version busybox-static) ]]; then
  if $is_root; then
    note "installing busybox-static"
    apt_install busybox-static || skip "apt-get install busybox-static failed"
  else
    skip "busybox-static is not installed and not running as root to install it"
  fi
fi

# ------------------------------------------------------------- kernel version
# The Debian kernel ABI (e.g. 6.1.0-56) is what linux-image-amd64 depends on.
find_abi() {
  local deps
  deps=$(apt-cache depends linux-image-amd64 2>/dev/null) || return 0
  sed -n 's/^ *Depends: linux-image-\([0-9][^ ]*\)-amd64$/\1/p' <<<"$deps" | head -n1
}
abi=${PLCFI_GPIO_QEMU_ABI:-}
if [[ -z $abi ]]; then
  abi=$(find_abi)
  if [[ -z $abi ]] && $is_root; then
    note "apt knows no linux-image-amd64: running apt-get update"
    apt-get -o DPkg::Lock::Timeout=300 update >&2 || true
    abi=$(find_abi)
  fi
  [[ -n $abi ]] || skip "apt has no linux-image-amd64 to tell the Debian kernel ABI (run apt-get update)"
fi
kver=$abi-amd64                       # e.g. 6.1.0-56-amd64
mm=$(cut -d. -f1,2 <<<"$abi")         # e.g. 6.1
cache=$cache_root/$abi

# ------------------------------------------------------ cache (under a lock)
cache_complete() { [[ -f $cache/complete ]]; }
vermagic() { tr '\0' '\n' <"$1" | sed -n 's/^vermagic=//p' | head -n1; }

prepare_cache() {
  local img_pkg=linux-image-$kver hdr_pkg=linux-headers-$kver src_pkg=linux-source-$mm
  local img_ver src_ver hdr_ver tmp

  local show madison src_avail
  show=$(apt-cache show --no-all-versions "$img_pkg" 2>/dev/null) || true
  img_ver=$(sed -n 's/^Version: //p' <<<"$show" | head -n1)
  [[ -n $img_ver ]] || skip "apt has no package $img_pkg (kernel ABI $abi)"

  # Everything below must be of one kernel version. First check that it can be had,
  # then install what is missing.
  src_ver=$(pkg_version "$src_pkg")
  madison=$(apt-cache madison "$src_pkg" 2>/dev/null) || true
  src_avail=$(awk -F'|' '{gsub(/ /, "", $2); printf "%s ", $2}' <<<"$madison")
  if [[ $src_ver != "$img_ver" && " $src_avail" != *" $img_ver "* ]]; then
    skip "apt has no $src_pkg $img_ver to match $img_pkg $img_ver (installed: ${src_ver:-none}; in apt: ${src_avail:-none})"
  fi
  hdr_ver=$(pkg_version "$hdr_pkg")
  if ! $is_root; then
    [[ -n $hdr_ver ]] || skip "$hdr_pkg is not installed and not running as root to install it"
    [[ -n $src_ver ]] || skip "$src_pkg is not installed and not running as root to install it"
  fi

  # Kernel headers of the same ABI: kbuild for the out-of-tree modules.
  if [[ -z $hdr_ver ]]; then
    note "installing $hdr_pkg"
    apt_install "$hdr_pkg" || skip "apt-get install $hdr_pkg failed"
    hdr_ver=$(pkg_version "$hdr_pkg")
  fi
  local kbuild=/usr/src/linux-headers-$kver
  [[ -f $kbuild/Makefile ]] || skip "$hdr_pkg installed but $kbuild/Makefile is missing"
  if grep -qE '^CONFIG_(IRQ_SIM|GPIO_SIM)=y' "$kbuild/.config" 2>/dev/null; then
    skip "kernel $kver has irq-sim/gpio-sim built in; this harness expects to build them as modules"
  fi

  tmp=$(mktemp -d "$cache_root/.prepare-$abi.XXXXXX")
  tmp_dirs+=("$tmp")

  # Source of the same version as the image: the four files the modules need.
  # Installed when missing; when another version is installed (another kernel ABI),
  # the matching one is downloaded and read here instead, leaving the system's alone.
  if [[ -z $src_ver ]]; then
    note "installing $src_pkg=$img_ver"
    apt_install "$src_pkg=$img_ver" || skip "apt-get install $src_pkg=$img_ver failed"
    src_ver=$(pkg_version "$src_pkg")
  fi
  local tarball=/usr/src/linux-source-$mm.tar.xz
  if [[ $src_ver != "$img_ver" ]]; then
    note "$src_pkg $src_ver is installed; downloading $src_pkg $img_ver to match $img_pkg"
    mkdir "$tmp/src"
    (cd "$tmp/src" && apt-get download "$src_pkg=$img_ver" >"$tmp/download.log" 2>&1) ||
      { cat "$tmp/download.log" >&2; skip "apt-get download $src_pkg=$img_ver failed"; }
    dpkg-deb --fsys-tarfile "$tmp"/src/*.deb | tar -x -C "$tmp/src" "./usr/src/linux-source-$mm.tar.xz" ||
      skip "$src_pkg $img_ver has no usr/src/linux-source-$mm.tar.xz"
    rm -f "$tmp"/src/*.deb
    tarball=$tmp/src/usr/src/linux-source-$mm.tar.xz
    src_ver=$img_ver
  fi
  [[ -f $tarball ]] || skip "$src_pkg $src_ver installed but $tarball is missing"

  # The image: downloaded and unpacked here, never installed. Only vmlinuz and
  # configfs.ko are kept.
  note "downloading $img_pkg $img_ver"
  (cd "$tmp" && apt-get download "$img_pkg=$img_ver" >"$tmp/download.log" 2>&1) ||
    { cat "$tmp/download.log" >&2; skip "apt-get download $img_pkg=$img_ver failed"; }
  local deb
  deb=$(ls "$tmp"/*.deb)
  mkdir "$tmp/image"
  dpkg-deb -x "$deb" "$tmp/image"
  rm -f "$deb"
  mkdir "$tmp/out"
  [[ -f $tmp/image/boot/vmlinuz-$kver ]] || skip "$img_pkg has no boot/vmlinuz-$kver"
  cp "$tmp/image/boot/vmlinuz-$kver" "$tmp/out/vmlinuz"
  local cfs
  cfs=$(find "$tmp/image/lib/modules/$kver" -name 'configfs.ko*' | head -n1)
  if [[ -n $cfs ]]; then
    case $cfs in
      *.ko) cp "$cfs" "$tmp/out/configfs.ko" ;;
      *.ko.xz) xz -dc "$cfs" >"$tmp/out/configfs.ko" ;;
      *.ko.zst) zstd -qdc "$cfs" >"$tmp/out/configfs.ko" ;;
      *.ko.gz) gzip -dc "$cfs" >"$tmp/out/configfs.ko" ;;
      *) skip "unknown module compression: $cfs" ;;
    esac
  elif ! grep -q '^CONFIG_CONFIGFS_FS=y' "$tmp/image/boot/config-$kver" 2>/dev/null; then
    skip "$img_pkg has neither configfs.ko nor configfs built in"
  fi
  rm -rf "$tmp/image"

  # irq-sim and gpio-sim as out-of-tree modules from the matching source. Two
  # changes make them build outside the kernel tree: irq_to_desc() is not exported
  # (generic_handle_irq() calls the same handle_simple_irq the domain sets up), and
  # a module needs a MODULE_LICENSE (GPL, to use the GPL-only exports).
  note "building irq-sim.ko and gpio-sim.ko from $src_pkg $src_ver"
  local b=$tmp/build top=linux-source-$mm
  mkdir "$b"
  tar -xJf "$tarball" -C "$tmp" "$top/drivers/gpio/gpio-sim.c" "$top/drivers/gpio/gpiolib.h" \
    "$top/kernel/irq/irq_sim.c" ||
    skip "$tarball lacks drivers/gpio/gpio-sim.c, gpiolib.h or kernel/irq/irq_sim.c"
  cp "$tmp/$top/drivers/gpio/gpio-sim.c" "$tmp/$top/drivers/gpio/gpiolib.h" "$tmp/$top/kernel/irq/irq_sim.c" "$b/"
  rm -rf "${tmp:?}/$top" "$tmp/src"
  grep -q 'handle_simple_irq(irq_to_desc(irqnum));' "$b/irq_sim.c" ||
    skip "irq_sim.c of $src_pkg $src_ver differs from what this harness patches (no handle_simple_irq(irq_to_desc(irqnum)))"
  sed -i 's/handle_simple_irq(irq_to_desc(irqnum));/generic_handle_irq(irqnum);/' "$b/irq_sim.c"
  grep -q MODULE_LICENSE "$b/irq_sim.c" || {
    printf '\n#include <linux/module.h>\nMODULE_LICENSE("GPL");\nMODULE_DESCRIPTION("Interrupt simulator (out-of-tree build for plcfi tests)");\n' >>"$b/irq_sim.c"
  }
  cat >"$b/Kbuild" <<'EOF'
obj-m := irq-sim.o gpio-sim.o
irq-sim-y := irq_sim.o
EOF
  if ! make -C "$kbuild" M="$b" modules >"$tmp/build.log" 2>&1; then
    tail -n 25 "$tmp/build.log" >&2
    skip "building irq-sim/gpio-sim from $src_pkg $src_ver against $hdr_pkg $hdr_ver failed (kernel/source mismatch?)"
  fi
  cp "$b/irq-sim.ko" "$b/gpio-sim.ko" "$tmp/out/"
  local vm_built vm_kernel
  vm_built=$(vermagic "$tmp/out/gpio-sim.ko")
  if [[ -f $tmp/out/configfs.ko ]]; then
    vm_kernel=$(vermagic "$tmp/out/configfs.ko")
    [[ $vm_built == "$vm_kernel" ]] ||
      skip "built modules' vermagic '$vm_built' differs from the image's '$vm_kernel'"
  fi

  printf 'abi=%s\nimage=%s %s\nheaders=%s %s\nsource=%s %s\nvermagic=%s\n' "$abi" \
    "$img_pkg" "$img_ver" "$hdr_pkg" "$hdr_ver" "$src_pkg" "$src_ver" "$vm_built" >"$tmp/out/complete"
  rm -rf "$cache"
  mv "$tmp/out" "$cache"
}

if ! cache_complete; then
  if ! mkdir -p "$cache_root" 2>/dev/null || ! [[ -w $cache_root ]]; then
    skip "cache $cache_root is not writable and holds no prepared kernel $kver (run once as root, or set PLCFI_GPIO_QEMU_CACHE)"
  fi
  # One preparer at a time (ctest -j): the others wait, then find the cache ready.
  exec 9>"$cache_root/$abi.lock"
  flock -w 1200 9 || fail "timed out waiting for the cache lock $cache_root/$abi.lock"
  if ! cache_complete; then
    rm -rf "$cache_root/.prepare-$abi."*   # left by a preparer that was killed
    start=$SECONDS
    note "preparing kernel $kver with gpio-sim in $cache (once per kernel version)"
    prepare_cache
    note "cache ready in $((SECONDS - start)) s"
  fi
  exec 9>&-
fi

# ---------------------------------------------------------- per-run initramfs
work=$(mktemp -d "${TMPDIR:-/tmp}/plcfi-gpio-qemu.XXXXXX")
tmp_dirs+=("$work")
root=$work/root
mkdir -p "$root"/{bin,sbin,usr/bin,usr/sbin,dev,proc,sys,tmp,etc,modules}

cp "$busybox" "$root/bin/busybox"
for m in configfs irq-sim gpio-sim; do
  if [[ -f $cache/$m.ko ]]; then cp "$cache/$m.ko" "$root/modules/"; fi
done

copy_into_root() {  # copy host path $1 to the same path in the guest (symlinks followed)
  local src=$1 dst=$root$1
  mkdir -p "$(dirname "$dst")"
  if [[ -d $src ]]; then
    mkdir -p "$dst"
    cp -aL "$src/." "$dst/"
  else
    cp -L "$src" "$dst"
  fi
}

copy_libs() {  # every shared object ldd lists for $1, including the dynamic loader
  local out lib
  out=$(ldd "$1" 2>/dev/null) || return 0   # static binary or script: nothing to copy
  while read -r lib; do
    [[ -n $lib && -e $lib ]] || continue
    [[ -e $root$lib ]] || copy_into_root "$lib"
  done < <(sed -n -e 's/^.*=> \(\/[^ ]*\) (0x[0-9a-f]*)$/\1/p' \
                  -e 's/^[[:space:]]*\(\/[^ ]*\) (0x[0-9a-f]*)$/\1/p' <<<"$out")
  if grep -q 'not found' <<<"$out"; then
    fail "ldd $1: $(grep 'not found' <<<"$out" | tr -s '\t\n' '  ')"
  fi
}

cp "$test_bin" "$root/test"
chmod 0755 "$root/test"
copy_libs "$test_bin"

if [[ -n ${PLCFI_GPIO_QEMU_FILES:-} ]]; then
  IFS=: read -r -a extra_files <<<"$PLCFI_GPIO_QEMU_FILES"
  for f in "${extra_files[@]}"; do
    [[ -n $f ]] || continue
    [[ $f == /* ]] || fail "PLCFI_GPIO_QEMU_FILES: not an absolute path: $f"
    [[ -e $f ]] || fail "PLCFI_GPIO_QEMU_FILES: no such file: $f"
    copy_into_root "$f"
    if [[ -f $f && -x $f ]]; then copy_libs "$f"; fi
  done
fi

# Arguments and a few environment variables, as POSIX-quoted shell words.
shq() { local s=${1//\'/\'\\\'\'}; printf "'%s'" "$s"; }
{
  printf 'set --'
  for a in "$@"; do printf ' %s' "$(shq "$a")"; done
  printf '\n'
  for v in ASAN_OPTIONS UBSAN_OPTIONS LSAN_OPTIONS GTEST_FILTER GTEST_REPEAT GTEST_SHUFFLE \
           GTEST_RANDOM_SEED GTEST_BRIEF GTEST_COLOR ${PLCFI_GPIO_QEMU_ENV:-}; do
    [[ $v =~ ^[A-Za-z_][A-Za-z0-9_]*$ ]] || fail "PLCFI_GPIO_QEMU_ENV: not a variable name: $v"
    if [[ -n ${!v+set} ]]; then printf 'export %s=%s\n' "$v" "$(shq "${!v}")"; fi
  done
} >"$root/args.sh"

# A per-run token marks the guest's report line, so no test output is taken for it.
token=$(od -An -N8 -tx8 /dev/urandom | tr -d ' \n')

cat >"$root/init" <<EOF
#!/bin/busybox sh
TOKEN=$token
EOF
cat >>"$root/init" <<'EOF'
/bin/busybox --install -s
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin HOME=/ TMPDIR=/tmp

halt_guest() {           # power off without reporting an exit code: the host fails
  sync
  poweroff -f
  while :; do sleep 60; done
}
die() { echo "plcfi-gpio-qemu: guest setup failed: $*" >&2; halt_guest; }

mount -t proc proc /proc || die "mount proc"
mount -t sysfs sysfs /sys || die "mount sysfs"
mount -t devtmpfs devtmpfs /dev || die "mount devtmpfs"
exec </dev/console >/dev/console 2>&1
stty -onlcr 2>/dev/null   # plain \n to the host, as from a local run
if [ -f /modules/configfs.ko ]; then insmod /modules/configfs.ko || die "insmod configfs.ko"; fi
mount -t configfs configfs /sys/kernel/config || die "mount configfs"
insmod /modules/irq-sim.ko || die "insmod irq-sim.ko"
insmod /modules/gpio-sim.ko || die "insmod gpio-sim.ko"

# One simulated chip: bank0, label plcfi-sim, 8 named lines.
d=/sys/kernel/config/gpio-sim/plcfi
mkdir "$d" "$d/bank0" || die "mkdir $d/bank0"
echo plcfi-sim > "$d/bank0/label" || die "set label"
echo 8 > "$d/bank0/num_lines" || die "set num_lines"
i=0
for name in in0 in1 in2 in3 out0 out1 out2 out3; do
  mkdir "$d/bank0/line$i" && echo "$name" > "$d/bank0/line$i/name" || die "name line$i"
  i=$((i + 1))
done
echo 1 > "$d/live" || die "echo 1 > $d/live"
chip=$(cat "$d/bank0/chip_name") && dev=$(cat "$d/dev_name") || die "read chip_name/dev_name"
[ -n "$chip" ] && [ -n "$dev" ] || die "empty chip_name/dev_name"
export PLCFI_SIM_CHIP="$chip" PLCFI_SIM_LABEL=plcfi-sim PLCFI_SIM_SYSFS="/sys/devices/platform/$dev/$chip"
n=0
while [ ! -c "/dev/$chip" ] && [ $n -lt 50 ]; do sleep 0.1; n=$((n + 1)); done
[ -c "/dev/$chip" ] || die "/dev/$chip did not appear"
[ -f "$PLCFI_SIM_SYSFS/sim_gpio0/pull" ] || die "$PLCFI_SIM_SYSFS/sim_gpio0/pull missing"

. /args.sh
cd /
/test "$@"
rc=$?
echo "plcfi-gpio-qemu[$TOKEN]: test exit status $rc"
stty -onlcr 2>/dev/null   # tcsetattr(TCSADRAIN): waits until the console has sent it all
sleep 0.2
# isa-debug-exit at port 0xf4: qemu exits with status (rc << 1) | 1.
printf "\\$(printf %o $((rc & 255)))" | dd of=/dev/port bs=1 seek=244 count=1 2>/dev/null
echo "plcfi-gpio-qemu: writing the exit code to port 0xf4 failed" >&2
halt_guest
EOF
chmod 0755 "$root/init"

(cd "$root" && find . -mindepth 1 | LC_ALL=C sort | "$busybox" cpio -o -H newc -R 0:0 2>/dev/null) \
  >"$work/initrd.cpio"

# -------------------------------------------------------------------- the run
# stdin from /dev/null: qemu leaves the terminal alone, and parallel runs do not
# share it. The console goes to stdout and to a log the report line is read from.
# qboot (Debian's qemu-system-data) boots -kernel silently and faster than SeaBIOS,
# whose banner and terminal resets would otherwise come first on stdout.
firmware=()
if [[ -f /usr/share/qemu/qboot.rom ]]; then firmware=(-bios /usr/share/qemu/qboot.rom); fi
#
# --foreground keeps qemu in this script's process group, so a Ctrl-C or a signal to
# the group reaches it. The pipeline runs in the background and is waited for with
# `wait`, so that the signal traps run at once rather than after qemu ends.
qemu_pid_file=$work/qemu.pid
{
  timeout --foreground -k 10 "$qemu_timeout" qemu-system-x86_64 -accel tcg -m 512 -smp 1 \
    -nographic -no-reboot -nic none "${firmware[@]}" \
    -device isa-debug-exit,iobase=0xf4,iosize=0x04 \
    -kernel "$cache/vmlinuz" -initrd "$work/initrd.cpio" \
    -append "console=ttyS0 quiet loglevel=3 panic=-1" </dev/null &
  echo $! >"$qemu_pid_file"
  rc=0
  wait $! || rc=$?
  echo "$rc" >"$work/qemu.status"
} | tee "$work/console.log" &
wait $! || true
[[ -s $work/qemu.status ]] || fail "qemu's exit status got lost"
status=$(<"$work/qemu.status")

# Not anchored at the line start: a test's last line may lack its newline.
reported=$(tr -d '\r' <"$work/console.log" |
  sed -n "s/^.*plcfi-gpio-qemu\[$token\]: test exit status \([0-9][0-9]*\)\$/\1/p" | tail -n1)

if [[ $status -eq 124 ]]; then
  fail "the guest did not finish within ${qemu_timeout} s (timeout; see the console output above)"
fi
if [[ $status -eq 137 ]]; then
  fail "qemu was killed (SIGKILL: after ignoring the timeout's SIGTERM, or from outside)"
fi
if [[ -n $reported ]]; then
  # The report line and qemu's status must agree: (rc << 1) | 1, cut to 8 bits.
  if [[ $status -eq $(( ((reported & 255) << 1 | 1) & 255 )) ]]; then
    exit "$reported"
  fi
  fail "the test exited with $reported but qemu exited with status $status (the exit code did not reach isa-debug-exit)"
fi
if (( status % 2 == 1 && status >= 3 )); then
  # The exit code arrived but the console lost the report line.
  exit $(( status >> 1 ))
fi
case $status in
  0) fail "the guest powered off without reporting an exit code (kernel panic or setup failure; see the console output above)" ;;
  1) fail "qemu failed (status 1) and the guest reported no exit code; see the output above" ;;
  *) fail "qemu exited with status $status and the guest reported no exit code" ;;
esac
