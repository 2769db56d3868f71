#!/bin/sh
# compare_trajectories.sh DAEMON_TRAJ OFFLINE_TRAJ PLAY_START_US LOG_START_US SPEED [MAX_POS_M MAX_HEADING_RAD [MEAN_POS_M]]
# sdpslamd's stamps are on the monotonic clock; mapped back to log time
#   t_log = LOG_START + (t − PLAY_START) · SPEED
# each of its poses is matched with the offline pose nearest in time (within 20 ms of log
# time). Prints the figures; exit 0 iff every pose matched, every pose is within the
# maximum tolerances (default 0.10 m, 0.05 rad) and the mean position difference is
# within MEAN_POS_M (default: the maximum).
a=$1 b=$2 play=$3 logstart=$4 speed=$5 maxp=${6:-0.10} maxh=${7:-0.05} meanp=${8:-${6:-0.10}}
awk -v play="$play" -v ls="$logstart" -v sp="$speed" -v maxp="$maxp" -v maxh="$maxh" -v meanp="$meanp" '
  /^#/ { next }
  NR == FNR { n = split($1, f, "."); bt[++nb] = f[1] * 1000000 + substr(f[2] "000000", 1, 6); bx[nb] = $2; by[nb] = $3; bh[nb] = $4; next }
  { n = split($1, f, "."); t = f[1] * 1000000 + substr(f[2] "000000", 1, 6)
    tl = ls + (t - play) * sp; na++
    while (j < nb && bt[j + 1] <= tl) j++
    k = j; if (j < nb && (k == 0 || bt[j + 1] - tl < tl - bt[k])) k = j + 1
    if (k == 0 || (bt[k] - tl > 20000) || (tl - bt[k] > 20000)) { unmatched++; next }
    dx = $2 - bx[k]; dy = $3 - by[k]; d = sqrt(dx * dx + dy * dy)
    h = $4 - bh[k]; while (h > 3.14159265) h -= 6.2831853; while (h < -3.14159265) h += 6.2831853; if (h < 0) h = -h
    dt = tl - bt[k]; if (dt < 0) dt = -dt; if (dt > maxdt) maxdt = dt
    if (d > maxd) maxd = d; if (h > maxhd) maxhd = h; sd += d; m++; if (d == 0 && h == 0) same++ }
  END { printf "trajectory vs offline: %d sdpslamd poses, %d offline, %d matched (stamp offset max %.2f ms), %d unmatched; position diff max %.4f m mean %.4f m, heading diff max %.4f rad; identical %d\n",
          na, nb, m, maxdt / 1000, unmatched, maxd, (m ? sd / m : 0), maxhd, same
        exit (m > 0 && unmatched == 0 && maxd <= maxp && maxhd <= maxh && sd / m <= meanp) ? 0 : 1 }' "$b" "$a"
