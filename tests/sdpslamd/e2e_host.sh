#!/bin/sh
# End-to-end run of sdpslamd on the host, checked exactly against the offline runner.
#   e2e_host.sh SDPSLAMD REPLAY SDPSLAM MAKE_CANDUMP LOG WORK LINES SPEED [FIDELITY [MODE]]
# MODE: dpslam (default: the bottom-level filter, 5 particles) or sdp (SDP-SLAM, 10 top /
# 5 bottom particles, a segment every 4 processed scans, 3 live levels: in 150 lines
# (about 35 processed scans) several segments end and older levels become permanent, so the trajectory holds
# permanent, live and current poses).
# The first LINES lines of a tinySLAM log (real wheel ticks + URG scans): the scans are
# served by a SCIP 2.0 emulator on a pty, the ticks as CANopen SYNC + TPDO1 frames
# (nodes 1, 2) through sdpslamd's --can-candump replay started on the laser's instant.
# sdpslamd records its input ([output] input_log = true: every scan fed to SLAM with its
# odometry pose and stamp, as SLAM got them), and publishes each scan's pose on
# [output] pose_socket, read by tools/examples/pose_client.py: one record per recorded
# scan from the client's first on (it may subscribe a little late), in order, with its
# stamp.
#
# Checks (zero tolerance, except that a loaded machine may make sdpslamd drop up to 5% of
# its scans, counted: see check_recording.sh): its recording holds one line per placed
# scan, and `sdpslam run input.clf --mode MODE` with the same options and seed writes a trajectory.txt and map.pgm byte-identical to sdpslamd's (same stamps: the
# recording carries sdpslamd's own). This is what "sdpslamd runs the same SLAM as the
# offline runner" can promise exactly.
# Printed, not judged: the replay's fidelity (FIDELITY program: the recording against the
# original log: stamp offsets, odometry and range differences) and sdpslamd's trajectory
# against `sdpslam run` on the ORIGINAL lines (compare_trajectories.sh). Those differ: the
# daemon's stamps come from the sensor clock mapped onto arrival, its odometry is
# interpolated to them from CAN receive stamps, and 5 particles turn a sub-millimetre
# motion difference into another resampling history.
# Exit 77 when the log is absent.
set -u
daemon=$1 replay=$2 sdpslam=$3 make_candump=$4 log=$5 work=$6 lines=${7:-150} speed=${8:-1} fidelity=${9:-}
mode=${10:-dpslam}
. "$(dirname "$0")/tinyslam_ini.sh"
case $mode in
  dpslam) sdp_section='' ;;
  sdp) sdp_section=$(small_sdp_section) ;;
  *) echo "FAIL: unknown mode $mode"; exit 1 ;;
esac
[ -f "$log" ] || { echo "SKIP: $log is absent (shared data sets live beside the checkout)"; exit 77; }
rm -rf "$work" && mkdir -p "$work/daemon" "$work/offline" "$work/recorded"
head -n "$lines" "$log" >"$work/log.dat"
# One tick sample more than scans: the last scan's stamp (arrival-based) is a little after
# its own tick sample, and odometry must reach past it to place it.
"$make_candump" "$log" $((lines + 1)) "$work/ticks.candump" >/dev/null || exit 1
{ tinyslam_sensors "$work/laser"; cat <<INI; } >"$work/sdpslamd.ini"
[slam]
mode = $mode
seed = 1
[filter]
particles = 5
[map]
width_m = 40
height_m = 40
observations_base = 300000
observations_per_particle = 20000
$sdp_section
[output]
directory = $work/daemon
period_s = 2
input_log = true
pose_socket = $work/pose.sock
INI
# The offline runner reads the same SLAM keys from its own file.
sed -n '/^\[filter\]/,/^\[output\]/p' "$work/sdpslamd.ini" | grep -v '^\[output\]' >"$work/offline.ini"
# The pose client subscribes (again every second until sdpslamd answers) and stops 3 s
# after the last record.
python3 "$(dirname "$0")/../../tools/examples/pose_client.py" "$work/pose.sock" --idle-s 3 \
  >"$work/poses.ndjson" 2>"$work/pose_client.err" &
