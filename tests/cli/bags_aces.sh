#!/bin/sh
# SLAM on ROS bags scores as on the CARMEN log they hold (seed 1 throughout).
#   bags_aces.sh SDPSLAM SHARED_DIR WORK ROS1 ROS2   (ROS1, ROS2: 1 where the build reads them)
# ROS 1: ../shared/testdata/bags/aces.clf2bag.bag holds aces.clf's scans and odometry,
#   written by another tool, the i-th scan stamped 1e9 s + i x 0.1 s (its README); its
#   trajectory is scored with aces.relations after giving pose i the stamp of the log's
#   i-th FLASER line. Its inputs agree with the log's bit for bit except the odometry
#   headings, which that tool put through quaternions (~1e-16 rad), so the runs part
#   ways in the last bits: their relations errors must agree to within 5 mm (ACES's
#   seeds spread over ~17 mm). `sdpslam convert` writes the bag as a CARMEN log that
#   gives the bag's run byte for byte.
# ROS 2: `sdpslam convert --to ros2` writes aces.clf as a rosbag2 folder whose run is the
#   log's run, byte for byte; the bag converted again (ROS 2 -> ROS 2) holds the same
#   messages.
set -u
sdpslam=$1 shared=$2 work=$3 ros1=$4 ros2=$5
bag=$shared/testdata/bags/aces.clf2bag.bag
log=$shared/datasets/aces.clf
rel=$shared/datasets/aces.relations
for f in "$bag" "$log" "$rel"; do
  [ -f "$f" ] || { echo "SKIP: $f is absent (../shared beside the checkout)"; exit 77; }
done
rm -rf "$work" && mkdir -p "$work"
run() {  # run NAME INPUT
  "$sdpslam" run "$2" --seed 1 --quiet --out "$work/$1" > "$work/$1.log" 2>&1 ||
    { echo "FAIL: run on $2"; cat "$work/$1.log"; exit 1; }
}
same() {  # same DIR_A DIR_B WHAT
  for f in trajectory.txt map.pgm; do
    cmp -s "$1/$f" "$2/$f" || { echo "FAIL: $f of $3 differs"; exit 1; }
  done
}
run clf "$log" &
clf_pid=$!

if [ "$ros1" = 1 ]; then
  run bag "$bag"
  wait $clf_pid || exit 1
  "$sdpslam" convert "$bag" "$work/converted.clf" --quiet > /dev/null || { echo "FAIL: convert"; exit 1; }
  run converted "$work/converted.clf"
  same "$work/bag" "$work/converted" "the converted ROS 1 bag's run"
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
  python3 - "$work/clf.json" "$work/bag.json" <<'PY' || exit 1
import json, sys
clf, bag = (json.load(open(p))["relations"] for p in sys.argv[1:3])
a, b = clf["translation_m"]["mean"], bag["translation_m"]["mean"]
print("ROS 1 bag: relations error: log %.5f m, bag %.5f m (%d and %d relations used)" % (a, b, clf["used_count"], bag["used_count"]))
if clf["used_count"] != bag["used_count"]:
    sys.exit("FAIL: not the same relations scored")
if abs(a - b) > 0.005:
    sys.exit("FAIL: the bag's run differs from the log's by %.4f m" % abs(a - b))
PY
fi

if [ "$ros2" = 1 ]; then
  "$sdpslam" convert "$log" "$work/aces_ros2" --to ros2 --quiet > /dev/null || { echo "FAIL: convert --to ros2"; exit 1; }
  run ros2 "$work/aces_ros2"
  wait $clf_pid 2> /dev/null
  [ -f "$work/clf/trajectory.txt" ] || exit 1
  same "$work/clf" "$work/ros2" "the ROS 2 bag's run (against the log's)"
  "$sdpslam" convert "$work/aces_ros2" "$work/again_ros2" --to ros2 --quiet > /dev/null ||
    { echo "FAIL: convert ROS 2 -> ROS 2"; exit 1; }
  for b in aces_ros2 again_ros2; do
    "$sdpslam" convert "$work/$b" "$work/$b.clf" --quiet > /dev/null || { echo "FAIL: convert $b"; exit 1; }
    grep -v '^#' "$work/$b.clf" > "$work/$b.lines"
  done
  cmp -s "$work/aces_ros2.lines" "$work/again_ros2.lines" || { echo "FAIL: the bag converted again differs"; exit 1; }
  echo "ROS 2 bag: the run is the log's, byte for byte; converted again, the same messages"
fi
wait
