#!/usr/bin/env python3
"""tools/bench/laser_spacing.py on synthetic CARMEN logs whose beam spacing is known.

    test_laser_spacing.py TOOL WORK_DIR

A robot drives a rounded loop through a room with pillars and a partition (odometry
exact, ranges with 5 mm noise from a fixed seed) and logs FLASER lines of 180 beams,
once 1 deg apart (CARMEN's convention) and once spread evenly over 180 deg. Each time the
tool must find the spacing the log was made with: its least residual within 0.45 % of
it (the candidates are 0.4 % apart), and the other convention's residual larger than
the true one by more than twice the standard error of the paired difference. A log
without FLASER lines must fail with a message naming the file.
"""
import math
import os
import random
import subprocess
import sys

BEAMS = 180
WALLS = [  # x1 y1 x2 y2, metres: a 12 x 9 m room, a partition, two pillars
    (0, 0, 12, 0), (12, 0, 12, 9), (12, 9, 0, 9), (0, 9, 0, 0),
    (5, 0, 5, 3.5), (7, 9, 7, 6),
    (2.5, 4, 3, 4), (3, 4, 3, 4.5), (3, 4.5, 2.5, 4.5), (2.5, 4.5, 2.5, 4),
    (9, 4.5, 9.6, 4.5), (9.6, 4.5, 9.6, 5.1), (9.6, 5.1, 9, 5.1), (9, 5.1, 9, 4.5),
]


def cast(x, y, a, max_range=20.0):
    dx, dy = math.cos(a), math.sin(a)
    best = max_range
    for x1, y1, x2, y2 in WALLS:
        ex, ey = x2 - x1, y2 - y1
        den = dx * ey - dy * ex
        if abs(den) < 1e-12:
            continue
        t = ((x1 - x) * ey - (y1 - y) * ex) / den
        u = ((x1 - x) * dy - (y1 - y) * dx) / den
        if t > 0.0 and 0.0 <= u <= 1.0 and t < best:
            best = t
    return best


def route():
    """Poses every 0.2 s along a rounded rectangle (corners turned while moving)."""
    corners = [(1.5, 1.5), (10.5, 1.5), (10.5, 7.5), (1.5, 7.5)]
    radius, speed, dt = 1.0, 0.5, 0.2
    poses = []
    for k in range(4):
        (ax, ay), (bx, by) = corners[k], corners[(k + 1) % 4]
        heading = math.atan2(by - ay, bx - ax)
        length = math.hypot(bx - ax, by - ay) - 2.0 * radius
        sx, sy = ax + radius * math.cos(heading), ay + radius * math.sin(heading)
        steps = int(length / (speed * dt))
        for i in range(steps):
            d = i * speed * dt
            poses.append((sx + d * math.cos(heading), sy + d * math.sin(heading), heading))
        # Quarter circle to the next side, centred inside the corner.
        ex, ey = bx - radius * math.cos(heading), by - radius * math.sin(heading)
        cx, cy = ex - radius * math.sin(heading), ey + radius * math.cos(heading)
        arc_steps = int(0.5 * math.pi * radius / (speed * dt))
        for i in range(arc_steps):
            phi = 0.5 * math.pi * i / arc_steps
            poses.append((cx + radius * math.sin(heading + phi), cy - radius * math.cos(heading + phi), heading + phi))
    return poses


def write_log(path, increment_rad, seed):
    rng = random.Random(seed)
    start = -0.5 * increment_rad * (BEAMS - 1)
    with open(path, "w") as f:
        f.write("# synthetic FLASER log, %d beams %.6f deg apart\n" % (BEAMS, math.degrees(increment_rad)))
        for k, (x, y, th) in enumerate(route()):
            ranges = [cast(x, y, th + start + i * increment_rad) + rng.gauss(0.0, 0.005) for i in range(BEAMS)]
            stamp = "%.6f" % (1000.0 + 0.2 * k)
            f.write("FLASER %d %s %.6f %.6f %.6f %.6f %.6f %.6f %s test %s\n" % (
                BEAMS, " ".join("%.4f" % r for r in ranges), x, y, th, x, y, th, stamp, stamp))


def table(output):
    """(spacing deg, candidate, mean residual, difference mm, std error mm) per row."""
    rows = []
    for line in output.splitlines():
        if not line.startswith("| ") or line.startswith("| beam"):
            continue
        cells = [c.strip() for c in line.strip("|").split("|")]
        diff, se = cells[4].split(" (")
        rows.append((float(cells[0]), cells[2], float(cells[3]), float(diff), float(se.rstrip(")"))))
    return rows


def check(tool, work, name, truth_deg, other_deg):
    log = os.path.join(work, name + ".clf")
    write_log(log, math.radians(truth_deg), 7)
    run = subprocess.run([sys.executable, tool, log, "--pairs", "60"], capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit("%s: the tool failed: %s" % (name, run.stderr))
    rows = table(run.stdout)
    if len(rows) < 3:
        sys.exit("%s: no table in the output:\n%s" % (name, run.stdout))
    least = min(rows, key=lambda r: r[2])
    if abs(least[0] / truth_deg - 1.0) > 0.0045:
        sys.exit("%s: least residual at %.5f deg, the log's spacing is %.5f deg\n%s" % (name, least[0], truth_deg, run.stdout))
    truth = [r for r in rows if abs(r[0] - truth_deg) < 6e-6]
    other = [r for r in rows if abs(r[0] - other_deg) < 6e-6]
    if not truth or not other:
        sys.exit("%s: the table lacks %.5f or %.5f deg\n%s" % (name, truth_deg, other_deg, run.stdout))
    # Differences are against the reader's row; their difference is the paired one.
    gap = other[0][3] - truth[0][3]
    se = max(other[0][4], truth[0][4])
    if not gap > 2.0 * se:
        sys.exit("%s: %.5f deg not clearly worse than %.5f deg (%+.3f mm, std error %.3f mm)\n%s"
                 % (name, other_deg, truth_deg, gap, se, run.stdout))
    print("%s: least at %.5f deg; %.5f deg is %.3f mm worse (std error %.3f)" % (name, least[0], other_deg, gap, se))


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    tool, work = argv[1], argv[2]
    os.makedirs(work, exist_ok=True)
    check(tool, work, "carmen_1deg", 1.0, 180.0 / (BEAMS - 1))
    check(tool, work, "even_180deg", 180.0 / (BEAMS - 1), 1.0)
    empty = os.path.join(work, "empty.clf")
    with open(empty, "w") as f:
        f.write("ODOM 0 0 0 0 0 0 1000.0 test 1000.0\n")
    run = subprocess.run([sys.executable, tool, empty], capture_output=True, text=True)
    if run.returncode == 0 or "empty.clf: no FLASER line" not in run.stderr:
        sys.exit("a log without FLASER lines: exit %d, stderr %r" % (run.returncode, run.stderr))
    print("a log without FLASER lines: refused")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
