#!/usr/bin/env python3
"""Cuts a CARMEN log into another recording of the same run.

    cut_log.py LOG FIRST LAST OUT [--rebase]

Writes the log's laser scans FIRST..LAST (1-based; FLASER or ROBOTLASER1 lines) with the
ODOM lines from the one after scan FIRST - 1 on. With --rebase the piece is made to look
like a recording of its own, as after the robot was switched off and on: its odometry
re-zeroed at its first line (every pose turned into that line's frame) and its clock
started again at 100 s. Used by tools/bench/extend.sh and tests/cli/extend_session.sh.
"""
import math
import sys


def pose_fields(f):
    """Indices of the x of each pose in a line: ODOM x y theta; FLASER ... x y theta
    odom_x odom_y odom_theta ts host logger_ts; ROBOTLASER1 ... laser x y theta, robot
    x y theta, five more fields, ts host logger_ts."""
    if f[0] == "ODOM":
        return [1]
    if f[0] == "FLASER":
        return [len(f) - 9, len(f) - 6]
    return [len(f) - 14, len(f) - 11]


def main(argv):
    if len(argv) not in (5, 6) or (len(argv) == 6 and argv[5] != "--rebase"):
        sys.exit(__doc__)
    log, first, last, out = argv[1], int(argv[2]), int(argv[3]), argv[4]
    rebase = len(argv) == 6
    kept, scan = [], 0
    with open(log) as src:
        for line in src:
            f = line.split()
            if not f or f[0] not in ("ODOM", "FLASER", "ROBOTLASER1"):
                continue
            if f[0] != "ODOM":
                scan += 1
                if scan > last:
                    break
                if scan >= first:
                    kept.append(f)
            elif scan >= first - 1:
                kept.append(f)
    origin = None
    with open(out, "w") as dst:
        for f in kept:
            if rebase:
                if origin is None:
                    i = pose_fields(f)[-1]
                    origin = [float(v) for v in f[i:i + 3]] + [float(f[-3]), float(f[-1])]
                ox, oy, oth, t0, l0 = origin
                c, s = math.cos(oth), math.sin(oth)
                for i in pose_fields(f):
                    x, y, th = (float(v) for v in f[i:i + 3])
                    dx, dy = x - ox, y - oy
                    f[i:i + 3] = ["%.9f" % (c * dx + s * dy), "%.9f" % (-s * dx + c * dy),
                                  "%.9f" % math.atan2(math.sin(th - oth), math.cos(th - oth))]
                f[-3] = "%.6f" % (float(f[-3]) - t0 + 100.0)
                f[-1] = "%.6f" % (float(f[-1]) - l0 + 100.0)
            dst.write(" ".join(f) + "\n")


if __name__ == "__main__":
    main(sys.argv)
