#!/usr/bin/env python3
"""Measures a CARMEN log's angle between laser beams from the scans themselves.

    laser_spacing.py LOG [--relations REL] [--min-turn-deg D] [--min-travel-m M]
                         [--max-gap-s S] [--pairs N]

A FLASER line holds ranges only: how far apart its beams are is a convention of the
reader. Two conventions are in use for 180 and 360 beams. The one that CARMEN's own log
reader assumes (src/logger/readlog.c, carmen_laser_guess_angle_increment): 1 deg for 180
or 181 beams, 0.5 deg for 360 or 361, 0.25 deg for 400 or 401 (the 180, 360 and 400
beam logs dropped the last beam of the scanner's 181, 361 and 401). And beams spread
evenly over 180 deg, 180 / (n - 1) deg apart, the one sdpslam's reader takes
(firmware-host/runtime/io/src/carmen_parse.cpp). For 180 beams they differ by 0.56 %,
about 1 deg at the last beam. A log may also say it in a PARAM line
(laser_front_laser_resolution, degrees), which is printed when present.

The data can tell them apart: a wrong spacing bends every scan a little (each beam is
off by its index times the error), so two scans of the same place taken at headings
20 deg or more apart no longer fit each other. Each pair of such scans is registered
(point-to-point ICP from a starting guess, then the mean point-to-segment distance of
the matched points) once per candidate spacing, and the mean residual over the pairs is
printed per candidate; the smallest is the spacing the scans agree with. The scans are
centred on the robot's x axis for every candidate: a constant rotation of the laser does
not change how well two scans fit.

Only pairs that moved as well as turned tell: a turn on the spot shifts every beam of a
scan with a stretched spacing by the same angle, which the registration takes as a
turn. Pairs: with --relations (a Kuemmerle relations file of the log), the relations
whose turn is at least D (most are revisits), starting from the relation; without it,
each scan with the first later one within S seconds that turned at least D and moved
at least M by odometry (the FLASER line's odometry pose), starting from the odometry.
At most N pairs, in the log's order. Needs python3 only.

    e.g. python3 tools/bench/laser_spacing.py ../shared/datasets/intel.clf \\
             --relations ../shared/datasets/intel.relations
"""
import argparse
import collections
import gzip
import math
import sys

GATE_M = 0.25     # ICP: pairs farther apart are not matched
FIT_GATE_M = 0.1  # residual: matched points farther than this are left out
MAX_RANGE_M = 15.0
MIN_RANGE_M = 0.05


def read_log(path):
    """FLASER scans as (stamp text, ranges, odometry pose) and the PARAM values."""
    opener = gzip.open if path.endswith(".gz") else open
    scans = []
    params = {}
    with opener(path, "rt") as f:
        for number, line in enumerate(f, 1):
            fields = line.split()
            if not fields:
                continue
            if fields[0] == "PARAM" and len(fields) >= 3:
                params[fields[1]] = fields[2]
                continue
            if fields[0] != "FLASER":
                continue
            try:
                n = int(fields[1])
                ranges = [float(v) for v in fields[2:2 + n]]
                odom = tuple(float(v) for v in fields[2 + n + 3:2 + n + 6])
                stamp = fields[-3]
            except (ValueError, IndexError):
                sys.exit("%s:%d: malformed FLASER line" % (path, number))
            if len(ranges) != n or len(odom) != 3:
                sys.exit("%s:%d: malformed FLASER line" % (path, number))
            scans.append((stamp, ranges, odom))
    return scans, params


