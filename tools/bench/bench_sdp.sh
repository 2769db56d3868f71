#!/bin/sh
# SDP-SLAM benchmark: Intel and ACES with ONE option set (the default profile, accurate,
# with firmware-host/runtime/slam/default.ini on top unless PROFILE / CONFIG say otherwise) at the
# paper's 60T/10B unless TB says otherwise: relations error
# through `sdpslam evaluate`, per-scan time (median, p99, max), the fixed arena declared
# at init, pool high-water marks and peak RSS from each run's stats.json.
#
#   tools/bench/bench_sdp.sh BUILD_DIR [OUT_DIR]
#   e.g. tools/bench/bench_sdp.sh build/release /tmp/sdp-bench
#
# Environment: PROFILE (accurate or paper), CONFIG=file.ini, SEED (default 1), SHARED (default ../shared beside the
# checkout), LOGS (default "intel aces"), TB (default "60/10": top/bottom particles,
# several allowed: "60/10 30/5"), TOPOLOGY (sdp or segslam, default sdp).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:?usage: bench_sdp.sh BUILD_DIR [OUT_DIR]}
out=${2:-/tmp/sdpslam-sdp-bench}
config=${CONFIG:-$root/firmware-host/runtime/slam/default.ini}
profile=${PROFILE:-accurate}
seed=${SEED:-1}
shared=${SHARED:-$root/../shared}
logs=${LOGS:-"intel aces"}
tbs=${TB:-"60/10"}
topology=${TOPOLOGY:-sdp}
bin="$build/tools/cli/sdpslam"
[ -x "$bin" ] || { echo "bench_sdp.sh: no sdpslam binary in $build" >&2; exit 2; }
mkdir -p "$out"
summary="$out/summary.tsv"
printf 'log\tTB\ttrans_err_m\trot_err_deg\ticp_err_m\tscans\tprocessed\tsegments\twall_s\tscan_ms_p50\tscan_ms_p99\tscan_ms_max\tarena_bytes\tobservations_peak\tnodes_peak\tpeak_rss_kib\n' > "$summary"
field() { sed -n "s/.*\"$1\": \([0-9.e+-]*\).*/\1/p" "$2" | head -1; }
peak() { sed -n "s/.*\"$1\": {\"capacity\": [0-9]*, \"peak\": \([0-9]*\).*/\1/p" "$2" | head -1; }
for log in $logs; do
  for tb in $tbs; do
    t=${tb%/*}; b=${tb#*/}
    dir="$out/$log-${t}T${b}B"
    echo "== $log, ${t}T/${b}B ($topology) -> $dir" >&2
    "$bin" run "$shared/datasets/$log.clf" --mode sdp --topology "$topology" --top-particles "$t" --particles "$b" \
      --profile "$profile" --config "$config" --seed "$seed" --out "$dir"
    eval_json="$dir/evaluate.json"
    if "$bin" evaluate --log "$shared/datasets/$log.clf" --relations "$shared/datasets/$log.relations" \
         --trajectory "$dir/trajectory.txt" --json "$eval_json" > "$dir/evaluate.txt" 2>&1; then
      terr=$(sed -n 's/.*"translation_m": {"mean": \([0-9.e+-]*\), "std": \([0-9.e+-]*\).*/\1±\2/p' "$eval_json")
      rerr=$(sed -n 's/.*"rotation_deg": {"mean": \([0-9.e+-]*\), "std": \([0-9.e+-]*\).*/\1±\2/p' "$eval_json")
    else
      terr=NA; rerr=NA
    fi
    s="$dir/stats.json"
    icp=$(sed -n 's/.*"icp_error": {"mean_m": \([0-9.e+-]*\), "std_m": \([0-9.e+-]*\).*/\1±\2/p' "$s")
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$log" "${t}T/${b}B" "${terr:-NA}" \
      "${rerr:-NA}" "${icp:-NA}" "$(field scans "$s")" "$(field processed_scans "$s")" "$(field segments "$s")" \
      "$(field wall_time_s "$s")" "$(field scan_ms_p50 "$s")" "$(field scan_ms_p99 "$s")" "$(field scan_ms_max "$s")" \
      "$(field arena_bytes "$s")" "$(peak observations "$s")" "$(peak ancestry_nodes "$s")" \
      "$(field peak_rss_kib "$s")" >> "$summary"
  done
done
column -t -s "$(printf '\t')" "$summary" 2>/dev/null || cat "$summary"