client=$!
start=$(date +%s.%N)
"$replay" --log "$work/log.dat" --link "$work/laser" --lines "$lines" --speed "$speed" --delay-s 1.5 --tail-s 1.5 \
  --daemon "$daemon" --config "$work/sdpslamd.ini" --out "$work/daemon" --candump "$work/ticks.candump" \
  >"$work/replay.log" 2>"$work/daemon.log"
rc=$?
cat "$work/replay.log"
end=$(date +%s.%N)
cat "$work/daemon.log" | tail -n 5
[ $rc = 0 ] || { echo "FAIL: replay or sdpslamd failed ($rc)"; exit 1; }
ls "$work/daemon" | grep -q '\.tmp' && { echo "FAIL: temporary files left"; exit 1; }
grep -o '"scans": {[^}]*}' "$work/daemon/status.json"
grep -o '"from_scan_stamp": {[^}]*}' "$work/daemon/status.json"
grep -o '"cpu": {[^}]*}' "$work/daemon/status.json"
grep -o '"input_log": {[^}]*}' "$work/daemon/status.json"
wait $client || { echo "FAIL: the pose client failed"; cat "$work/pose_client.err"; exit 1; }
grep -o '"pose_socket": {[^}]*}' "$work/daemon/status.json"
python3 - "$work/poses.ndjson" "$work/daemon/input.clf" <<'PY' || exit 1
import json, sys
poses = [json.loads(l) for l in open(sys.argv[1])]
stamps = [round(float(l.split()[-3]) * 1e6) for l in open(sys.argv[2]) if l.startswith("ROBOTLASER1")]
print("pose socket: %d records for %d recorded scans" % (len(poses), len(stamps)))
# The client may subscribe a few records late on a loaded machine (it asks again every
# second): what it gets is every record from its first on, in order, each with its
# scan's stamp, up to the last scan's, and at least half of them.
if not poses:
    sys.exit("FAIL: no record reached the client")
first = poses[0]["seq"]
if [p["seq"] for p in poses] != list(range(first, first + len(poses))):
    sys.exit("FAIL: the records are not consecutive and in order")
if first + len(poses) - 1 != len(stamps) or 2 * len(poses) < len(stamps):
    sys.exit("FAIL: records %d..%d for %d recorded scans" % (first, first + len(poses) - 1, len(stamps)))
if [p["stamp_us"] for p in poses] != stamps[first - 1:]:
    sys.exit("FAIL: the records' stamps are not the recorded scans' stamps")
PY
# Exact: the offline runner on sdpslamd's recorded input.
sh "$(dirname "$0")/check_recording.sh" "$sdpslam" "$work/daemon" "$work/daemon/status.json" "$work/offline.ini" \
  "$mode" 5 "$work/recorded" host || exit 1
if [ "$mode" = sdp ]; then
  # status.json holds them in its "engine" object, stats.json at the top.
  segs=$(sed -n 's/^ *"segments": \([0-9]*\),$/\1/p' "$work/daemon/status.json")
  grep -q "\"segments\": $segs," "$work/recorded/stats.json" || { echo "FAIL: segment counts differ"; exit 1; }
  [ "${segs:-0}" -ge 2 ] || { echo "FAIL: only ${segs:-0} segments: the test no longer exercises the top level"; exit 1; }
  perm=$(sed -n 's/^ *"levels_made_permanent": \([0-9]*\),$/\1/p' "$work/daemon/status.json")
  [ "${perm:-0}" -ge 1 ] || { echo "FAIL: no level became permanent: the test no longer exercises that path"; exit 1; }
  echo "segments: $segs, levels made permanent: $perm (sdpslamd and sdpslam run alike)"
fi
# Figures: the replay against the original log.
set -- $(sed -n 's/^timeline: play_start_us \([0-9]*\) log_start_us \([0-9]*\) speed \(.*\)/\1 \2 \3/p' "$work/replay.log")
[ -n "$fidelity" ] && { "$fidelity" "$work/log.dat" "$work/daemon/input.clf" "$1" "$2" "$3" || echo "note: fidelity comparison incomplete"; }
"$sdpslam" run "$work/log.dat" --mode "$mode" --particles 5 --config "$work/offline.ini" --seed 1 --out "$work/offline" 2>/dev/null || exit 1
printf 'against the original log (figure): '
sh "$(dirname "$0")/compare_trajectories.sh" "$work/daemon/trajectory.txt" "$work/offline/trajectory.txt" "$1" "$2" "$3" 1e9 10 1e9 || true
exit 0
