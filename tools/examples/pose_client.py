#!/usr/bin/env python3
"""Reads sdpslamd's live pose ([output] pose_socket) and prints one JSON line per pose.

    pose_client.py SOCKET [--count N] [--idle-s S]

The client binds a datagram socket of its own (in Linux's abstract namespace, so no file
is left behind), sends "SUBSCRIBE" to sdpslamd's socket, and prints each 64-byte record
(firmware-host/include/sdpslam/daemon/pose_publisher.h) as
    {"seq": 12, "processed": true, "localize": false, "map_version": 3,
     "stamp_us": 123456789, "x_m": 1.5, "y_m": -2.0, "heading_rad": 0.7,
     "cov": [var_x, cov_xy, var_y, var_heading]}
It subscribes again whenever a second passes without a record (sdpslamd not started yet,
or restarted), reports gaps in the sequence on stderr (records the daemon dropped for
a client that read too slowly), and ends after N records (--count) or S seconds without
one (--idle-s, default: never), saying UNSUBSCRIBE.
"""
import argparse
import json
import os
import socket
import struct
import sys
import time

RECORD = struct.Struct("<4sHHIIq3d4f")  # 64 bytes, little-endian, no padding


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("socket", help="sdpslamd's [output] pose_socket")
    ap.add_argument("--count", type=int, default=0, help="stop after this many records (0: never)")
    ap.add_argument("--idle-s", type=float, default=0.0, help="stop after this long without a record (0: never)")
    a = ap.parse_args()
    s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    s.bind("\0sdpslam-pose-client-%d" % os.getpid())
    s.settimeout(1.0)
    got, last_seq, last_record = 0, None, time.monotonic()
    try:
        while a.count == 0 or got < a.count:
            try:
                data = s.recv(128)
            except socket.timeout:
                if a.idle_s > 0 and time.monotonic() - last_record > a.idle_s:
                    break
                try:
                    s.sendto(b"SUBSCRIBE", a.socket)
                except OSError:
                    pass  # not there yet
                continue
            if len(data) != RECORD.size:
                continue
            magic, version, flags, seq, map_version, stamp_us, x, y, h, vxx, vxy, vyy, vhh = RECORD.unpack(data)
            if magic != b"SDPP" or version != 1:
                continue
            if last_seq is not None and seq != last_seq + 1:
                print("pose_client: %d records missed before %d" % (seq - last_seq - 1, seq), file=sys.stderr)
            last_seq, last_record = seq, time.monotonic()
            got += 1
            print(json.dumps({"seq": seq, "processed": bool(flags & 1), "localize": bool(flags & 2),
                              "map_version": map_version, "stamp_us": stamp_us, "x_m": x, "y_m": y,
                              "heading_rad": h, "cov": [vxx, vxy, vyy, vhh]}), flush=True)
    except KeyboardInterrupt:
        pass
    finally:
        try:
            s.sendto(b"UNSUBSCRIBE", a.socket)
        except OSError:
            pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
