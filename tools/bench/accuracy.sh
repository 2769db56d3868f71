#!/bin/sh
# Accuracy benchmark: every real log that has ground truth and every built-in simulated
# world, each run once per seed with the same options, so that a change is judged by its
# mean and its worst seed rather than by one lucky run.
#   - logs: `sdpslam run LOG --seed S`, then the relations metric (`sdpslam evaluate
#     --relations`, mean absolute translational error, m), and the along-track scale
#     error of the relations under 2 s apart (evaluate's local span class: whether the
#     steps come out shorter or longer than the true ones, whatever the loops did), and
#     how much of the mean the placement of the run's submaps accounts for (evaluate
#     --segments: the mean less what it is once each segment's frame is fitted rigidly
#     to the relations; the rest lies within the submaps);
#   - worlds: `sdpslam simulate --world NAME --seed S` (the seed also draws the sensor
#     noise, so each seed is a different simulated run), `sdpslam run --seed S` on it, then
#     the absolute trajectory error against the simulator's ground truth (ATE RMSE after
#     SE(2) alignment, m) and the relative error per 10 m of path (`sdpslam evaluate`'s
#     --rpe-m: the local drift, and its along-track part, whatever the loops did), and
#     the loop constraints the run used, checked against that ground truth (`evaluate
#     --loops`: "wrong loops used" counts those 2 m or more off, over all seeds), and the
#     drift of the run's submaps, each from its first scan to its last, per 10 m of path
#     (evaluate --segments), beside the simulated odometry's drift over the same
#     stretches: a bottom level that drifts more than its odometry loses to it;
#     `simulate` has two built-in worlds: "paper", the paper's nested
#     28 m / 80 m loops, and "large", a 203 m x 123 m building with 2.26 km of nested loops,
#     an open hall and featureless corridors, scanned by a 270 deg 30 m laser (its log is
#     about 130 MB per seed).
# From each run's stats.json: CPU seconds of the whole run, worst per-scan CPU time and
# the scans over the 100 ms budget (summed over the seeds), the arena declared at init
# (the state's size), peak RSS, and the refusals (pools.*.exhausted, pools.*.refused,
# pools.*.dropped, out_of_map_updates: capacity running out, which the core survives by
# dropping work), with the bottom level's writes made at a shortened update range
# (pools.observations.writes_shortened) noted beside them.
# Every (log or world, seed) pair is one job in its own folder OUT_DIR/{logs,worlds}/NAME/S
# (run.log, evaluate.json, stats.json, record.tsv); JOBS of them run at once. A failed run
# or evaluation is recorded as NA, the rest go on, and the script exits 1 after printing
# the table. Prints one markdown table (a row per log / world) on stdout and writes it to
# OUT_DIR/accuracy.md, every job's record to OUT_DIR/runs.tsv; progress goes to stderr.
# Needs python3 (reads the JSON) and xargs -P.
#
#   tools/bench/accuracy.sh BUILD_DIR [OUT_DIR]
#   e.g. tools/bench/accuracy.sh build/host-release /tmp/sdpslam-accuracy
#        SEEDS="1 2" LOGS=aces WORLDS= RUN_ARGS="--profile paper" tools/bench/accuracy.sh build/host-release
#
# Environment: SEEDS (default "1 2 3 4 5"), JOBS (runs at once, default nproc), SHARED
# (default ../shared beside the checkout), LOGS (default: every NAME in $SHARED/datasets
# with a NAME.relations and a NAME.clf or NAME.clf.gz; LOGS="" runs none), WORLDS
# (default "paper large"; WORLDS="" runs none), RUN_ARGS (appended to every `sdpslam run`,
# e.g. "--profile paper" or "--config my.ini"; default none). Use a Release build.
# Without $SHARED/datasets only the worlds run. Default OUT_DIR: /tmp/sdpslam-accuracy.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
self="$here/$(basename "$0")"

