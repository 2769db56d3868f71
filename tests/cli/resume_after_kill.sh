#!/bin/sh
# A run killed with SIGKILL again and again, each time restarted from its last snapshot,
# ends with the outputs of a run that was never stopped, byte for byte; a snapshot is
# never found half-written (a resume of a torn or partial file would be refused and fail
# this test).
#   resume_after_kill.sh SDPSLAM WORK
# The log: the built-in paper world (the paper's nested loops), so that the run crosses
# segments, permanent levels and loop closures. Kill times step through a range so that
# the stops fall in different places on any machine (the run takes about 4 s here with
# its snapshots); an attempt killed before its first snapshot starts again from the
# previous one. After twelve attempts the run is left to finish once a snapshot exists;
# until then (a slow machine: a sanitizer build on a loaded host) each limit doubles, so
# that the test still kills, resumes and ends.
set -u
sdpslam=$1 work=$2
rm -rf "$work" && mkdir -p "$work"
"$sdpslam" simulate --world paper --seed 3 --quiet --out "$work/sim" >/dev/null || { echo "FAIL: simulate"; exit 1; }
log=$work/sim/sim.clf
"$sdpslam" run "$log" --seed 3 --quiet --out "$work/whole" >/dev/null || { echo "FAIL: uninterrupted run"; exit 1; }

snap=$work/run.sdps
kills=0 resumes=0 attempt=0
while :; do
  attempt=$((attempt + 1))
  resume=""
  if [ -f "$snap" ]; then resume="--resume $snap"; resumes=$((resumes + 1)); fi
  # 1 s, 1.5 s, ... 3.5 s, twice over; then no limit once a snapshot exists, 7 s, 14 s,
  # ... until one does.
  limit=$(awk -v a="$attempt" -v have="$([ -f "$snap" ] && echo 1 || echo 0)" 'BEGIN {
    if (a <= 12) printf "%.1f", 1.0 + 0.5 * ((a - 1) % 6);
    else if (have) printf "0";
    else printf "%.1f", 3.5 * 2 ^ (a - 12) }')
  # shellcheck disable=SC2086
  timeout -s KILL "$limit" "$sdpslam" run "$log" --seed 3 --quiet --out "$work/resumed" \
    --snapshot "$snap" --snapshot-every-s 30 $resume >"$work/attempt.log" 2>&1
  rc=$?
  if [ "$rc" -eq 0 ]; then break; fi
  if [ "$rc" -ne 137 ]; then
    echo "FAIL: attempt $attempt ended with exit $rc:"; cat "$work/attempt.log"; exit 1
  fi
  kills=$((kills + 1))
done
echo "finished after $kills kills and $resumes resumes ($attempt attempts)"
[ "$kills" -gt 0 ] || { echo "FAIL: no attempt was killed: nothing was tested"; exit 1; }
[ "$resumes" -gt 0 ] || { echo "FAIL: no attempt resumed: nothing was tested"; exit 1; }
status=0
for f in trajectory.txt trajectory.tum map.pgm map.yaml loops.tsv segments.tsv icp_error.csv; do
  if cmp -s "$work/whole/$f" "$work/resumed/$f"; then
    echo "same $f"
  else
    echo "FAIL: $f differs from the uninterrupted run's"
    status=1
  fi
done
exit $status
