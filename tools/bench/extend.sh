#!/bin/sh
# Extension benchmark: a session saved part-way through a real log, continued with the
# rest of the log as another recording (`sdpslam run --extend`), as a robot does that is
# switched off and on again, carried or not. For each START the second recording begins
# at that scan (1-based), its odometry re-zeroed and its clock started again at 100 s; a
# START after SPLIT + 1 means the robot was carried from where the session stopped to where
# scan START was taken. Each extended trajectory (stamps mapped back to the log's) is
# scored with the relations metric on the relations whose two scans it holds, and so is
# the uninterrupted run (`sdpslam run LOG`, same seed) on the same relations.
# Prints one markdown table row per START: what the extension found (stats.json
# "extended"), the scans it held back, the search time, and both errors (mean / max, m).
# Needs python3.
#
#   tools/bench/extend.sh BUILD_DIR LOG RELATIONS SPLIT START... [-- SEED]
#   e.g. tools/bench/extend.sh build/host-release ../shared/datasets/intel.clf \
#          ../shared/datasets/intel.relations 6800 6801 7300 8000
set -u
build=$1 log=$2 rel=$3 split=$4
shift 4
seed=1
starts=""
while [ $# -gt 0 ]; do
  case $1 in
    --) seed=$2; shift 2 ;;
    *) starts="$starts $1"; shift ;;
  esac
done
sdpslam=$build/tools/cli/sdpslam
[ -x "$sdpslam" ] || { echo "no $sdpslam: build first" >&2; exit 2; }
[ -f "$log" ] && [ -f "$rel" ] || { echo "no $log or $rel" >&2; exit 2; }
out=${EXTEND_OUT:-/tmp/sdpslam-extend}/$(basename "$log" .clf)
rm -rf "$out" && mkdir -p "$out"

# The log's scans FIRST..LAST, --rebase: as a recording of its own (cut_log.py).
cut() { python3 "$(dirname "$0")/cut_log.py" "$log" "$@"; }

cut 1 "$split" "$out/session.clf" || exit 1
"$sdpslam" run "$out/session.clf" --seed "$seed" --quiet --snapshot "$out/session.sdps" --out "$out/session" \
  >/dev/null 2>&1 || { echo "the session's run failed" >&2; exit 1; }
"$sdpslam" run "$log" --seed "$seed" --quiet --out "$out/whole" >/dev/null 2>&1 ||
  { echo "the uninterrupted run failed" >&2; exit 1; }
echo "| log | seed | session: scans | second recording from scan | place | scans held | found from where it stopped | search ms | extended: relations mean / max m | uninterrupted, same relations | relations |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for k in $starts; do
  cut "$k" 1000000000 "$out/from$k.clf" --rebase || exit 1
  "$sdpslam" run "$out/from$k.clf" --seed "$seed" --quiet --extend "$out/session.sdps" --out "$out/from$k" \
    >"$out/from$k.log" 2>&1 || { echo "extension from scan $k failed" >&2; cat "$out/from$k.log" >&2; continue; }
  python3 - "$log" "$rel" "$out" "$k" "$split" <<'PY' > "$out/from$k.info" || continue
import json, sys
log, rel, out, k, split = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5])
s = json.load(open("%s/from%d/stats.json" % (out, k)))
e = s["extended"]
held = e.get("scans_held", 0)
stamps = [l.split()[-3] for l in open(log) if l.startswith(("FLASER", "ROBOTLASER1"))]
rows = [l.split() for l in open("%s/from%d/trajectory.txt" % (out, k)) if not l.startswith("#")]
kept = set()
with open("%s/from%d.orig.txt" % (out, k), "w") as o:
    o.write("# t x y theta\n")
    for i, f in enumerate(rows):
        f[0] = stamps[i] if i < split else stamps[k - 1 + held + (i - split)]
        kept.add(round(float(f[0]) * 1e6))
        o.write(" ".join(f) + "\n")
n = 0
with open("%s/from%d.relations" % (out, k), "w") as o:
    for l in open(rel):
        f = l.split()
        if len(f) >= 2 and round(float(f[0]) * 1e6) in kept and round(float(f[1]) * 1e6) in kept:
            o.write(l)
            n += 1
print(e["place"], held, "%.2f m, %.0f deg" % (e.get("moved_m", 0.0), e.get("turned_rad", 0.0) * 57.29577951308232),
      "%.0f" % s["timing"]["extend_search_ms"], n)
PY
  set -- $(cat "$out/from$k.info")
  place=$1
  [ "$place" = in ] && { place="in place"; shift; }
  held=$2 found="$3 $4 $5 $6" ms=$7 nrel=$8
  a=$("$sdpslam" evaluate --log "$log" --relations "$out/from$k.relations" --trajectory "$out/from$k.orig.txt" 2>&1 |
    awk '/translation \[m\]/ { printf "%.4f / %.3f", $3, $5 }')
  b=$("$sdpslam" evaluate --log "$log" --relations "$out/from$k.relations" --trajectory "$out/whole/trajectory.txt" 2>&1 |
    awk '/translation \[m\]/ { printf "%.4f / %.3f", $3, $5 }')
  echo "| $(basename "$log") | $seed | 1-$split | $k | $place | $held | $found | $ms | $a | $b | $nrel |"
done
