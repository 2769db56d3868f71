#!/bin/sh
# Localization benchmark (`sdpslam localize`): each real log with ground-truth relations
# is first mapped by `sdpslam run LOG --seed 1` (the map the robot would have), and each
# built-in world is simulated (`sdpslam simulate --world NAME --seed 1`, whose world.yaml
# is the true map); then the same log is localized on that map once per seed, from an
# unknown start (global) and from the start pose (tracking: the SLAM map's frame begins at
# the log's first pose; a world's at its ground truth's first pose).
# Per run it prints:
#   - relations m: `sdpslam evaluate --relations` of the localized trajectory (logs), or
#     ATE m: `sdpslam evaluate --ground-truth` (worlds, RMSE after SE(2) alignment);
#   - found: the first scan whose estimate is within 0.3 m of the reference (the SLAM
#     trajectory the map was built with, or the ground truth), and kept: the share of
#     the later scans still within 0.3 m;
#   - converged: stats.json converged_at_scan (the first update whose particle spread fell
#     below 0.2 m: a look-alike place counts too, which found/kept tell apart);
#   - CPU ms per scan (mean) and per update (p99), and the state's bytes (arena).
# Prints one markdown table on stdout and writes it to OUT_DIR/localize.md. Needs python3.
#
#   tools/bench/localize.sh BUILD_DIR [OUT_DIR]
#   e.g. SEEDS="1 2" LOGS=aces WORLDS=paper tools/bench/localize.sh build/host-release
#
# Environment: SEEDS (default "1 2 3"), SHARED (default ../shared beside the checkout),
# LOGS (default: every NAME in $SHARED/datasets with NAME.relations and NAME.clf[.gz];
# LOGS="" runs none), WORLDS (default "paper large"; WORLDS="" runs none). Use a Release
# build. Default OUT_DIR: /tmp/sdpslam-localize.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
build=${1:?usage: localize.sh BUILD_DIR [OUT_DIR]}
out=${2:-/tmp/sdpslam-localize}
bin=$build/tools/cli/sdpslam
[ -x "$bin" ] || { echo "localize.sh: no sdpslam in $build/tools/cli" >&2; exit 2; }
shared=${SHARED:-$here/../../../shared}
seeds=${SEEDS:-1 2 3}
worlds=${WORLDS-paper large}
if [ -z "${LOGS+x}" ]; then
  logs=""
  for r in "$shared"/datasets/*.relations; do
    [ -f "$r" ] || continue
    n=$(basename "$r" .relations)
    if [ -f "$shared/datasets/$n.clf" ] || [ -f "$shared/datasets/$n.clf.gz" ]; then logs="$logs $n"; fi
  done
else
  logs=$LOGS
fi
mkdir -p "$out/runs"
runs="$out/runs.tsv"
: > "$runs"

# One localization: name kind(log|world) mode(global|tracking) seed map log reference [relations]
localize_one() {
  name=$1 kind=$2 mode=$3 seed=$4 map=$5 log=$6 ref=$7 rel=${8:-}
  dir="$out/runs/$name.$mode.$seed"
  rm -rf "$dir"
  start=""
  if [ "$mode" = tracking ]; then
    if [ "$kind" = log ]; then
      start="--start 0,0,0"
    else
      start="--start $(awk '!/^#/ { printf "%s,%s,%s", $2, $3, $4; exit }' "$ref")"
    fi
  fi
  echo "   $name $mode seed $seed" >&2
  # shellcheck disable=SC2086
  if ! "$bin" localize "$log" --map "$map" --seed "$seed" $start --quiet --out "$dir" > "$dir.log" 2>&1; then
    printf '%s\t%s\t%s\tNA\tNA\tNA\tfailed\tNA\tNA\tNA\n' "$name" "$mode" "$seed" >> "$runs"
    return 0
  fi
  if [ "$kind" = log ]; then
    "$bin" evaluate --log "$log" --relations "$rel" --trajectory "$dir/trajectory.txt" --json "$dir/evaluate.json" \
      > "$dir/evaluate.txt" 2>&1 || true
  else
    "$bin" evaluate --ground-truth "$ref" --trajectory "$dir/trajectory.txt" --json "$dir/evaluate.json" \
      > "$dir/evaluate.txt" 2>&1 || true
  fi
  python3 - "$name" "$mode" "$seed" "$dir" "$ref" "$kind" >> "$runs" <<'EOF'
import json, math, os, sys
name, mode, seed, d, ref, kind = sys.argv[1:]
def poses(path):
    out = {}
    with open(path) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            p = line.split()
            out[p[0]] = (float(p[1]), float(p[2]))
    return out
a, b = poses(os.path.join(d, "trajectory.txt")), poses(ref)
keys = sorted((k for k in a if k in b), key=float)
near = [math.hypot(a[k][0] - b[k][0], a[k][1] - b[k][1]) < 0.3 for k in keys]
found = next((i for i, ok in enumerate(near) if ok), None)
kept = "NA" if found is None else "%.1f" % (100.0 * sum(near[found:]) / len(near[found:]))
try:
    with open(os.path.join(d, "evaluate.json")) as f:
        ev = json.load(f)
    score = ev["relations"]["translation_m"]["mean"] if kind == "log" else ev["ate"]["rmse_m"]
    score = "%.4f" % score
except (OSError, ValueError, KeyError, TypeError):
    score = "NA"
with open(os.path.join(d, "stats.json")) as f:
    st = json.load(f)
t = st["timing"]
print("\t".join([name, mode, seed, score, "NA" if found is None else str(found), kept,
                 str(st["converged_at_scan"]), "%.3f" % t["cpu_ms_per_scan_mean"],
                 "%.2f" % t["cpu_ms_per_update_p99"], str(st["memory"]["arena_bytes"])]))
EOF
}

for n in $logs; do
  log=$shared/datasets/$n.clf
  [ -f "$log" ] || log=$log.gz
  echo "== mapping $n (sdpslam run --seed 1)" >&2
  "$bin" run "$log" --seed 1 --quiet --out "$out/maps/$n" > "$out/maps.$n.log" 2>&1 || {
    echo "localize.sh: mapping $n failed (see $out/maps.$n.log)" >&2
    continue
  }
  for s in $seeds; do
    for mode in global tracking; do
      localize_one "$n" log "$mode" "$s" "$out/maps/$n/map.yaml" "$log" "$out/maps/$n/trajectory.txt" \
        "$shared/datasets/$n.relations"
    done
  done
done
for w in $worlds; do
  echo "== simulating $w (sdpslam simulate --seed 1)" >&2
  "$bin" simulate --world "$w" --seed 1 --quiet --out "$out/worlds/$w" > "$out/worlds.$w.log" 2>&1 || {
    echo "localize.sh: simulating $w failed" >&2
    continue
  }
  for s in $seeds; do
    for mode in global tracking; do
      localize_one "$w" world "$mode" "$s" "$out/worlds/$w/world.yaml" "$out/worlds/$w/sim.clf" \
        "$out/worlds/$w/ground_truth.txt"
    done
  done
done

python3 - "$runs" <<'EOF' | tee "$out/localize.md"
import sys
print("| map | start | seed | relations m (logs) / ATE m (worlds) | found at scan | kept % | converged_at_scan "
      "| CPU ms/scan | CPU ms/update p99 | state bytes |")
print("|---|---|---|---|---|---|---|---|---|---|")
with open(sys.argv[1]) as f:
    for line in f:
        print("| " + " | ".join(line.rstrip("\n").split("\t")) + " |")
EOF
