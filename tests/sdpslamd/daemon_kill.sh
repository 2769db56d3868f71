#!/bin/sh
# sdpslamd killed with SIGKILL three times during a mapping run (mode sdp, a snapshot every
# second) and started again each time while the sensors go on, as a power cut and a
# restart would leave it; then the same run uninterrupted.
#   daemon_kill.sh SDPSLAMD REPLAY SDPSLAM MAKE_CANDUMP LOG WORK LINES SPEED
# The first LINES lines of a tinySLAM log (real wheel ticks + URG scans) served as in
# e2e_host.sh: a SCIP 2.0 emulator on a pty and the ticks through sdpslamd's
# --can-candump replay, which a restarted sdpslamd continues on the first start's instant.
# Checks: every restart resumed the saved session (the journal says so, each time with more
# scans behind it); at the end the trajectory holds at least the scans of the last
# snapshot resumed and the rest of the session, in time order, nothing is left
# half-written (no temporary file, no refused snapshot), and the map and trajectory are
# there.
# Printed: the scans lost to the kills (served by the laser but in no trajectory), and
# how close both runs come to `sdpslam run` on the original lines (the daemon's
# stamps mapped back to log time, compare_trajectories.sh), the uninterrupted run's
# figure being the baseline: five particles turn a sub-millimetre difference in the
# input into another resampling history, so neither matches it exactly.
# Exit 77 when the log is absent.
set -u
daemon=$1 replay=$2 sdpslam=$3 make_candump=$4 log=$5 work=$6 lines=${7:-300} speed=${8:-1} particles=${9:-5}
[ -f "$log" ] || { echo "SKIP: $log is absent (shared data sets live beside the checkout)"; exit 77; }
rm -rf "$work" && mkdir -p "$work"
head -n "$lines" "$log" >"$work/log.dat"
"$make_candump" "$log" $((lines + 1)) "$work/ticks.candump" >/dev/null || exit 1
# The run lasts lines / 10 / speed seconds: kills at a quarter, half and three quarters.
kills=$(awk -v n="$lines" -v s="$speed" 'BEGIN { d = n / 10 / s; printf "%.2f,%.2f,%.2f", d / 4, d / 2, 3 * d / 4 }')
. "$(dirname "$0")/tinyslam_ini.sh"
config() {
  tinyslam_sensors "$work/laser"
  cat <<INI
[slam]
mode = sdp
seed = 1
[filter]
particles = $particles
[map]
width_m = 40
height_m = 40
observations_base = 300000
observations_per_particle = 20000
$(small_sdp_section)
[output]
directory = $1
period_s = 1
snapshot_interval_s = 1
INI
}
status=0
for run in whole killed; do
  mkdir -p "$work/$run"
  config "$work/$run" >"$work/$run.ini"
  kill_args=""
  [ "$run" = killed ] && kill_args="--kill-at-s $kills"
  # shellcheck disable=SC2086
  "$replay" --log "$work/log.dat" --link "$work/laser" --lines "$lines" --speed "$speed" --delay-s 1.5 --tail-s 2 \
    --daemon "$daemon" --config "$work/$run.ini" --out "$work/$run" --candump "$work/ticks.candump" $kill_args \
    >"$work/$run.replay.log" 2>"$work/$run.daemon.log"
  rc=$?
  cat "$work/$run.replay.log"
  [ $rc = 0 ] || { echo "FAIL: $run: replay or sdpslamd failed ($rc)"; tail -n 20 "$work/$run.daemon.log"; exit 1; }
done
d=$work/killed
log_file=$work/killed.daemon.log
n_kills=$(grep -c 'supervisor: killed sdpslamd' "$log_file")
grep 'resumed the session\|the first scan\|robot was moved\|snapshot refused' "$log_file" | sed 's/^/journal: /'
resumes=$(grep -c 'resumed the session' "$log_file")
[ "$n_kills" = 3 ] || { echo "FAIL: $n_kills kills instead of 3"; status=1; }
[ "$resumes" = 3 ] || { echo "FAIL: $resumes restarts resumed the session, not 3"; status=1; }
grep -q 'snapshot refused' "$log_file" && { echo "FAIL: a snapshot was refused"; status=1; }
ls "$d" | grep -q '\.tmp\|\.refused' && { echo "FAIL: temporary or refused files left: $(ls "$d")"; status=1; }
# Each resume has more scans behind it than the one before, unless the run before it was
# still looking for the robot in the saved map when it was killed: scans are held back
# from mapping until it is found, so that run wrote no snapshot further on. None goes back.
grep -o 'resumed the session of [^:]*: [0-9]* scans\|looking for it in the saved map\|the robot was moved' "$log_file" |
  awk '/resumed the session/ { n = $(NF - 1); if (n < last || (n == last && !held)) bad = 1; last = n; held = 0; next }
       /looking for it/ { held = 1 } /the robot was moved/ { held = 0 }
       END { exit bad }' || { echo "FAIL: a resume did not continue from further on"; status=1; }
# Where each restart found the robot is printed above (the journal's "session" lines),
# not judged: the log's robot drives on while sdpslamd is down, on a map that five
# particles keep rough, and a restart may spend its remaining scans looking for it.
for f in trajectory.txt map.pgm map.yaml status.json snapshot.sdps; do
  [ -s "$d/$f" ] || { echo "FAIL: $f missing"; status=1; }
done
awk '!/^#/ { split($1, f, "."); t = f[1] * 1000000 + f[2]; if (n++ && t <= last) bad = 1; last = t }
  END { exit bad }' "$d/trajectory.txt" || { echo "FAIL: the trajectory is not in time order"; status=1; }
served=$(sed -n 's/.* served \([0-9]*\) .*/\1/p' "$work/killed.replay.log")
rows_killed=$(grep -vc '^#' "$d/trajectory.txt")
rows_whole=$(grep -vc '^#' "$work/whole/trajectory.txt")
echo "scans: $served served by the laser; the interrupted session's trajectory holds $rows_killed, the uninterrupted one's $rows_whole (lost to the kills: $((rows_whole - rows_killed)))"
# Nothing the last resumed snapshot held is lost.
last_resume=$(grep -o 'resumed the session of [^:]*: [0-9]* scans' "$log_file" | tail -n 1 | awk '{ print $(NF - 1) }')
[ "$rows_killed" -ge "${last_resume:-1000000}" ] ||
  { echo "FAIL: the trajectory holds $rows_killed scans, the last resumed snapshot $last_resume"; status=1; }
sed -n '/^\[filter\]/,/^\[output\]/p' "$work/whole.ini" | grep -v '^\[output\]' >"$work/offline.ini"
"$sdpslam" run "$work/log.dat" --particles "$particles" --config "$work/offline.ini" --seed 1 --out "$work/offline" >/dev/null 2>&1 ||
  { echo "FAIL: sdpslam run on the lines"; exit 1; }
for run in whole killed; do
  set -- $(sed -n 's/^timeline: play_start_us \([0-9]*\) log_start_us \([0-9]*\) speed \(.*\)/\1 \2 \3/p' \
    "$work/$run.replay.log")
  printf '%s: ' "$run"
  sh "$(dirname "$0")/compare_trajectories.sh" "$work/$run/trajectory.txt" "$work/offline/trajectory.txt" "$1" "$2" \
    "$3" 1e9 10 1e9 || true
done
exit $status
