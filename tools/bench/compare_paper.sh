#!/bin/sh
# The paper's comparison (SDP-SLAM §IV, Table I) in one command:
#   - on the simulated nested-loop world (`sdpslam simulate`, 28 m / 80 m loops) and on
#     the Intel log: SegSLAM's topology estimation (--topology segslam: local analysis of
#     the last few segments, everything else identical) vs SDP-SLAM, at 30T/5B, 30T/10B,
#     60T/5B and 60T/10B: mean and std of the ICP nearest-neighbour error of the top-level
#     samples over the run (Table I's μ, σ), plus the trajectory accuracy: ATE against the
#     ground truth (simulation) or the relations metric (Intel);
#   - the DP-SLAM baseline with as many particles as fit the run time of SDP-SLAM 60T/10B
#     (measured: a 20-particle run's time is scaled linearly, then that count is run).
# Prints markdown tables; every run's outputs stay in OUT_DIR.
#
#   tools/bench/compare_paper.sh BUILD_DIR [OUT_DIR]
#   e.g. tools/bench/compare_paper.sh build/release /tmp/sdpslam-paper
#
# Environment: SEED (default 1), SHARED (default ../shared beside the checkout),
# DATASETS (default "sim intel"), CONFIG (INI for every run, default firmware-host/runtime/slam/default.ini),
# PROFILE (sdp runs' --profile, default paper: the paper's algorithm, as in its Table I;
# accurate adds scan-matching proposals and loop closure to both topologies).
# Use a Release build; the Intel part takes a while.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:?usage: compare_paper.sh BUILD_DIR [OUT_DIR]}
out=${2:-/tmp/sdpslam-paper}
seed=${SEED:-1}
shared=${SHARED:-$root/../shared}
datasets=${DATASETS:-"sim intel"}
config=${CONFIG:-$root/firmware-host/runtime/slam/default.ini}
profile=${PROFILE:-paper}
bin="$build/tools/cli/sdpslam"
[ -x "$bin" ] || { echo "compare_paper.sh: no sdpslam binary in $build" >&2; exit 2; }
mkdir -p "$out"

num() { sed -n "s/.*\"$1\": \([0-9.e+-]*\).*/\1/p" "$2" | head -1; }
icp() { sed -n "s/.*\"icp_error\": {\"mean_m\": \([0-9.e+-]*\), \"std_m\": \([0-9.e+-]*\).*/\1 \2/p" "$1"; }

# accuracy DATASET RUN_DIR -> "value" (ATE rmse for sim, relations translation mean±std for logs)
accuracy() {
  ds=$1; dir=$2
  if [ "$ds" = sim ]; then
    "$bin" evaluate --log "$log" --trajectory "$dir/trajectory.txt" --ground-truth "$out/sim/ground_truth.txt" \
      --json "$dir/evaluate.json" > "$dir/evaluate.txt" 2>&1 || { echo NA; return; }
    printf '%.3f' "$(num rmse_m "$dir/evaluate.json")"
  else
    "$bin" evaluate --log "$log" --relations "$shared/datasets/$ds.relations" --trajectory "$dir/trajectory.txt" \
      --json "$dir/evaluate.json" > "$dir/evaluate.txt" 2>&1 || { echo NA; return; }
    sed -n 's/.*"translation_m": {"mean": \([0-9.e+-]*\), "std": \([0-9.e+-]*\).*/\1 \2/p' "$dir/evaluate.json" |
      awk '{printf "%.3f ± %.3f", $1, $2}'
  fi
}

for ds in $datasets; do
  if [ "$ds" = sim ]; then
    echo "== simulating the nested-loop world -> $out/sim" >&2
    "$bin" simulate --seed "$seed" --out "$out/sim" >&2
    log="$out/sim/sim.clf"
    metric="ATE rmse (m)"
  else
    log="$shared/datasets/$ds.clf"
    [ -f "$log" ] || { echo "compare_paper.sh: $log missing, skipping $ds" >&2; continue; }
    metric="relations translation error (m)"
  fi
  table="$out/table-$ds.md"
  {
    echo "### $ds: ICP error (m) of the top-level samples, and $metric"
    echo
    echo "| Particles | SegSLAM μ | SegSLAM σ | SegSLAM accuracy | SDP-SLAM μ | SDP-SLAM σ | SDP-SLAM accuracy | SDP-SLAM time (s) |"
    echo "|---|---|---|---|---|---|---|---|"
  } > "$table"
  sdp_time=0
  for tb in "30 5" "30 10" "60 5" "60 10"; do
    set -- $tb
    t=$1; b=$2
    row="| ${t}T/${b}B"
    for topo in segslam sdp; do
      dir="$out/$ds-$topo-${t}T${b}B"
      echo "== $ds $topo ${t}T/${b}B -> $dir" >&2
      "$bin" run "$log" --mode sdp --topology "$topo" --top-particles "$t" --particles "$b" --profile "$profile" \
        --config "$config" --seed "$seed" --out "$dir" > "$dir.log" 2>&1 || true
      s="$dir/stats.json"
      if [ -f "$s" ]; then
        set -- $(icp "$s")
        acc=$(accuracy "$ds" "$dir")
        row="$row | $1 | $2 | $acc"
        wall=$(num wall_time_s "$s")
      else
        row="$row | NA | NA | NA"
        wall=NA
      fi
    done
    row="$row | $wall |"
    echo "$row" >> "$table"
    [ "$t$b" = 6010 ] && sdp_time=$wall
  done
  # DP-SLAM with as many particles as fit the SDP-SLAM 60T/10B run time.
  probe="$out/$ds-dpslam-20"
  echo "== $ds dpslam 20 particles (timing probe) -> $probe" >&2
  "$bin" run "$log" --mode dpslam --particles 20 --config "$config" --seed "$seed" --out "$probe" > "$probe.log" 2>&1
  probe_time=$(num wall_time_s "$probe/stats.json")
  n=$(awk -v a="$sdp_time" -v b="$probe_time" 'BEGIN { n = int(20 * a / b); if (n < 1) n = 1; if (n > 512) n = 512; print n }')
  dir="$out/$ds-dpslam-$n"
  echo "== $ds dpslam $n particles -> $dir" >&2
  "$bin" run "$log" --mode dpslam --particles "$n" --config "$config" --seed "$seed" --out "$dir" > "$dir.log" 2>&1
  {
    echo
    echo "DP-SLAM baseline, same run time as SDP-SLAM 60T/10B (${sdp_time} s): $n particles" \
      "(20 particles took ${probe_time} s), $(num wall_time_s "$dir/stats.json") s, $metric $(accuracy "$ds" "$dir")"
    echo
  } >> "$table"
  cat "$table"
done
