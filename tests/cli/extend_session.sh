#!/bin/sh
# `sdpslam run --extend`: a saved session continued with another recording of the same
# building (slam/session_continuation.h), as sdpslamd continues its session after a
# restart. The second recording starts with its own odometry origin and a clock that
# started again (a power loss), wherever the robot then stood:
#   - where the session left it: mapping goes on at once ("in place");
#   - carried elsewhere in the mapped part: the robot is found by global localization in
#     the saved map and the session continues there ("moved"); the same log taken to
#     start where the session stopped (--extend-window-m 0) goes metres wrong, so the
#     check has teeth;
# Judged on the built-in paper world against its ground truth: the mean position error
# of the second recording's first 200 placed scans, in the session's frame (the first
# scan's pose at the origin).
#   extend_session.sh SDPSLAM WORK
set -u
sdpslam=$1 work=$2
rm -rf "$work" && mkdir -p "$work"
"$sdpslam" simulate --world paper --seed 3 --quiet --out "$work/sim" >/dev/null || { echo "FAIL: simulate"; exit 1; }
log=$work/sim/sim.clf

# The log's scans FIRST..LAST, --rebase: as a recording of its own, odometry re-zeroed and
# the clock restarted at 100 s (tools/bench/cut_log.py).
cut() { python3 "$(dirname "$0")/../../tools/bench/cut_log.py" "$log" "$@"; }

# check NAME FIRST_SCAN PLACE MAX_MEAN_M|MIN_MEAN_M: the extension's place and the error
# of its first 200 placed scans (at most MAX, or with a leading '>' at least MIN).
check() {
  name=$1 first=$2 place=$3 bound=$4
  python3 - "$work/sim/ground_truth.txt" "$work/$name" "$first" "$place" "$bound" <<'PY'
import json, math, sys
gt_path, out, first, place, bound = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4], sys.argv[5]
st = json.load(open(out + "/stats.json"))["extended"]
gt = [[float(v) for v in l.split()[1:4]] for l in open(gt_path) if not l.startswith("#")]
tr = [l.split() for l in open(out + "/trajectory.txt") if not l.startswith("#")]
stamps = [int(round(float(r[0]) * 1e6)) for r in tr]
if any(b <= a for a, b in zip(stamps, stamps[1:])):
    sys.exit("FAIL: %s: the trajectory's stamps are not increasing" % out)
held = st.get("scans_held", 0)
if len(tr) != 900 + (len(gt) - first + 1) - held:
    sys.exit("FAIL: %s: %d trajectory rows, expected the session's 900 and %d more" % (out, len(tr), len(gt) - first + 1 - held))
g0 = gt[0]
def rel(p):
    c, s = math.cos(g0[2]), math.sin(g0[2])
    dx, dy = p[0] - g0[0], p[1] - g0[1]
    return c * dx + s * dy, -s * dx + c * dy
errs = []
for j in range(200):
    g = rel(gt[first - 1 + held + j])
    t = [float(v) for v in tr[900 + j][1:3]]
    errs.append(math.hypot(g[0] - t[0], g[1] - t[1]))
mean = sum(errs) / len(errs)
print("%s: place %s (expected %s), %d scans held, moved %.2f m, error of the next 200 scans: mean %.2f m, max %.2f m"
      % (out.rsplit("/", 1)[-1], st["place"], place, held, st.get("moved_m", 0.0), mean, max(errs)))
if st["place"] != place:
    sys.exit("FAIL: the extension's place is %s, not %s" % (st["place"], place))
if bound.startswith(">"):
    if not mean > float(bound[1:]):
        sys.exit("FAIL: mean error %.2f m, expected above %s m (the check has no teeth)" % (mean, bound[1:]))
elif not mean <= float(bound):
    sys.exit("FAIL: mean error %.2f m, above %s m" % (mean, bound))
PY
}

cut 1 900 "$work/a.clf" || { echo "FAIL: cut"; exit 1; }
"$sdpslam" run "$work/a.clf" --seed 3 --quiet --snapshot "$work/a.sdps" --out "$work/session" >/dev/null ||
  { echo "FAIL: the session's run"; exit 1; }
status=0
# extend NAME FIRST_SCAN [flags]
extend() {
  name=$1 first=$2
  shift 2
  cut "$first" 1000000000 "$work/$name.clf" --rebase || return 1
  "$sdpslam" run "$work/$name.clf" --seed 3 --quiet --extend "$work/a.sdps" "$@" --out "$work/$name" \
    >"$work/$name.log" 2>&1 || { echo "FAIL: extend $name:"; cat "$work/$name.log"; return 1; }
  grep "extended the session" "$work/$name.log"
}
extend in_place 901 && check in_place 901 "in place" 0.5 || status=1
extend moved 500 && check moved 500 moved 0.5 || status=1
extend moved_unchecked 500 --extend-window-m 0 && check moved_unchecked 500 "not checked" ">5" || status=1
exit $status