def relative(a, b):
    """Pose b in the frame of pose a (x, y, heading)."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    c, s = math.cos(a[2]), math.sin(a[2])
    return (c * dx + s * dy, -s * dx + c * dy, math.remainder(b[2] - a[2], 2.0 * math.pi))


def pairs_from_relations(scans, path, min_turn, limit):
    index = {stamp: i for i, (stamp, _, _) in enumerate(scans)}
    out = []
    with open(path) as f:
        for number, line in enumerate(f, 1):
            p = line.split()
            if len(p) < 8:
                continue
            if p[0] not in index or p[1] not in index:
                continue
            try:
                guess = (float(p[2]), float(p[3]), float(p[7]))
            except ValueError:
                sys.exit("%s:%d: malformed relation" % (path, number))
            if abs(guess[2]) >= min_turn:
                out.append((index[p[0]], index[p[1]], guess))
            if len(out) == limit:
                break
    return out


def pairs_from_odometry(scans, min_turn, min_travel_m, max_gap_s, limit):
    out = []
    for i, (stamp, _, odom) in enumerate(scans):
        t0 = float(stamp)
        for j in range(i + 1, len(scans)):
            if float(scans[j][0]) - t0 > max_gap_s:
                break
            guess = relative(odom, scans[j][2])
            if abs(guess[2]) >= min_turn and math.hypot(guess[0], guess[1]) >= min_travel_m:
                out.append((i, j, guess))
                break
        if len(out) == limit:
            break
    return out


def points(ranges, increment):
    start = -0.5 * increment * (len(ranges) - 1)
    out = []
    for i, r in enumerate(ranges):
        if MIN_RANGE_M < r < MAX_RANGE_M:
            a = start + i * increment
            out.append((r * math.cos(a), r * math.sin(a)))
    return out


class Grid:
    """Nearest neighbour among a scan's points within GATE_M."""

    def __init__(self, pts):
        self.pts = pts
        self.cells = collections.defaultdict(list)
        for k, (x, y) in enumerate(pts):
            self.cells[(math.floor(x / GATE_M), math.floor(y / GATE_M))].append(k)

    def nearest(self, x, y, gate):
        cx, cy = math.floor(x / GATE_M), math.floor(y / GATE_M)
        best, best_k = gate, -1
        for gx in (cx - 1, cx, cx + 1):
            for gy in (cy - 1, cy, cy + 1):
                for k in self.cells.get((gx, gy), ()):
                    d = math.hypot(self.pts[k][0] - x, self.pts[k][1] - y)
                    if d < best:
                        best, best_k = d, k
        return best, best_k


