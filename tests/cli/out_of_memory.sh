#!/bin/sh
# `sdpslam run` whose state fits --memory-budget-mib but not the address space the
# process may use (ulimit -v): the allocation fails, and the program says "out of memory"
# and exits 3 (kExitBadInput, README's exit codes) instead of aborting; the output folder
# is left without a file. Usage: out_of_memory.sh SDPSLAM WORK_DIR
set -u
sdpslam=$1
work=$2
rm -rf "$work" && mkdir -p "$work" || exit 1
printf 'FLASER 3 2.0 2.0 2.0 0 0 0 0 0 0 1.0 host 1.0\n' > "$work/log.clf"
# About 600 MiB of observation pool: within the 2048 MiB budget, beyond 400 MB of address space.
printf '[sdp]\nmap_observation_capacity = 20000000\n' > "$work/big.ini"
out=$( (ulimit -v 400000 && exec "$sdpslam" run "$work/log.clf" --config "$work/big.ini" --memory-budget-mib 2048 \
  --quiet --out "$work/out") 2>&1)
rc=$?
echo "$out"
if [ "$rc" -ne 3 ]; then
  echo "FAIL: exit $rc, expected 3"
  exit 1
fi
case "$out" in
  *"sdpslam: out of memory: "*) ;;
  *) echo "FAIL: no 'out of memory' message"; exit 1 ;;
esac
if [ -d "$work/out" ] && [ -n "$(ls -A "$work/out")" ]; then
  echo "FAIL: files left in $work/out:"; ls -A "$work/out"
  exit 1
fi
echo "ok: out of memory is a message and exit 3, no output written"
