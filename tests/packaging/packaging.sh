#!/usr/bin/env bash
# The packaging tests (tests/packaging/CMakeLists.txt runs each step as one CTest test).
#
#   packaging.sh sysroot  ARCH SRC SYSROOT          target libraries for a cross build
#   packaging.sh build    ARCH SRC DIR [SYSROOT]    configure preset package-ARCH in DIR, build, cpack
#   packaging.sh contents ARCH DIR                  check the .deb files of DIR/packages
#   packaging.sh consumer ARCH DIR SRC WORK [SYSROOT]
#                                                   build tests/packaging/consumer against the
#                                                   unpacked libsdpslam-dev and run it (under
#                                                   qemu for a foreign ARCH)
#   packaging.sh qemu     ARCH DIR AMD64_DIR WORK SYSROOT
#                                                   run the packaged ARCH programs under qemu-user
#                                                   and compare with the amd64 package's output
#
# Exit status: 0 pass, 1 fail (the message says what), 77 skipped (a prerequisite of the
# machine is missing: the message says which).
set -euo pipefail

say() { printf 'packaging: %s\n' "$*"; }
fail() { printf 'packaging: FAIL: %s\n' "$*" >&2; exit 1; }
skip() { printf 'packaging: SKIPPED: %s\n' "$*" >&2; exit 77; }
jobs=${SDPSLAM_PACKAGING_JOBS:-2}

triplet_of() {
  case "$1" in
    amd64) echo x86_64-linux-gnu ;;
    arm64) echo aarch64-linux-gnu ;;
    armhf) echo arm-linux-gnueabihf ;;
    *) fail "unknown architecture $1" ;;
  esac
}
qemu_of() {
  case "$1" in arm64) echo qemu-aarch64 ;; armhf) echo qemu-arm ;; *) echo "" ;; esac
}
elf_machine_of() {
  case "$1" in amd64) echo 'Advanced Micro Devices X86-64' ;; arm64) echo AArch64 ;; armhf) echo ARM ;; esac
}
# Command prefix that runs a program of ARCH on this machine (empty when native).
runner_of() {  # ARCH SYSROOT
  local q; q=$(qemu_of "$1")
  [ -z "$q" ] && return 0
  command -v "$q" >/dev/null || skip "$q is not installed (apt-get install qemu-user)"
  local t; t=$(triplet_of "$1")
  echo "$q -L /usr/$t -E LD_LIBRARY_PATH=$2/usr/lib/$t:$2/lib/$t"
}
deb_of() {  # DIR PACKAGE ARCH
  local f
  f=$(ls "$1"/packages/"$2"_*_"$3".deb 2>/dev/null | head -n1)
  [ -n "$f" ] || fail "no $2 package for $3 in $1/packages"
  echo "$f"
}
elapsed() { echo $(( $(date +%s) - $1 )); }

cmd=${1:-}
shift || true
case "$cmd" in
sysroot)
  arch=$1 src=$2 sysroot=$3
  t=$(triplet_of "$arch")
  # Plain multiarch first (apt-get install libpng-dev:ARCH ...): then no folder is needed
  # and cmake/SdpslamTargetSysroot.cmake, finding none, leaves the search paths alone.
  # (libyaml-cpp-dev is not Multi-Arch: same, so beside the build machine's own it comes
  # from the folder.)
  if [ -e "/usr/lib/$t/libpng16.so" ] && [ -e "/usr/lib/$t/libz.so" ] && [ -e "/usr/lib/$t/libinih.so" ] \
     && [ -e "/usr/lib/$t/libyaml-cpp.so" ]; then
    rm -rf "$sysroot"
    say "the $arch libpng, zlib, inih and yaml-cpp are installed through multiarch: no sysroot needed"
    exit 0
  fi
  "$src/cmake/fetch-target-sysroot.sh" "$arch" "$sysroot" \
    || skip "cannot get the $arch libpng/zlib/inih/yaml-cpp: not installed through multiarch, and apt-get download failed"
  ;;