def register(a_pts, b_pts, guess, iterations=25):
    """Mean point-to-segment residual of b on a after ICP from guess; None if too few pairs."""
    grid = Grid(a_pts)
    x, y, th = guess
    for _ in range(iterations):
        c, s = math.cos(th), math.sin(th)
        matched = []
        for bx, by in b_pts:
            qx, qy = x + c * bx - s * by, y + s * bx + c * by
            _, k = grid.nearest(qx, qy, GATE_M)
            if k >= 0:
                matched.append((bx, by, a_pts[k][0], a_pts[k][1]))
        if len(matched) < 20:
            return None
        m = float(len(matched))
        mbx = sum(v[0] for v in matched) / m
        mby = sum(v[1] for v in matched) / m
        max_ = sum(v[2] for v in matched) / m
        may = sum(v[3] for v in matched) / m
        sxx = sum((v[0] - mbx) * (v[2] - max_) + (v[1] - mby) * (v[3] - may) for v in matched)
        sxy = sum((v[0] - mbx) * (v[3] - may) - (v[1] - mby) * (v[2] - max_) for v in matched)
        th = math.atan2(sxy, sxx)
        c, s = math.cos(th), math.sin(th)
        x, y = max_ - (c * mbx - s * mby), may - (s * mbx + c * mby)
    total, count = 0.0, 0
    for bx, by in b_pts:
        qx, qy = x + c * bx - s * by, y + s * bx + c * by
        d, k = grid.nearest(qx, qy, FIT_GATE_M)
        if k < 0:
            continue
        # The segments to the point's neighbours in the scan (its beams' order).
        for j in (k - 1, k + 1):
            if 0 <= j < len(a_pts):
                ax, ay = a_pts[k]
                vx, vy = a_pts[j][0] - ax, a_pts[j][1] - ay
                length2 = vx * vx + vy * vy
                if 0.0 < length2 < 0.04:
                    t = max(0.0, min(1.0, ((qx - ax) * vx + (qy - ay) * vy) / length2))
                    d = min(d, math.hypot(ax + t * vx - qx, ay + t * vy - qy))
        total += d
        count += 1
    return total / count if count else None


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("log")
    ap.add_argument("--relations", help="Kuemmerle relations file: pairs and starting guesses")
    ap.add_argument("--min-turn-deg", type=float, default=20.0)
    ap.add_argument("--min-travel-m", type=float, default=0.5)
    ap.add_argument("--max-gap-s", type=float, default=5.0)
    ap.add_argument("--pairs", type=int, default=120)
    args = ap.parse_args(argv[1:])
    if not (0.0 < args.min_turn_deg < 180.0) or args.min_travel_m < 0.0 or args.max_gap_s <= 0.0 or args.pairs < 1:
        sys.exit("laser_spacing.py: --min-turn-deg in (0, 180), --min-travel-m >= 0, --max-gap-s > 0, --pairs >= 1")
    scans, params = read_log(args.log)
    if not scans:
        sys.exit("%s: no FLASER line" % args.log)
    n = len(scans[0][1])
    if any(len(r) != n for _, r, _ in scans):
        sys.exit("%s: FLASER lines with different beam counts" % args.log)
    min_turn = math.radians(args.min_turn_deg)
    if args.relations:
        pairs = pairs_from_relations(scans, args.relations, min_turn, args.pairs)
    else:
        pairs = pairs_from_odometry(scans, min_turn, args.min_travel_m, args.max_gap_s, args.pairs)
    if not pairs:
        sys.exit("%s: no pair of scans turned %.1f deg apart%s" % (
            args.log, args.min_turn_deg, "" if args.relations else " and moved %.2f m" % args.min_travel_m))

    # Candidate spacings (deg) and their names; one spacing that two conventions share
    # (181 and 361 beams) is one row named after both.
    reader_deg = 180.0 / (n - 1)
    carmen_deg = {180: 1.0, 181: 1.0, 360: 0.5, 361: 0.5, 400: 0.25, 401: 0.25}.get(n, reader_deg)
    named = [(reader_deg, "evenly over 180 deg, 180/(n-1) (sdpslam's reader)"), (carmen_deg, "CARMEN readlog.c")]
    named += [(180.0 / n * f, "180/n x %.3f" % f) for f in (0.988, 0.992, 0.996, 1.004, 1.008, 1.012)]
    candidates = {}
    for increment_deg, name in named:
        candidates[increment_deg] = candidates[increment_deg] + "; " + name if increment_deg in candidates else name
    print("%s: %d beams per scan, %d scan pairs turned %.0f deg or more apart (%s)"
          % (args.log, n, len(pairs), args.min_turn_deg, "relations" if args.relations else "odometry"))
    if "laser_front_laser_resolution" in params:
        print("the log's PARAM laser_front_laser_resolution: %s deg" % params["laser_front_laser_resolution"])
    # Every candidate is judged on the same pairs: those registered under all of them.
    ordered = sorted(candidates.items())
    residuals = []
    for increment_deg, _ in ordered:
        inc = math.radians(increment_deg)
        residuals.append([register(points(scans[i][1], inc), points(scans[j][1], inc), guess)
                          for i, j, guess in pairs])
    common = [k for k in range(len(pairs)) if all(r[k] is not None for r in residuals)]
    if not common:
        sys.exit("%s: no pair registered under every candidate spacing" % args.log)
    # Paired differences against the reader's spacing: the pairs differ far more from one
    # another than the candidates do, so each candidate's mean is compared pair by pair,
    # with the standard error of that mean difference.
    reader = [increment_deg for increment_deg, _ in ordered].index(reader_deg)
    rows = []
    for (increment_deg, name), r in zip(ordered, residuals):
        mean = sum(r[k] for k in common) / len(common)
        diffs = [r[k] - residuals[reader][k] for k in common]
        d = sum(diffs) / len(diffs)
        se = math.sqrt(sum((v - d) ** 2 for v in diffs) / (len(diffs) - 1) / len(diffs)) if len(diffs) > 1 else 0.0
        rows.append((increment_deg, name, mean, d, se))
    best = min(rows, key=lambda row: row[2])
    print("judged on the %d pairs registered under every candidate" % len(common))
    print("| beam spacing, deg | spanned, deg | candidate | mean residual, m | minus the reader's, mm (std error) |")
    print("|---|---|---|---|---|")
    for increment_deg, name, mean, d, se in rows:
        mark = " (least)" if increment_deg == best[0] else ""
        print("| %.5f | %.2f | %s%s | %.5f | %+.3f (%.3f) |" % (increment_deg, increment_deg * (n - 1), name, mark, mean,
                                                              1000.0 * d, 1000.0 * se))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