# One job: `accuracy.sh --job log|world NAME SEED` (run by xargs below, settings in ACC_*).
# Writes DIR/record.tsv; exits 0 whether or not the run and evaluation succeeded.
if [ "${1:-}" = --job ]; then
  kind=$2; name=$3; seed=$4
  bin=$ACC_BIN
  dir="$ACC_OUT/${kind}s/$name/$seed"
  rm -rf "$dir"; mkdir -p "$dir"
  echo "   start $name seed $seed -> $dir" >&2
  status=ok
  if [ "$kind" = log ]; then
    log=$ACC_SHARED/datasets/$name.clf
    [ -f "$log" ] || log=$log.gz
    metric="relations m"
  else
    metric="ATE m"
    if "$bin" simulate --world "$name" --seed "$seed" --out "$dir/sim" > "$dir/simulate.log" 2>&1; then
      log=$dir/sim/sim.clf
    else
      status=simulate_failed
    fi
  fi
  if [ "$status" = ok ]; then
    set -f  # RUN_ARGS is split into words, never globbed
    # shellcheck disable=SC2086
    if "$bin" run "$log" --seed "$seed" --out "$dir" $ACC_RUN_ARGS > "$dir/run.log" 2>&1; then :; else
      status="run_failed(exit $?)"
    fi
    set +f
  fi
  if [ "$status" = ok ]; then
    if [ "$kind" = log ]; then
      set -- --log "$log" --relations "$ACC_SHARED/datasets/$name.relations"
      # sdp mode writes its segments: the frames' placement is measured too.
      if [ -f "$dir/segments.tsv" ]; then set -- "$@" --segments "$dir/segments.tsv"; fi
    else
      set -- --ground-truth "$dir/sim/ground_truth.txt"
      # sdp mode writes its loop constraints: checked against the ground truth too.
      if [ -f "$dir/loops.tsv" ]; then set -- "$@" --loops "$dir/loops.tsv"; fi
      # ... and its segments: the submaps' own drift is measured too, and the odometry's
      # over the same stretches.
      if [ -f "$dir/segments.tsv" ]; then
        set -- "$@" --segments "$dir/segments.tsv"
        if "$bin" evaluate --ground-truth "$dir/sim/ground_truth.txt" --trajectory "$dir/sim/odometry.txt" \
             --segments "$dir/segments.tsv" --rpe-m 0 --json "$dir/evaluate_odometry.json" \
             > "$dir/evaluate_odometry.txt" 2>&1; then :; else
          status="evaluate_failed(odometry, exit $?)"
        fi
      fi
    fi
    if [ "$status" != ok ]; then :
    elif "$bin" evaluate "$@" --trajectory "$dir/trajectory.txt" --json "$dir/evaluate.json" \
         > "$dir/evaluate.txt" 2>&1; then :; else
      status="evaluate_failed(exit $?)"
    fi
  fi
  python3 - "$kind" "$name" "$seed" "$metric" "$status" "$dir" > "$dir/record.tsv.tmp" <<'EOF' ||
import json, os, sys
kind, name, seed, metric, status, d = sys.argv[1:]
def load(f):
    try:
        with open(os.path.join(d, f)) as fh:
            return json.load(fh)
    except (OSError, ValueError):
        return None
value = "NA"
ev = load("evaluate.json") if status == "ok" else None
if status == "ok":
    try:
        value = repr(ev["relations"]["translation_m"]["mean"] if kind == "log" else ev["ate"]["rmse_m"])
    except (TypeError, KeyError):
        status = "evaluate_unreadable"
st = load("stats.json") or {}
t, m, pools = st.get("timing", {}), st.get("memory", {}), st.get("pools", {})
def get(o, k):
    return "NA" if k not in o else str(o[k])
kinds = []
for pool, v in pools.items():
    if isinstance(v, dict):
        kinds += [("%s.%s" % (pool, k), v[k]) for k in ("exhausted", "refused", "dropped") if k in v]
# map_updates_dropped and global_map_updates_dropped repeat the observation and
# permanent-map pools' exhausted counts (the same refusals): not added again.
if "out_of_map_updates" in pools:
    kinds.append(("out_of_map_updates", pools["out_of_map_updates"]))
