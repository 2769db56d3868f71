#!/usr/bin/env bash
# The two quick-start commands of README.md.
#
#   tools/quickstart.sh demo   install what is missing, build (host-release), simulate the
#                              paper's world, run SLAM on it, write its map and trajectory
#                              and print its accuracy
#   tools/quickstart.sh test   install what is missing, build and run the whole test suite:
#                              host (debug; includes the Debian packaging tests, which
#                              build the amd64 and arm64 package sets), ASan+UBSan,
#                              aarch64 under qemu, fuzzers
#
# Works on a fresh Debian 12 with a compiler and CMake; installs Debian packages as root
# or through sudo. Environment: SDPSLAM_JOBS (parallel build jobs, default: nproc),
# SDPSLAM_FUZZ_SECONDS (per fuzzer, default 10: a smoke run; longer campaigns:
# SDPSLAM_FUZZ_SECONDS=600 ctest --preset fuzz), SDPSLAM_SKIP_INSTALL=1 (no apt-get).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$here"
mode=${1:-}
jobs=${SDPSLAM_JOBS:-$(nproc)}

log() { printf '\n== %s\n' "$*"; }
die() { printf 'quickstart: %s\n' "$*" >&2; exit 1; }

as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; elif command -v sudo >/dev/null; then sudo "$@";
  else die "need root or sudo to install: $*"; fi
}

# Packages for the host build and tests; cross and fuzz extras for `test`.
host_pkgs=(cmake ninja-build g++ pkg-config libcpputest-dev libpng-dev zlib1g-dev
           libcli11-dev libinih-dev nlohmann-json3-dev libyaml-cpp-dev libcairo2-dev)
test_pkgs=(clang libclang-rt-14-dev g++-aarch64-linux-gnu qemu-user qemu-system-x86 busybox-static cpio xz-utils
           dpkg-dev binutils lintian systemd)
# ROS 1 and ROS 2 bags (tools/bags, optional in a build): the test suite reads and writes them.
rosbag_pkgs=(librosbag-storage-dev libsensor-msgs-dev libnav-msgs-dev libtf2-msgs-dev libsqlite3-dev libfastcdr-dev)
arm64_pkgs=(libcpputest-dev:arm64)
# Target libraries of the arm64 package build (tests/packaging). Optional: when the mirror's
# arm64 indexes lag amd64 this install fails, and the tests unpack the same packages with
# apt-get download + dpkg -x instead (cmake/fetch-target-sysroot.sh). libyaml-cpp-dev is
# not among them: it cannot be installed for two architectures at once (not Multi-Arch:
# same), so the arm64 one always comes from a folder that script unpacks (the packaging
# tests make their own; the aarch64 preset reads build/sysroot-arm64, made below). Its
# shared library can, and the aarch64 tests load it under qemu.
arm64_packaging_pkgs=(libpng-dev:arm64 zlib1g-dev:arm64 libinih-dev:arm64 libyaml-cpp0.7:arm64)

missing() {
  local p out=()
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || out+=("$p")
  done
  echo "${out[@]:-}"
}

apt_updated=0
install() {
  [ "${SDPSLAM_SKIP_INSTALL:-0}" = 1 ] && return 0
  local need
  need=$(missing "$@")
  [ -z "$need" ] && return 0
  log "installing: $need"
  if [ $apt_updated = 0 ]; then
    # A mirror caught mid-sync can fail one index; what is needed may still install.
    as_root apt-get update -qq || echo "quickstart: apt-get update reported errors; trying the install anyway" >&2
    apt_updated=1
  fi
  # shellcheck disable=SC2086
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $need
}

configure_build() {  # preset [target...]
  log "build: $1"
  if ! cmake --preset "$1" >"build/$1.configure.log" 2>&1; then
    cat "build/$1.configure.log"
    echo "quickstart: configure of $1 failed" >&2
    return 1
  fi
  local preset=$1
  shift
  if [ $# -gt 0 ]; then
    cmake --build --preset "$preset" -j "$jobs" --target "$@"
  else
    cmake --build --preset "$preset" -j "$jobs"
  fi
}

case "$mode" in
  demo)
    install "${host_pkgs[@]}"
    mkdir -p build
    configure_build host-release sdpslam   # the program only; the test suite is `test`'s job
    bin=build/host-release/tools/cli/sdpslam
    out=out/demo
    log "simulate the paper's world (inner loop 28 m, outer loop 80 m) -> $out/sim"
    "$bin" simulate --out "$out/sim"
    log "run SDP-SLAM (60 top / 10 bottom particles) on it -> $out/run"
    "$bin" run "$out/sim/sim.clf" --out "$out/run"
    log "accuracy against ground truth (absolute trajectory error)"
    "$bin" evaluate --trajectory "$out/run/trajectory.txt" --ground-truth "$out/sim/ground_truth.txt"
    echo "map: $out/run/map.png  trajectory: $out/run/trajectory.txt  stats: $out/run/stats.json"
    ;;
  test)
    if [ "${SDPSLAM_SKIP_INSTALL:-0}" != 1 ] && ! dpkg --print-foreign-architectures | grep -qx arm64; then
      as_root dpkg --add-architecture arm64
      apt_updated=0
    fi
    install "${host_pkgs[@]}" "${test_pkgs[@]}" "${rosbag_pkgs[@]}" "${arm64_pkgs[@]}"
    install "${arm64_packaging_pkgs[@]}" 2>/dev/null \
      || echo "quickstart: multiarch arm64 libpng/zlib/inih/yaml-cpp did not install; the packaging tests will unpack them into a sysroot" >&2
    mkdir -p build
    # The aarch64 build of sdpslamd needs the target's yaml-cpp (see arm64_packaging_pkgs).
    bash cmake/fetch-target-sysroot.sh arm64 build/sysroot-arm64 \
      || echo "quickstart: the arm64 libraries could not be unpacked into build/sysroot-arm64; the aarch64 preset will build without sdpslamd" >&2
    [ -d ../shared ] || echo "quickstart: ../shared is absent: tests that need the benchmark logs and sensor captures will be reported as skipped" >&2
    start=$(date +%s)
    failed=()
    for preset in host-debug host-asan aarch64 fuzz; do
      if ! configure_build "$preset"; then failed+=("$preset(build)"); continue; fi
      log "test: $preset"
      if [ "$preset" = fuzz ]; then
        export SDPSLAM_FUZZ_SECONDS=${SDPSLAM_FUZZ_SECONDS:-10}
      fi
      ctest --preset "$preset" -j "$jobs" || failed+=("$preset")
    done
    log "whole suite took $(( $(date +%s) - start )) s"
    if [ ${#failed[@]} -gt 0 ]; then
      echo "FAILED: ${failed[*]}"
      exit 1
    fi
    echo "all test presets passed: host-debug host-asan aarch64 fuzz"
    ;;
  *)
    sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
    ;;
esac
