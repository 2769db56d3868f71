#!/bin/sh
# Hardware-in-the-loop test of sdpslamd in the virtual-CAN machine, checked exactly
# against the offline runner.
#   hil_sdpslamd.sh RUN_IN_VM CACHE WORK SDPSLAMD_STATIC REPLAY_STATIC MAKE_CANDUMP SDPSLAM LOG LINES SPEED [FIDELITY]
# The first LINES lines of the tinySLAM log (real wheel ticks + URG-04LX scans): ticks as
# CANopen SYNC + TPDO1 frames on vcan0, scans from the SCIP 2.0 emulator on a pty, both
# from one player on one clock (sdpslamd_replay); sdpslamd runs unmodified with 5
# particles and records its input ([output] input_log).
# Checks: both programs exit 0, no CAN frame lost, sdpslamd skipped and dropped (queue,
# gap, no odometry) at most 5% of its scans, each counted (check_recording.sh: the budget
# a shared machine's load needs; none on an idle one), its recording holds every placed scan, and `sdpslam run
# input.clf --mode dpslam` (same options and seed) on the host writes a trajectory.txt
# and map.pgm byte-identical to those sdpslamd wrote in the machine.
# Printed: latency, CPU and drop figures from sdpslamd's status.json, the replay's
# fidelity (FIDELITY: the recording against the original log) and the trajectory against
# `sdpslam run` on the original log (see tests/sdpslamd/e2e_host.sh for why those differ).
# Exit 77 when the log or the machine is unavailable.
# Under TCG a slow step lets encoder frames queue in the socket; sdpslamd reads such a
# backlog frame by frame so every sample keeps its own receive stamp.
set -u
run=$1 cache=$2 work=$3 daemon=$4 replay=$5 make_candump=$6 sdpslam=$7 log=$8 lines=${9:-300} speed=${10:-1}
fidelity=${11:-}
here=$(cd "$(dirname "$0")" && pwd)
[ -f "$log" ] || { echo "SKIP: $log is absent (shared data sets live beside the checkout)"; exit 77; }
rm -rf "$work" && mkdir -p "$work/offline" "$work/out" "$work/recorded"
head -n "$lines" "$log" >"$work/log.dat"
"$make_candump" "$log" $((lines + 1)) "$work/ticks.candump" >/dev/null || exit 1
. "$here/../sdpslamd/tinyslam_ini.sh"
{ tinyslam_sensors /tmp/laser vcan0 1500; cat <<INI; } >"$work/sdpslamd.ini"
scan_queue = 16
[slam]
mode = dpslam
seed = 1
[filter]
particles = 5
[map]
width_m = 40
height_m = 40
observations_base = 300000
observations_per_particle = 20000
[output]
period_s = 5
input_log = true
INI
sed -n '/^\[filter\]/,/^\[output\]/p' "$work/sdpslamd.ini" | grep -v '^\[output\]' >"$work/offline.ini"
"$sdpslam" run "$work/log.dat" --mode dpslam --config "$work/offline.ini" --seed 1 --out "$work/offline" 2>/dev/null || exit 1
start=$(date +%s)
sh "$run" --cache "$cache" --work "$work/vm" --timeout 280 \
  --file "$daemon:sdpslamd_static" --file "$replay:sdpslamd_replay_static" --file "$work/log.dat" \
  --file "$work/ticks.candump" --file "$work/sdpslamd.ini" --file "$here/sdpslamd_inside.sh" \
  -- "sh ./sdpslamd_inside.sh $lines $speed" >"$work/console.txt" 2>&1
rc=$?
end=$(date +%s)
sed -n '/^@@STATUS/q;p' "$work/console.txt"
[ $rc = 77 ] && exit 77
sed -n '/^@@STATUS/,/^@@OUTPUTS/p' "$work/console.txt" | grep -v '^@@' >"$work/status.json"
got=1
sed -n '/^@@OUTPUTS/,/^@@END/p' "$work/console.txt" | grep -v '^@@' | base64 -d | gzip -dc | tar xf - -C "$work/out" || got=0
grep -E "HIL machine|exit" "$work/console.txt" | tail -n 3
for k in scans from_scan_stamp from_driver_read odometry cpu can input_log; do grep -o "\"$k\": {[^}]*}" "$work/status.json"; done
echo "HIL sdpslamd test: $((end - start)) s in the machine (boot to power-off)"
[ $rc = 0 ] || { echo "FAIL: the machine's command exited $rc"; exit 1; }
[ $got = 1 ] || { echo "FAIL: the outputs did not come out of the machine"; exit 1; }
grep -q '"rx_overflows": 0' "$work/status.json" || { echo "FAIL: CAN frames lost"; exit 1; }
sh "$here/../sdpslamd/check_recording.sh" "$sdpslam" "$work/out" "$work/status.json" "$work/offline.ini" dpslam 5 \
  "$work/recorded" machine || exit 1
set -- $(sed -n 's/^timeline: play_start_us \([0-9]*\) log_start_us \([0-9]*\) speed \(.*\)/\1 \2 \3/p' "$work/console.txt")
[ -n "$fidelity" ] && { "$fidelity" "$work/log.dat" "$work/out/input.clf" "$1" "$2" "$3" || echo "note: fidelity comparison incomplete"; }
printf 'against the original log (figure): '
sh "$here/../sdpslamd/compare_trajectories.sh" "$work/out/trajectory.txt" "$work/offline/trajectory.txt" "$1" "$2" "$3" 1e9 10 1e9 || true
exit 0
