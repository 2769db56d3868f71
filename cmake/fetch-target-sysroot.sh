#!/usr/bin/env bash
# fetch-target-sysroot.sh ARCH DIR
#
# Unpacks the target architecture's libraries that the tools and sdpslamd link against
# (libpng, zlib, inih, yaml-cpp: headers, .so links, pkg-config and CMake files and the
# runtime libraries)
# into DIR, for a cross build with -DSDPSLAM_TARGET_SYSROOT=DIR (cmake/SdpslamTargetSysroot.cmake).
#
# Why not multiarch: `apt-get install libpng-dev:ARCH` fails whenever the mirror's ARCH
# indexes lag the host's (Multi-Arch: same version skew of libc6-dev, linux-libc-dev).
# `apt-get download` + `dpkg -x` needs neither root nor matching versions: it only needs
# `dpkg --add-architecture ARCH` to have been done once and the package lists to be current.
#
# Idempotent: a stamp file records the exact package versions unpacked; a second run with
# the same candidates does nothing. Exit status: 0 done, 1 a package could not be fetched
# or unpacked (the message says which), 2 bad arguments.
set -euo pipefail

usage() { echo "usage: $0 ARCH DIR   (ARCH: arm64, armhf, amd64, ...)" >&2; exit 2; }
[ $# -eq 2 ] || usage
arch=$1
dir=$2
case "$arch" in *[!a-z0-9]*|'') usage ;; esac

pkgs=(libpng-dev libpng16-16 zlib1g-dev zlib1g libinih-dev libinih1 libyaml-cpp-dev libyaml-cpp0.7)

if ! dpkg --print-foreign-architectures | grep -qx "$arch" && [ "$(dpkg --print-architecture)" != "$arch" ]; then
  echo "fetch-target-sysroot: architecture $arch is not configured; run: dpkg --add-architecture $arch && apt-get update" >&2
  exit 1
fi

# The versions apt would install now; the stamp compares against them.
want=""
for p in "${pkgs[@]}"; do
  v=$(apt-cache policy "$p:$arch" 2>/dev/null | awk '/Candidate:/ {print $2}')
  if [ -z "$v" ] || [ "$v" = "(none)" ]; then
    echo "fetch-target-sysroot: no candidate for $p:$arch in the package lists (apt-get update?)" >&2
    exit 1
  fi
  want+="$p:$arch=$v"$'\n'
done

stamp="$dir/.sdpslam-sysroot"
if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "${want%$'\n'}" ]; then
  echo "fetch-target-sysroot: $dir is up to date"
  exit 0
fi

mkdir -p "$dir"
debs=$(mktemp -d)
trap 'rm -rf "$debs"' EXIT
# apt-get download writes into the current directory; as root it warns that the _apt
# user cannot write there, which is harmless.
(cd "$debs" && apt-get download -q $(printf '%s\n' "${want%$'\n'}")) >"$debs/download.log" 2>&1 || {
  cat "$debs/download.log" >&2
  echo "fetch-target-sysroot: apt-get download failed (network or mirror?)" >&2
  exit 1
}
for deb in "$debs"/*.deb; do
  dpkg -x "$deb" "$dir" || { echo "fetch-target-sysroot: cannot unpack $deb" >&2; exit 1; }
done
# Some packages ship absolute symlinks (zlib1g-dev: libz.so -> /lib/<triplet>/libz.so.1...):
# point them inside DIR so the linker finds the target's library, never the host's.
while IFS= read -r link; do
  target=$(readlink "$link")
  case "$target" in
    /*) ln -sfn "$(realpath -m --relative-to="$(dirname "$link")" "$dir$target")" "$link" ;;
  esac
done < <(find "$dir" -type l)
printf '%s' "${want%$'\n'}" >"$stamp"
echo "fetch-target-sysroot: unpacked $(ls "$debs"/*.deb | wc -l) packages for $arch into $dir"