refusals = str(sum(n for _, n in kinds)) if st else "NA"
nonzero = ",".join("%s=%d" % kn for kn in kinds if kn[1]) or "-"
obs = pools.get("observations", {})
rpe = (ev or {}).get("rpe") or {}
scale = get(rpe, "scale_error")
if kind == "log":
    # The local span class (relations under 2 s apart) comes first.
    spans = ((ev or {}).get("relations") or {}).get("by_span") or [{}]
    local = spans[0].get("scale_error")
    scale = "NA" if local is None else repr(local)
used = ((ev or {}).get("loops") or {}).get("used") or {}
fit = (((ev or {}).get("relations") or {}).get("frame_fit") or {}).get("all") or {}
placement = repr(fit["mean_m"] - fit["fitted_mean_m"]) if "mean_m" in fit else "NA"
seg = (ev or {}).get("segment_drift") or {}
odo = ((load("evaluate_odometry.json") if status == "ok" else None) or {}).get("segment_drift") or {}
print("\t".join([kind, name, seed, metric, value, status, get(t, "cpu_time_s"), get(t, "scan_cpu_ms_max"),
                 get(m, "arena_bytes"), get(t, "peak_rss_kib"), get(t, "wall_time_s"), refusals, nonzero, d,
                 get(rpe, "mean_m"), scale, get(used, "count"), get(used, "wrong"),
                 get(obs, "writes_shortened"), get(obs, "shortest_write_reach_m"), get(t, "scans_cpu_over_100ms"),
                 placement, get(seg, "drift_per_10m_m"), get(odo, "drift_per_10m_m")]))
EOF
  printf '%s\t%s\t%s\t%s\tNA\trecord_failed\tNA\tNA\tNA\tNA\tNA\tNA\t-\t%s\tNA\tNA\tNA\tNA\tNA\tNA\tNA\tNA\tNA\tNA\n' \
    "$kind" "$name" "$seed" "$metric" "$dir" > "$dir/record.tsv.tmp"
  mv "$dir/record.tsv.tmp" "$dir/record.tsv"
  value=$(cut -f5 "$dir/record.tsv"); status=$(cut -f6 "$dir/record.tsv")
  if [ "$status" = ok ]; then
    echo "   done  $name seed $seed: $metric $value (cpu $(cut -f7 "$dir/record.tsv") s)" >&2
  else
    echo "   FAIL  $name seed $seed: $status, see $dir" >&2
  fi
  exit 0
fi

root=$(cd "$here/../.." && pwd)
build=${1:?usage: accuracy.sh BUILD_DIR [OUT_DIR]}
out=${2:-/tmp/sdpslam-accuracy}
seeds=${SEEDS:-"1 2 3 4 5"}
jobs=${JOBS:-$(nproc 2>/dev/null || getconf _NPROCESSORS_ONLN 2>/dev/null || echo 1)}
shared=${SHARED:-$root/../shared}
worlds=${WORLDS-paper large}
run_args=${RUN_ARGS:-}
bin="$build/tools/cli/sdpslam"
[ -x "$bin" ] || { echo "accuracy.sh: no sdpslam binary in $build" >&2; exit 2; }
command -v python3 > /dev/null || { echo "accuracy.sh: needs python3 (apt-get install python3)" >&2; exit 2; }
case $jobs in ''|*[!0-9]*|0) echo "accuracy.sh: JOBS must be a positive integer, not '$jobs'" >&2; exit 2;; esac
[ -n "$seeds" ] || { echo "accuracy.sh: SEEDS is empty" >&2; exit 2; }
for s in $seeds; do
  case $s in *[!0-9]*) echo "accuracy.sh: seeds are non-negative integers, not '$s'" >&2; exit 2;; esac
done
for w in $worlds; do
  case $w in
    paper|large) ;;
    *) echo "accuracy.sh: unknown world '$w' (sdpslam simulate's built-in worlds: paper, large)" >&2; exit 2;;
  esac
done

