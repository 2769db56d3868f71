#!/bin/sh
# SLAM on a ROS 1 bag scores as on the CARMEN log it was made from. The bag
# ../shared/testdata/bags/aces.clf2bag.bag holds aces.clf's scans and odometry, the i-th
# scan stamped 1e9 s + i x 0.1 s (its README); its trajectory is scored with
# aces.relations after giving pose i the stamp of the log's i-th FLASER line. Both runs
# use seed 1. The inputs agree bit for bit except the odometry headings, which went
# through quaternions (~1e-16 rad), so the runs part ways in the last bits: their
# relations errors must agree to within 2 mm (seeds differ by ~10 mm on ACES). And
# `sdpslam convert` writes the bag as a CARMEN log that gives the bag's run byte for byte.
#   rosbag_aces.sh SDPSLAM SHARED_DIR WORK
set -u
sdpslam=$1 shared=$2 work=$3
bag=$shared/testdata/bags/aces.clf2bag.bag
log=$shared/datasets/aces.clf
rel=$shared/datasets/aces.relations
for f in "$bag" "$log" "$rel"; do
  [ -f "$f" ] || { echo "SKIP: $f is absent (../shared beside the checkout)"; exit 77; }
done
rm -rf "$work" && mkdir -p "$work"
"$sdpslam" run "$bag" --seed 1 --quiet --out "$work/bag" > "$work/bag.log" 2>&1 &
bag_pid=$!
"$sdpslam" run "$log" --seed 1 --quiet --out "$work/clf" > "$work/clf.log" 2>&1 || { echo "FAIL: run on the log"; cat "$work/clf.log"; exit 1; }
wait $bag_pid || { echo "FAIL: run on the bag"; cat "$work/bag.log"; exit 1; }
"$sdpslam" convert "$bag" "$work/converted.clf" --quiet > /dev/null || { echo "FAIL: convert"; exit 1; }
"$sdpslam" run "$work/converted.clf" --seed 1 --quiet --out "$work/converted" > "$work/converted.log" 2>&1 ||
  { echo "FAIL: run on the converted bag"; cat "$work/converted.log"; exit 1; }
for f in trajectory.txt map.pgm; do
  cmp -s "$work/bag/$f" "$work/converted/$f" || { echo "FAIL: $f of the converted bag's run differs from the bag's"; exit 1; }
done

# Pose i of the bag's run gets the stamp of FLASER line i.
grep '^FLASER' "$log" | awk '{ print $(NF - 2) }' > "$work/stamps.txt"
awk 'NR == FNR { s[FNR - 1] = $1; next }
     /^#/ { print; next }
     { i = int(($1 - 1000000000) * 10 + 0.5); if (!(i in s)) { bad = 1; exit }
       printf "%s %s %s %s\n", s[i], $2, $3, $4 }
     END { if (bad) exit 1 }' "$work/stamps.txt" "$work/bag/trajectory.txt" > "$work/bag_mapped.txt" ||
  { echo "FAIL: a bag pose's stamp is no scan index"; exit 1; }
[ "$(grep -vc '^#' "$work/bag_mapped.txt")" -eq "$(wc -l < "$work/stamps.txt")" ] ||
  { echo "FAIL: the bag's trajectory has $(grep -vc '^#' "$work/bag_mapped.txt") poses, the log $(wc -l < "$work/stamps.txt") scans"; exit 1; }

for k in clf bag; do
  t=$work/clf/trajectory.txt
  [ $k = bag ] && t=$work/bag_mapped.txt
  "$sdpslam" evaluate --trajectory "$t" --relations "$rel" --log "$log" --json "$work/$k.json" > /dev/null ||
    { echo "FAIL: evaluate $k"; exit 1; }
done
python3 - "$work/clf.json" "$work/bag.json" <<'PY'
import json, sys
clf, bag = (json.load(open(p))["relations"] for p in sys.argv[1:3])
a, b = clf["translation_m"]["mean"], bag["translation_m"]["mean"]
print("relations error: log %.5f m, bag %.5f m (%d and %d relations used)" % (a, b, clf["used_count"], bag["used_count"]))
if clf["used_count"] != bag["used_count"]:
    sys.exit("FAIL: not the same relations scored")
if abs(a - b) > 0.002:
    sys.exit("FAIL: the bag's run differs from the log's by %.4f m" % abs(a - b))
PY
