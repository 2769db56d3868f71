#!/bin/sh
# DP-SLAM baseline benchmark: Intel and ACES at 30, 100 and 400 particles with ONE set
# of options (tools/slam/default.ini unless CONFIG is given), relations error through
# `sdpslam evaluate`, time per scan and memory from each run's stats.json.
#
#   tools/bench/bench_dpslam.sh BUILD_DIR [OUT_DIR] [PARTICLES...]
#   e.g. tools/bench/bench_dpslam.sh build/release /tmp/dpslam-bench 30 100 400
#
# Environment: CONFIG=file.ini, SEED (default 1), SHARED (default ../shared beside the
# checkout), LOGS (default "intel aces"). Use a Release build; runs are long.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:?usage: bench_dpslam.sh BUILD_DIR [OUT_DIR] [PARTICLES...]}
out=${2:-/tmp/sdpslam-dpslam-bench}
shift 2 2>/dev/null || shift $#
particles=${*:-"30 100 400"}
config=${CONFIG:-$root/tools/slam/default.ini}
seed=${SEED:-1}
shared=${SHARED:-$root/../shared}
logs=${LOGS:-"intel aces"}
bin="$build/tools/cli/sdpslam"
[ -x "$bin" ] || { echo "bench_dpslam.sh: no sdpslam binary in $build" >&2; exit 2; }
mkdir -p "$out"
summary="$out/summary.tsv"
printf 'log\tparticles\ttrans_err_m\trot_err_deg\tscans\tprocessed\twall_s\tscan_ms_p50\tscan_ms_p99\tprocessed_ms_p50\tprocessed_ms_p99\tstate_bytes\tnaive_copy_bytes\tpeak_rss_kib\n' > "$summary"
field() { sed -n "s/.*\"$1\": \([0-9.e+-]*\).*/\1/p" "$2" | head -1; }
for log in $logs; do
  for n in $particles; do
    dir="$out/$log-$n"
    echo "== $log, $n particles -> $dir" >&2
    "$bin" run "$shared/datasets/$log.clf" --mode dpslam --particles "$n" --config "$config" --seed "$seed" --out "$dir"
    eval_json="$dir/evaluate.json"
    if "$bin" evaluate --log "$shared/datasets/$log.clf" --relations "$shared/datasets/$log.relations" \
         --trajectory "$dir/trajectory.txt" --json "$eval_json" > "$dir/evaluate.txt" 2>&1; then
      terr=$(sed -n 's/.*"translation_m": {"mean": \([0-9.e+-]*\), "std": \([0-9.e+-]*\).*/\1±\2/p' "$eval_json")
      rerr=$(sed -n 's/.*"rotation_deg": {"mean": \([0-9.e+-]*\), "std": \([0-9.e+-]*\).*/\1±\2/p' "$eval_json")
    else
      terr=NA; rerr=NA
    fi
    s="$dir/stats.json"
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$log" "$n" "${terr:-NA}" "${rerr:-NA}" \
      "$(field scans "$s")" "$(field processed_scans "$s")" "$(field wall_time_s "$s")" \
      "$(field scan_ms_p50 "$s")" "$(field scan_ms_p99 "$s")" "$(field processed_ms_p50 "$s")" \
      "$(field processed_ms_p99 "$s")" "$(field state_bytes_peak "$s")" "$(field naive_copy_bytes "$s")" \
      "$(field peak_rss_kib "$s")" >> "$summary"
  done
done
column -t -s "$(printf '\t')" "$summary" 2>/dev/null || cat "$summary"