# has_log NAME: the dataset has ground-truth relations and a CARMEN log.
has_log() {
  [ -f "$shared/datasets/$1.relations" ] || return 1
  [ -f "$shared/datasets/$1.clf" ] || [ -f "$shared/datasets/$1.clf.gz" ]
}
if [ ! -d "$shared/datasets" ]; then
  echo "accuracy.sh: no datasets in $shared/datasets (set SHARED): running the simulated worlds only" >&2
  logs=""
elif [ "${LOGS+set}" = set ]; then
  logs=$LOGS
  for l in $logs; do
    has_log "$l" || { echo "accuracy.sh: log '$l' needs $shared/datasets/$l.relations and $l.clf or $l.clf.gz" >&2; exit 2; }
  done
else
  logs=""
  for r in "$shared/datasets"/*.relations; do
    [ -f "$r" ] || continue
    l=$(basename "$r" .relations)
    if has_log "$l"; then logs="${logs:+$logs }$l"; fi
  done
fi
mkdir -p "$out"
joblist="$out/jobs.txt"
: > "$joblist"
for l in $logs; do for s in $seeds; do echo "log $l $s" >> "$joblist"; done; done
for w in $worlds; do for s in $seeds; do echo "world $w $s" >> "$joblist"; done; done
[ -s "$joblist" ] || { echo "accuracy.sh: nothing to run (no logs, WORLDS empty)" >&2; exit 2; }
echo "== accuracy: $(wc -l < "$joblist") jobs, $jobs at a time; logs: ${logs:-none}; worlds: ${worlds:-none};" \
  "seeds: $seeds; RUN_ARGS: ${run_args:-none}; outputs in $out" >&2

ACC_BIN=$bin ACC_OUT=$out ACC_SHARED=$shared ACC_RUN_ARGS=$run_args
export ACC_BIN ACC_OUT ACC_SHARED ACC_RUN_ARGS
xargs -P "$jobs" -L 1 sh "$self" --job < "$joblist" || echo "accuracy.sh: a job ended abnormally" >&2

# runs.tsv in job order; a job that left no record counts as failed.
runs="$out/runs.tsv"
printf 'kind\tname\tseed\tmetric\tvalue_m\tstatus\tcpu_time_s\tscan_cpu_ms_max\tarena_bytes\tpeak_rss_kib\twall_time_s\trefusals\trefusal_kinds\tdir\trpe_m\trpe_scale\tloops_used\tloops_used_wrong\twrites_shortened\tshortest_write_reach_m\tscans_cpu_over_100ms\tplacement_m\tsubmap_drift_m\todometry_drift_m\n' > "$runs"
while read -r kind name seed; do
  rec="$out/${kind}s/$name/$seed/record.tsv"
  if [ -f "$rec" ]; then cat "$rec"; else
    printf '%s\t%s\t%s\tNA\tNA\tno_record\tNA\tNA\tNA\tNA\tNA\tNA\t-\t%s\tNA\tNA\tNA\tNA\tNA\tNA\tNA\tNA\tNA\tNA\n' "$kind" "$name" "$seed" "${rec%/*}"
  fi
done < "$joblist" >> "$runs"

python3 - "$runs" "$out/accuracy.md" <<'EOF'
import sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1])]
head, rows = rows[0], [dict(zip(rows[0], r)) for r in rows[1:]]
groups = {}
for r in rows:
    groups.setdefault((r["kind"], r["name"]), []).append(r)
def num(v):
    return None if v == "NA" else float(v)
def fmt(v, f):
    return "NA" if v is None else f % v
def nums(rs, k):
    return [x for x in (num(r[k]) for r in rs) if x is not None]
out = ["| name | metric | mean | worst (seed) | per seed | frames' placement m | drift m per 10 m, mean (worst) "
       "| submaps' drift m per 10 m (odometry's) | along-track % | wrong loops used | CPU s mean | CPU s max | worst scan ms | scans over 100 ms | state bytes "
       "| peak RSS MiB | refusals |",
       "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
for (kind, name), rs in groups.items():
    metric = "relations m" if kind == "log" else "ATE m"
    ok = [(num(r["value_m"]), r["seed"]) for r in rs if num(r["value_m"]) is not None]
    mean = sum(v for v, _ in ok) / len(ok) if ok else None
    mean_s = fmt(mean, "%.3f") + ("" if len(ok) == len(rs) else " (%d of %d)" % (len(ok), len(rs)))
    worst = "NA" if not ok else "%.3f (%s)" % max(ok, key=lambda vs: vs[0])
    per = ", ".join("%s: %s" % (r["seed"], fmt(num(r["value_m"]), "%.3f")) for r in rs)
    cpu = nums(rs, "cpu_time_s")
    scan, arena, rss, ref = (nums(rs, k) for k in ("scan_cpu_ms_max", "arena_bytes", "peak_rss_kib", "refusals"))
    # The 100 ms budget per scan (speed target): the scans of all seeds over it.
    slow = nums(rs, "scans_cpu_over_100ms")
    kinds = sorted({k.split("=")[0] for r in rs if r["refusal_kinds"] != "-" for k in r["refusal_kinds"].split(",")})
    refs = "NA" if not ref else "%d" % sum(ref) + (" (%s)" % ", ".join(kinds) if kinds else "")
    # Writes the observation pool could only take with a shortened update range (not
    # refusals: every writer kept its near cells), and the shortest such range.
    short = [(n, num(r["shortest_write_reach_m"])) for r in rs for n in [num(r["writes_shortened"])] if n]
    if short:
        refs += "; %d writes shortened (to %.2f m)" % (sum(n for n, _ in short), min(m for _, m in short))
    # The relative error needs a ground-truth trajectory: the worlds have one, the logs
    # not. The along-track scale: the worlds' per 10 m of path, the logs' over their
    # relations under 2 s apart.
    rpe, scale = nums(rs, "rpe_m"), nums(rs, "rpe_scale")
    drift = "-" if not rpe else "%.3f (%.3f)" % (sum(rpe) / len(rpe), max(rpe))
    along = "-" if not scale else "%+.2f" % (100.0 * sum(scale) / len(scale))
    # The part of the relations error a rigid fit of the segments' frames takes away:
    # what the submaps' placement (loop closure) costs, mean over the seeds.
    place = nums(rs, "placement_m")
    placement = "-" if not place else "%.3f" % (sum(place) / len(place))
    # The submaps' drift from first to last scan, and the odometry's over the same
    # stretches, per 10 m of path, mean over the seeds (worlds only: a ground truth).
    sub, odo = nums(rs, "submap_drift_m"), nums(rs, "odometry_drift_m")
    submaps = "-" if not sub else "%.3f (%s)" % (sum(sub) / len(sub), fmt(sum(odo) / len(odo) if odo else None, "%.3f"))
    # Loop constraints used at the end that the ground truth says are 2 m or more off.
    used, wrong = nums(rs, "loops_used"), nums(rs, "loops_used_wrong")
    loops = "-" if not used else "%d of %d" % (sum(wrong), sum(used))
    out.append("| %s |" % " | ".join([name, metric, mean_s, worst, per, placement, drift, submaps, along, loops,
        fmt(sum(cpu) / len(cpu) if cpu else None, "%.1f"), fmt(max(cpu) if cpu else None, "%.1f"),
        fmt(max(scan) if scan else None, "%.1f"), fmt(sum(slow) if slow else None, "%d"),
        fmt(max(arena) if arena else None, "%d"),
        fmt(max(rss) / 1024 if rss else None, "%.1f"), refs]))
text = "\n".join(out) + "\n"
open(sys.argv[2], "w").write(text)
sys.stdout.write(text)
EOF
failed=$(awk -F '\t' 'NR > 1 && $6 != "ok"' "$runs" | wc -l)
if [ "$failed" -gt 0 ]; then
  echo "accuracy.sh: $failed of $(wc -l < "$joblist") jobs failed (NA above); see status in $runs" >&2
  exit 1
fi
