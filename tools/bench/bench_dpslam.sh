#!/bin/sh
# DP-SLAM baseline benchmark: Intel and ACES at 30, 100 and 400 particles with ONE set
# of options (firmware-host/runtime/slam/default.ini unless CONFIG is given): relations error (mean±std,
# `sdpslam evaluate`), CPU seconds of the whole run (user+sys from /usr/bin/time: the
# machine may be shared, so wall time is not the figure), per-scan CPU time p50/p99/max and
# pool high-water marks from each run's stats.json, peak RSS, and the memory a naive
# per-particle copy of the best map would take.
#
#   tools/bench/bench_dpslam.sh BUILD_DIR [OUT_DIR] [PARTICLES...]
#   e.g. tools/bench/bench_dpslam.sh build/release /tmp/dpslam-bench 30 100 400
#
# Environment: CONFIG=file.ini, SEED (default 1), SHARED (default ../shared beside the
# checkout), LOGS (default "intel aces"), REUSE=1 (tabulate existing run directories
# instead of running again). Runs one at a time; use a Release build (400 particles on
# Intel: several CPU-minutes).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:?usage: bench_dpslam.sh BUILD_DIR [OUT_DIR] [PARTICLES...]}
out=${2:-/tmp/sdpslam-dpslam-bench}
shift 2 2>/dev/null || shift $#
particles=${*:-"30 100 400"}
config=${CONFIG:-$root/firmware-host/runtime/slam/default.ini}
seed=${SEED:-1}
shared=${SHARED:-$root/../shared}
logs=${LOGS:-"intel aces"}
bin="$build/tools/cli/sdpslam"
[ -x "$bin" ] || { echo "bench_dpslam.sh: no sdpslam binary in $build" >&2; exit 2; }
mkdir -p "$out"
summary="$out/summary.tsv"
printf 'log\tparticles\ttrans_err_m\trot_err_deg\tscans\tprocessed\tcpu_s\tscan_cpu_ms_p50\tscan_cpu_ms_p99\tscan_cpu_ms_max\tnodes_peak\tobs_peak\ttiles_peak\tstate_bytes\tnaive_copy_bytes\tpeak_rss_kib\n' > "$summary"
field() { sed -n "s/.*\"$1\": \([0-9.e+-]*\).*/\1/p" "$2" | head -1; }
peak() { sed -n "s/.*\"$1\": {\"capacity\": [0-9]*, \"peak\": \([0-9]*\).*/\1/p" "$2" | head -1; }
for log in $logs; do
  for n in $particles; do
    dir="$out/$log-$n"
    if [ "${REUSE:-0}" != 1 ] || [ ! -f "$dir/stats.json" ]; then
      echo "== $log, $n particles -> $dir" >&2
      mkdir -p "$dir"
      /usr/bin/time -f '%U %S %M' -o "$dir/cpu.txt" \
        "$bin" run "$shared/datasets/$log.clf" --mode dpslam --particles "$n" --config "$config" --seed "$seed" \
        --out "$dir" 2>"$dir/run.err" || { echo "run failed: see $dir/run.err" >&2; continue; }
    fi
    eval_json="$dir/evaluate.json"
    if "$bin" evaluate --log "$shared/datasets/$log.clf" --relations "$shared/datasets/$log.relations" \
         --trajectory "$dir/trajectory.txt" --json "$eval_json" > "$dir/evaluate.txt" 2>&1; then
      terr=$(sed -n 's/.*"translation_m": {"mean": \([0-9.e+-]*\), "std": \([0-9.e+-]*\).*/\1±\2/p' "$eval_json")
      rerr=$(sed -n 's/.*"rotation_deg": {"mean": \([0-9.e+-]*\), "std": \([0-9.e+-]*\).*/\1±\2/p' "$eval_json")
    else
      terr=NA; rerr=NA
    fi
    cpu=$(awk 'NF >= 3 && $1 ~ /^[0-9.]+$/ { printf "%.1f", $1 + $2 }' "$dir/cpu.txt" 2>/dev/null || true)
    s="$dir/stats.json"
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$log" "$n" "${terr:-NA}" "${rerr:-NA}" \
      "$(field scans "$s")" "$(field processed_scans "$s")" "${cpu:-NA}" \
      "$(field scan_cpu_ms_p50 "$s")" "$(field scan_cpu_ms_p99 "$s")" "$(field scan_cpu_ms_max "$s")" \
      "$(peak ancestry_nodes "$s")" "$(peak observations "$s")" "$(peak tiles "$s")" \
      "$(field state_bytes_peak "$s")" "$(field naive_copy_bytes "$s")" "$(field peak_rss_kib "$s")" >> "$summary"
  done
done
column -t -s "$(printf '\t')" "$summary" 2>/dev/null || cat "$summary"