build)
  arch=$1 src=$2 dir=$3 sysroot=${4:-}
  start=$(date +%s)
  args=(-S "$src" --preset "package-$arch" -B "$dir")
  [ -n "$sysroot" ] && args+=("-DSDPSLAM_TARGET_SYSROOT=$sysroot")
  cmake "${args[@]}" >"$dir.configure.log" 2>&1 || { cat "$dir.configure.log"; fail "configure package-$arch"; }
  cmake --build "$dir" -j "$jobs" || fail "build package-$arch"
  rm -rf "$dir/packages"
  (cd "$dir" && cpack --config CPackConfig.cmake) || fail "cpack package-$arch"
  say "package-$arch built in $(elapsed "$start") s:"
  for f in "$dir"/packages/*.deb; do
    printf '  %-40s %8d bytes  %3d files\n' "$(basename "$f")" "$(stat -c %s "$f")" \
      "$(dpkg-deb -c "$f" | grep -vc '/$')"
  done
  ;;

contents)
  arch=$1 dir=$2
  t=$(triplet_of "$arch")
  rt=$(deb_of "$dir" sdpslam "$arch")
  dev=$(deb_of "$dir" libsdpslam-dev "$arch")
  errors=0
  bad() { printf 'packaging: FAIL: %s\n' "$*" >&2; errors=$((errors + 1)); }
  has() {  # DEB PATH
    # grep reads the whole listing (no -q): a grep that quits at the first match makes
    # dpkg-deb die of SIGPIPE, which pipefail turns into a false "lacks".
    dpkg-deb -c "$1" | awk '{print $6}' | grep -x "./${2#/}" >/dev/null || bad "$(basename "$1") lacks /${2#/}"
  }
  for deb in "$rt" "$dev"; do
    a=$(dpkg-deb -f "$deb" Architecture)
    [ "$a" = "$arch" ] || bad "$(basename "$deb"): Architecture is '$a', not $arch"
    # Everything under /usr or /etc; no trace of the build machine.
    stray=$(dpkg-deb -c "$deb" | awk '{print $6}' | grep -Ev '^\./(usr|etc)(/|$)|^\./$' || true)
    [ -z "$stray" ] && true || bad "$(basename "$deb") has files outside /usr and /etc: $stray"
    owners=$(dpkg-deb -c "$deb" | awk '{print $2}' | sort -u | tr '\n' ' ')
    [ "$owners" = "root/root " ] || bad "$(basename "$deb"): owners are $owners, not root/root"
  done

  # Runtime package: programs for the right machine, and what the daemon needs.
  has "$rt" usr/bin/sdpslam
  daemon=0
  [ -e "$dir/firmware-host/sdpslamd" ] && daemon=1
  if [ $daemon = 1 ]; then
    has "$rt" usr/bin/sdpslamd
    has "$rt" etc/sdpslamd/sdpslamd.ini
    has "$rt" usr/lib/sysusers.d/sdpslamd.conf
    has "$rt" usr/lib/tmpfiles.d/sdpslamd.conf
    has "$rt" usr/lib/systemd/system/sdpslamd.service
    dpkg-deb -I "$rt" conffiles 2>/dev/null | grep -qx /etc/sdpslamd/sdpslamd.ini \
      || bad "/etc/sdpslamd/sdpslamd.ini is not a conffile"
    dpkg-deb -I "$rt" postinst 2>/dev/null | grep -q 'systemd-sysusers sdpslamd.conf' || bad "postinst does not create the user"
    dpkg-deb -I "$rt" postinst 2>/dev/null | grep -Eq '^[^#]*systemctl[^#]*(enable|start)' \
      && bad "postinst enables or starts the service (left to the administrator)"
    # Every absolute file the unit names (programs, --config, Documentation=) is shipped.
    unit=$(dpkg-deb --fsys-tarfile "$rt" | tar -xOf - ./usr/lib/systemd/system/sdpslamd.service)
    for path in $(printf '%s\n' "$unit" | grep -E '^(ExecStart|ExecStartPre|Documentation)=' \
                  | grep -oE '(file:)?/(usr|etc)/[^ ]+' | sed 's/^file://' | sort -u); do
      has "$rt" "$path"
    done
    has "$rt" usr/share/man/man8/sdpslamd.8.gz
    dpkg-deb -I "$rt" prerm 2>/dev/null | grep -Eq "^[^#]*deb-systemd-invoke stop 'sdpslamd.service'" \
      || bad "prerm does not stop the service before the program is removed"
  else
    say "sdpslamd is not part of this tree yet: daemon files not checked"
  fi
  # What Debian asks of every package: a changelog, and a manual page per program.
  has "$rt" usr/share/doc/sdpslam/changelog.Debian.gz
  has "$dev" usr/share/doc/libsdpslam-dev/changelog.Debian.gz
  has "$rt" usr/share/man/man1/sdpslam.1.gz
  # The daemon's manual page names every option its --help lists (built for this machine).
  if [ "$arch" = amd64 ] && [ $daemon = 1 ]; then
    page=$(dpkg-deb --fsys-tarfile "$rt" | tar -xOf - ./usr/share/man/man8/sdpslamd.8.gz | gunzip | sed 's/\\-/-/g')
    for opt in $("$dir/firmware-host/sdpslamd" --help 2>&1 | grep -oE -- '--[a-z][a-z-]+' | sort -u); do
      printf '%s\n' "$page" | grep -qF -- "$opt" || bad "sdpslamd.8 does not document $opt (sdpslamd --help lists it)"
    done
  fi
  # lintian at error and warning level. Findings that stay until the project has them: a
  # licence (no-copyright-file) and a maintainer address (bogus-mail-host, also in the
  # changelog; set -DSDPSLAM_DEB_MAINTAINER=... when packaging); and, as the packages are
  # not uploaded to Debian, no ITP bug for the first changelog entry to close.
  # Anything else fails.
  if command -v lintian > /dev/null; then
    for deb in "$rt" "$dev"; do
      findings=$(lintian --tag-display-limit 0 \
                   --suppress-tags no-copyright-file,bogus-mail-host,bogus-mail-host-in-debian-changelog,initial-upload-closes-no-bugs \
                   "$deb" 2>/dev/null | grep -E '^[EW]: ' || true)
      if [ -n "$findings" ]; then bad "lintian: $findings"; else say "lintian $(basename "$deb"): clean but for the licence and address"; fi
    done
  else
    say "lintian is not installed: the packages' policy checks were not run (apt-get install lintian)"
  fi
  stage=$(mktemp -d)
  trap 'rm -rf "$stage"' EXIT
  dpkg -x "$rt" "$stage/rt"
  dpkg -x "$dev" "$stage/dev"
  machine=$(elf_machine_of "$arch")
  depends=$(dpkg-deb -f "$rt" Depends)
  say "sdpslam Depends: $depends"
  for bin in "$stage"/rt/usr/bin/*; do
    readelf -h "$bin" | grep -q "Machine:.*$machine" || bad "$(basename "$bin") is not a $arch ($machine) program"
    # Every shared library the program needs must come from a package in Depends.
    for so in $(readelf -d "$bin" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'); do
      case "$so" in
        libc.so.*|libm.so.*|libutil.so.*|libpthread.so.*|libdl.so.*|librt.so.*|ld-linux*) pkg=libc6 ;;
        libstdc++.so.*) pkg=libstdc++6 ;;
        libgcc_s.so.*) pkg=libgcc-s1 ;;
        libpng16.so.*) pkg=libpng16-16 ;;
        libz.so.*) pkg=zlib1g ;;
        libinih.so.*) pkg=libinih1 ;;
        libyaml-cpp.so.0.7) pkg=libyaml-cpp0.7 ;;
        *) bad "$(basename "$bin") needs $so, which this test cannot map to a package"; continue ;;
      esac
      printf '%s\n' "$depends" | tr ',' '\n' | sed 's/^ *//; s/ .*//' | grep -qx "$pkg" \
        || bad "$(basename "$bin") needs $so but Depends lacks $pkg"
    done
  done
  # The libc6 version in Depends covers the newest glibc symbol version used.
  libc_min=$(printf '%s\n' "$depends" | tr ',' '\n' | sed -n 's/^ *libc6 (>= \([0-9.]*\)).*/\1/p')
  glibc_max=$(for bin in "$stage"/rt/usr/bin/*; do readelf -V "$bin"; done | grep -o 'GLIBC_[0-9.]*' | sed 's/GLIBC_//' | sort -V | tail -n1)
  [ -n "$libc_min" ] || bad "Depends has no versioned libc6"
  if [ -n "$glibc_max" ] && [ -n "$libc_min" ] && [ "$(printf '%s\n%s\n' "$glibc_max" "$libc_min" | sort -V | tail -n1)" != "$libc_min" ]; then
    bad "the programs use GLIBC_$glibc_max symbols but Depends asks only libc6 (>= $libc_min)"
  fi
  say "newest glibc symbol version used: ${glibc_max:-none}; Depends: libc6 (>= $libc_min)"
  if [ "$arch" = amd64 ]; then
    # The list stated for cross builds names the same packages dpkg-shlibdeps finds here.
    stated=$(sed -n 's/^SDPSLAM_DEB_CROSS_DEPENDS:STRING=//p' "$dir/CMakeCache.txt" | tr ',' '\n' | sed 's/^ *//; s/ .*//' | sort | tr '\n' ' ')
    found=$(printf '%s\n' "$depends" | tr ',' '\n' | sed 's/^ *//; s/ .*//' | sort -u | tr '\n' ' ')
    [ "$stated" = "$found" ] || bad "cross Depends names '$stated' but dpkg-shlibdeps finds '$found'"
  fi

  # Development package: headers, static libraries, CMake package.
  for h in core/arena.h core/pool.h core/pose2.h core/bottom/dpslam_filter.h core/sdp_slam.h core/sdp_stats.h \
           hal/clock.h drivers/linux_clock.h drivers/scip2.h drivers/socketcan_bus.h io/log_reader.h io/trajectory_io.h; do
    has "$dev" "usr/include/sdpslam/$h"
  done
  # The core's own headers (core/src: the parts behind SdpSlam) are not API.
  srcdir=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$dir/CMakeCache.txt")
  headers=$(dpkg-deb -c "$dev" | awk '{print $6}')
  for h in $(cd "$srcdir/core/src" && find . -name '*.h' | sed 's|^\./||'); do
    ! grep -qx "./usr/include/sdpslam/core/$h" <<<"$headers" \
      || bad "$(basename "$dev") ships the core's private header core/src/$h"
  done
  for l in core drivers_common drivers_can drivers_serial io; do
    has "$dev" "usr/lib/$t/libsdpslam_$l.a"
    if [ -f "$stage/dev/usr/lib/$t/libsdpslam_$l.a" ]; then
      obj=$(cd "$stage" && ar x --output="$stage" "dev/usr/lib/$t/libsdpslam_$l.a" && ls "$stage"/*.o | head -n1)
      readelf -h "$obj" | grep -q "Machine:.*$machine" || bad "libsdpslam_$l.a is not $arch code"
      rm -f "$stage"/*.o
    fi
  done
  for c in sdpslamConfig.cmake sdpslamConfigVersion.cmake sdpslamTargets.cmake sdpslamTargets-release.cmake; do
    has "$dev" "usr/lib/$t/cmake/sdpslam/$c"
  done
  grep -qF -e "$srcdir" -e "$dir" "$stage"/dev/usr/lib/"$t"/cmake/sdpslam/*.cmake \
    && bad "the CMake package names a path of the build machine"
  ! dpkg-deb -f "$dev" Depends | grep -q libeigen3-dev || bad "libsdpslam-dev depends on libeigen3-dev, which nothing uses"
  [ -z "$(find "$stage/dev" -name '*.so*')" ] || bad "libsdpslam-dev ships a shared library"

  for deb in "$rt" "$dev"; do
    say "$(basename "$deb"): $(stat -c %s "$deb") bytes, installed size $(dpkg-deb -f "$deb" Installed-Size) KiB"
    dpkg-deb -c "$deb" | awk '$6 !~ /\/$/ {printf "    %8d %s\n", $3, $6}'
  done
  [ $errors = 0 ] || fail "$errors problem(s) in the $arch packages"
  say "$arch packages: contents, architecture and Depends as expected"
  ;;

consumer)
  arch=$1 dir=$2 src=$3 work=$4 sysroot=${5:-}
  t=$(triplet_of "$arch")
  dev=$(deb_of "$dir" libsdpslam-dev "$arch")
  rm -rf "$work"
  mkdir -p "$work/scratch"
  dpkg -x "$dev" "$work/stage"
  version=$(dpkg-deb -f "$dev" Version)
  version=${version%%-*}
  major=${version%%.*}
  args=(-S "$src/tests/packaging/consumer" -G Ninja -DCMAKE_BUILD_TYPE=Release
        "-DCMAKE_PREFIX_PATH=$work/stage/usr")
  if [ "$arch" != amd64 ]; then
    toolchain=$src/toolchains/$t.cmake
    # The installed package and the target's libpng/zlib are both "target" roots.
    args+=("-DCMAKE_TOOLCHAIN_FILE=$toolchain" "-DCMAKE_FIND_ROOT_PATH=$work/stage;$sysroot"
           "-DCMAKE_EXE_LINKER_FLAGS=-Wl,-rpath-link,$sysroot/usr/lib/$t:$sysroot/lib/$t")
  fi
  # SameMajorVersion: the next major must be refused, this one accepted.
  if cmake "${args[@]}" -B "$work/wrong-major" "-DSDPSLAM_WANT_VERSION=$((major + 1)).0" >"$work/wrong-major.log" 2>&1; then
    fail "find_package(sdpslam $((major + 1)).0) accepted version $version"
  fi
  grep -q 'compatible with requested version' "$work/wrong-major.log" || { cat "$work/wrong-major.log"; fail "refused for another reason than the version"; }
  say "find_package(sdpslam $((major + 1)).0) refused version $version, as it should"
  cmake "${args[@]}" -B "$work/build" "-DSDPSLAM_WANT_VERSION=$major.0" >"$work/configure.log" 2>&1 \
    || { cat "$work/configure.log"; fail "consumer configure against the installed package"; }
  grep 'sdpslam .* from' "$work/configure.log" | sed 's/^-- /packaging: /'
  cmake --build "$work/build" -j "$jobs" || fail "consumer build"
  runner=$(runner_of "$arch" "$sysroot")
  # shellcheck disable=SC2086
  $runner "$work/build/consumer" "$work/scratch" || fail "consumer run"
  ;;

qemu)
  arch=$1 dir=$2 native_dir=$3 work=$4 sysroot=$5
  runner=$(runner_of "$arch" "$sysroot")
  rm -rf "$work"
  mkdir -p "$work"
  dpkg -x "$(deb_of "$dir" sdpslam "$arch")" "$work/$arch"
  dpkg -x "$(deb_of "$native_dir" sdpslam amd64)" "$work/amd64"
  # Short jobs of the packaged tool on both architectures, compared byte for byte
  # (determinism across platforms is a project rule): the simulator, then the offline
  # DP-SLAM runner on one and the same input (the amd64 simulation's log).
  # SDPSLAM_KNOWN_ARCH_DIFFERENCES lists outputs known to differ ("job/file ..."): they
  # are reported as such; any other difference fails the test.
  known=" ${SDPSLAM_KNOWN_ARCH_DIFFERENCES:-} "
  differ=()
  job() {  # NAME ARGS... : runs `sdpslam ARGS --out DIR` on amd64 and ARCH, compares
    local name=$1 t0 native_s
    shift
    t0=$(date +%s)
    "$work/amd64/usr/bin/sdpslam" "$@" --out "$work/$name-amd64" >"$work/$name-amd64.log" 2>&1 \
      || { cat "$work/$name-amd64.log"; fail "amd64 sdpslam $*"; }
    native_s=$(elapsed "$t0")
    t0=$(date +%s)
    # shellcheck disable=SC2086
    $runner "$work/$arch/usr/bin/sdpslam" "$@" --out "$work/$name-$arch" >"$work/$name-$arch.log" 2>&1 \
      || { cat "$work/$name-$arch.log"; fail "$arch sdpslam $* under $(qemu_of "$arch")"; }
    say "sdpslam $*: amd64 ${native_s} s, $arch under $(qemu_of "$arch") $(elapsed "$t0") s"
    diff <(cd "$work/$name-amd64" && ls) <(cd "$work/$name-$arch" && ls) || fail "$name: different sets of output files"
    local f base a b lines
    for f in "$work/$name-amd64"/*; do
      base=$(basename "$f")
      a=$f b=$work/$name-$arch/$base
      if [ "$base" = stats.json ]; then  # wall time and memory use are measurements
        grep -v '"timing"' "$f" >"$work/$name-amd64.stats" && a=$work/$name-amd64.stats
        grep -v '"timing"' "$b" >"$work/$name-$arch.stats" && b=$work/$name-$arch.stats
      elif [ "$base" = manifest.txt ]; then  # lists stats.json's size and checksum
        grep -v ' stats.json$' "$f" >"$work/$name-amd64.manifest" && a=$work/$name-amd64.manifest
        grep -v ' stats.json$' "$b" >"$work/$name-$arch.manifest" && b=$work/$name-$arch.manifest
      fi
      if cmp -s "$a" "$b"; then
        say "  identical: $name/$base ($(stat -c %s "$f") bytes)"
      else
        lines=$(cmp -l "$a" "$b" 2>/dev/null | wc -l)
        if [ "${known#* $name/$base }" != "$known" ]; then
          say "  KNOWN DIFFERENCE: $name/$base: $lines of $(stat -c %s "$a") bytes differ, first at $(cmp "$a" "$b" 2>&1 | head -n1 | sed 's/.* differ: //')"
        else
          say "  DIFFERENT: $name/$base: $lines of $(stat -c %s "$a") bytes differ, first at $(cmp "$a" "$b" 2>&1 | head -n1 | sed 's/.* differ: //')"
          differ+=("$name/$base")
        fi
      fi
    done
  }
  job sim simulate --max-duration 20
  job run run "$work/sim-amd64/sim.clf" --mode dpslam --particles 10 --seed 1
  [ ${#differ[@]} = 0 ] || fail "$arch output differs from amd64 in: ${differ[*]}"
  say "$arch and amd64 outputs agree (known differences listed above, if any)"

  # The packaged daemon on a short replay: the simulated log's odometry as a candump
  # (sdpslamd --can-candump) and its scans served as a SCIP 2.0 laser on a pty by the
  # amd64 tool; sdpslamd runs under qemu with the package's own configuration file.
  daemon=$work/$arch/usr/bin/sdpslamd
  if [ ! -x "$daemon" ]; then
    say "no sdpslamd in the $arch package: daemon replay not run"
    exit 0
  fi
  host=$work/amd64/usr/bin/sdpslam
  log=$work/sim-amd64/sim.clf
  [ -f "$log" ] || fail "the simulation wrote no sim.clf"
  ini=$work/$arch/etc/sdpslamd/sdpslamd.ini
  [ -f "$ini" ] || fail "the $arch package has no /etc/sdpslamd/sdpslamd.ini"
  # Encoder geometry from the packaged configuration, so the frames decode as the robot's.
  key() { sed -n "s/^$1 *= *\([^ ;]*\).*/\1/p" "$ini" | head -n1; }
  "$host" replay-can "$log" "$work/can.log" --protocol canopen --ticks-per-rev "$(key ticks_per_rev)" \
    --wheel-radius "$(key left_radius_m)" --wheel-separation "$(key wheel_separation_m)" \
    --left-node "$(key left_node)" --right-node "$(key right_node)" >"$work/replay-can.log" 2>&1 \
    || { cat "$work/replay-can.log"; fail "sdpslam replay-can"; }
  sed -e "s|^device *=.*|device = $work/laser|" -e "s|^directory *=.*|directory = $work/daemon-out|" \
      -e "s|^particles *=.*|particles = 10|" -e "s|^period_s *=.*|period_s = 2|" \
      -e "s|^send_nmt_start *=.*|send_nmt_start = false|" -e "s|^sync_period_ms *=.*|sync_period_ms = 0|" \
      "$ini" >"$work/sdpslamd.ini"
  delay_s=3
  "$host" replay-laser "$log" --link "$work/laser" --protocol scip --start-delay "$delay_s" >"$work/replay-laser.log" 2>&1 &
  laser_pid=$!
  # Both replays on one timeline: the candump's first frame is due when the laser's
  # first scan is (CLOCK_MONOTONIC, as both programs use).
  start_arg=()
  if command -v python3 >/dev/null; then
    start_arg=(--can-candump-start-us "$(python3 -c "import time; print(int(time.monotonic() * 1e6) + $delay_s * 1000000)")")
  fi
  for _ in $(seq 50); do [ -e "$work/laser" ] && break; sleep 0.1; done
  start=$(date +%s)
  # shellcheck disable=SC2086
  $runner "$daemon" --config "$work/sdpslamd.ini" --can-candump "$work/can.log" "${start_arg[@]}" \
    >"$work/sdpslamd.log" 2>&1 &
  daemon_pid=$!
  wait "$laser_pid" || { cat "$work/replay-laser.log"; kill "$daemon_pid" 2>/dev/null; fail "sdpslam replay-laser"; }
  sleep 1
  kill -TERM "$daemon_pid" 2>/dev/null || true
  status=0
  wait "$daemon_pid" || status=$?
  say "sdpslamd ($arch, $(qemu_of "$arch")) ran $(elapsed "$start") s, exit status $status; last lines of its log:"
  tail -n 5 "$work/sdpslamd.log" | sed 's/^/    /'
  [ $status = 0 ] || fail "sdpslamd exit status $status (0 expected after SIGTERM)"
  traj=$work/daemon-out/trajectory.txt
  [ -s "$traj" ] || fail "sdpslamd wrote no trajectory ($traj)"
  scans=$(grep -c '^[0-9]' "$traj" || true)
  log_scans=$(grep -Ec '^(FLASER|ROBOTLASER1)' "$log" || true)
  say "sdpslamd wrote $scans trajectory poses for the log's $log_scans scans; outputs: $(cd "$work/daemon-out" && ls | tr '\n' ' ')"
  [ "$scans" -gt 0 ] || fail "the trajectory has no pose"
  ;;

*)
  sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
  ;;
esac
