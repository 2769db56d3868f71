#!/bin/sh
# Hardware-in-the-loop test of sdpslamd in the virtual-CAN machine, compared with the
# offline runner on the same log.
#   hil_sdpslamd.sh RUN_IN_VM CACHE WORK SDPSLAMD_STATIC REPLAY_STATIC MAKE_CANDUMP SDPSLAM LOG LINES SPEED
# The first LINES lines of the tinySLAM log (real wheel ticks + URG-04LX scans): ticks as
# CANopen SYNC + TPDO1 frames on vcan0, scans from the SCIP 2.0 emulator on a pty, both
# from one player on one clock (sdpslamd_replay); sdpslamd runs unmodified with 5
# particles. Checks: both programs exit 0, no scan dropped from the queue, at most 5 % of
# scans skipped (reported), and its trajectory
# matches `sdpslam run` (same options, seed): mean position difference within 0.5 m,
# every pose within 2.0 m / 0.8 rad (see tests/sdpslamd/e2e_host.sh for why they differ
# at all). Prints latency, CPU and drop
# figures from sdpslamd's status.json. Exit 77 when the log or the machine is unavailable.
# Under TCG a slow step lets encoder frames queue in the socket; sdpslamd reads such a
# backlog frame by frame so every sample keeps its own receive stamp.
set -u
run=$1 cache=$2 work=$3 daemon=$4 replay=$5 make_candump=$6 sdpslam=$7 log=$8 lines=${9:-300} speed=${10:-1}
here=$(cd "$(dirname "$0")" && pwd)
[ -f "$log" ] || { echo "SKIP: $log is absent (shared data sets live beside the checkout)"; exit 77; }
rm -rf "$work" && mkdir -p "$work/offline"
head -n "$lines" "$log" >"$work/log.dat"
"$make_candump" "$log" $((lines + 1)) "$work/ticks.candump" >/dev/null || exit 1
cat >"$work/sdpslamd.ini" <<INI
[can]
interface = vcan0
protocol = canopen
left_node = 1
right_node = 2
sync_period_ms = 0
position_timeout_ms = 500
[laser]
device = /tmp/laser
protocol = scip
stall_timeout_ms = 5000
[sync]
odometry_wait_ms = 400
max_interpolation_gap_ms = 1500
scan_queue = 16
[slam]
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
sed -n '/^@@TRAJECTORY/,/^@@END/p' "$work/console.txt" | grep -v '^@@' >"$work/trajectory.txt"
sed -n '/^@@STATUS/,/^@@TRAJECTORY/p' "$work/console.txt" | grep -v '^@@' >"$work/status.json"
grep -E "HIL machine|exit" "$work/console.txt" | tail -n 3
for k in scans from_scan_stamp from_driver_read cpu can; do grep -o "\"$k\": {[^}]*}" "$work/status.json"; done
echo "HIL sdpslamd test: $((end - start)) s in the machine (boot to power-off)"
[ $rc = 0 ] || { echo "FAIL: the machine's command exited $rc"; exit 1; }
# Queue drops are never allowed. Scans skipped because their stamp cannot be interpolated
# ("gap") are bounded at 5 %: in this emulated machine 2..7 of 300 were skipped per run
# (not understood yet; the host end-to-end run skips none), so the bound catches a broken
# pipeline while the figure itself is printed and reported.
dropped=$(sed -n 's/.*"dropped_total": \([0-9]*\).*/\1/p' "$work/status.json")
grep -q '"dropped_queue_full": 0' "$work/status.json" || { echo "FAIL: sdpslamd dropped scans (queue full)"; exit 1; }
echo "scans skipped by sdpslamd: $dropped of $lines"
[ -n "$dropped" ] && [ "$dropped" -le $((lines / 20)) ] || { echo "FAIL: sdpslamd dropped $dropped scans"; exit 1; }
grep -q '"rx_overflows": 0' "$work/status.json" || { echo "FAIL: CAN frames lost"; exit 1; }
set -- $(sed -n 's/^timeline: play_start_us \([0-9]*\) log_start_us \([0-9]*\) speed \(.*\)/\1 \2 \3/p' "$work/console.txt")
sh "$here/../sdpslamd/compare_trajectories.sh" "$work/trajectory.txt" "$work/offline/trajectory.txt" "$1" "$2" "$3" 2.0 0.8 0.5
