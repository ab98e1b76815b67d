#!/usr/bin/env python3
"""Writes a large gyro log as a TDMS file of small integers, for memory figures (docs/formats.md, "TDMS").

Channels time_s (int32, whole seconds 0, 1, 2, ...) and g1..gN (int8, a repeating ramp), in one segment or
in segments of --segment-rows rows, from NI's published layout with the struct module alone (as
make_tdms.py). 8 bytes a row with 4 gyros: 7,500,000 rows make a 60 MB file.

    make_int8_tdms.py OUT.tdms ROWS [--gyros N] [--segment-rows N]
"""
import argparse
import array
import struct
import sys

TOC_META, TOC_NEW_LIST, TOC_RAW = 1 << 1, 1 << 2, 1 << 3
T_I8, T_I32 = 1, 3
NO_DATA = 0xFFFFFFFF


def text(s):
    b = s.encode("utf-8")
    return struct.pack("<I", len(b)) + b


def segment(toc, meta, raw):
    toc |= TOC_RAW | (TOC_META if meta else 0)
    lead = b"TDSm" + struct.pack("<IIQQ", toc, 4713, len(meta) + len(raw), len(meta))
    return lead + meta + raw


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("rows", type=int)
    ap.add_argument("--gyros", type=int, default=4)
    ap.add_argument("--segment-rows", type=int, default=0)
    a = ap.parse_args()
    per = a.segment_rows if a.segment_rows > 0 else a.rows
    ramp = array.array("b", [(i % 200) - 100 for i in range(200)]).tobytes()
    names = ["time_s"] + ["g%d" % i for i in range(1, a.gyros + 1)]

    def metadata(count):
        objs = [text("/") + struct.pack("<I", NO_DATA) + struct.pack("<I", 1) + text("units") +
                struct.pack("<I", 0x20) + text("V")]
        for name in names:
            t = T_I32 if name == "time_s" else T_I8
            objs.append(text("/'Log'/'%s'" % name) + struct.pack("<IIIQI", 20, t, 1, count, 0))
        return struct.pack("<I", len(objs)) + b"".join(objs)

    with open(a.out, "wb") as f:
        first = 0
        while first < a.rows:
            n = min(per, a.rows - first)
            raw = array.array("i", range(first, first + n)).tobytes()
            gyro = (ramp * (n // len(ramp) + 1))[:n]
            raw += gyro * a.gyros
            meta = metadata(n) if first == 0 or n != per else b""
            f.write(segment(TOC_NEW_LIST if first == 0 else 0, meta, raw))
            first += n
    return 0


if __name__ == "__main__":
    sys.exit(main())
