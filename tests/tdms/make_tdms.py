#!/usr/bin/env python3
"""Writes a CSV log (gyro log or turntable log) as a TDMS 2.0 file, an independent route to test data.

Written from NI's published description of the TDMS file format with nothing but the struct module: each
segment is a 28-byte lead-in ("TDSm", ToC mask, version 4713, next segment offset, raw data offset), then
metadata (objects: path, raw data index, properties), then raw data. Columns become channels of one group
(named as the columns, or renamed with --rename COLUMN=CHANNEL), "# key=value" comment lines become file
properties (numbers as doubles, other values as text).

The file is cut into segments that exercise the format: full metadata, a segment without metadata (the
previous one's reused, two chunks), incremental metadata ("same index as before" and a new property), a
metadata-only segment, and a last segment whose index changes the value count. --layout interleaved
writes interleaved raw data, --big-endian big-endian segments, --index the optional .tdms_index beside it.

--segment-rows N writes a LabVIEW-style stream instead: the metadata once, then one segment of N rows
after another, each without metadata (a logger writing as it goes).

    make_tdms.py IN.csv OUT.tdms [--layout contiguous|interleaved] [--big-endian] [--one-segment]
                 [--segment-rows N] [--index] [--int32 COLUMN ...] [--float32 COLUMN ...] [--rename COLUMN=CHANNEL ...]
                 [--group NAME] [--rename-property KEY=NAME ...]
"""
import argparse
import struct
import sys

TOC_META, TOC_NEW_LIST, TOC_RAW, TOC_INTERLEAVED, TOC_BIG = 1 << 1, 1 << 2, 1 << 3, 1 << 5, 1 << 6
T_I32, T_F32, T_F64, T_STRING = 3, 9, 10, 0x20
FORMATS = {T_I32: "i", T_F32: "f", T_F64: "d"}
NO_DATA, SAME_INDEX = 0xFFFFFFFF, 0


def read_csv(path):
    props, columns, rows = [], None, []
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.rstrip("\n")
            if line.startswith("#"):
                body = line[1:].strip()
                if "=" in body and " " not in body.split("=", 1)[0]:
                    key, value = body.split("=", 1)
                    props.append((key.strip(), value.strip()))
                continue
            if columns is None:
                columns = [c.strip() for c in line.split(",")]
                continue
            if line.strip():
                rows.append([float(c) for c in line.split(",")])
    return props, columns, rows


class Writer:
    def __init__(self, big):
        self.e = ">" if big else "<"

    def u32(self, v):
        return struct.pack(self.e + "I", v)

    def u64(self, v):
        return struct.pack(self.e + "Q", v)

    def text(self, s):
        b = s.encode("utf-8")
        return self.u32(len(b)) + b

    def prop(self, name, value):
        try:
            number = float(value)
            return self.text(name) + self.u32(T_F64) + struct.pack(self.e + "d", number)
        except ValueError:
            return self.text(name) + self.u32(T_STRING) + self.text(value)

    def props(self, items):
        return self.u32(len(items)) + b"".join(self.prop(k, v) for k, v in items)


def path_of(group, channel=None):
    quote = lambda s: "'" + s.replace("'", "''") + "'"
    return "/" + quote(group) + ("" if channel is None else "/" + quote(channel))


def segment(w, toc, objects, raw):
    """objects: list of bytes (each an object entry) or None for no metadata."""
    meta = b"" if objects is None else w.u32(len(objects)) + b"".join(objects)
    if objects is not None:
        toc |= TOC_META
    if raw:
        toc |= TOC_RAW
    if w.e == ">":
        toc |= TOC_BIG  # the ToC mask itself is always little-endian; the rest of the segment big-endian
    lead = b"TDSm" + struct.pack("<I", toc) + w.u32(4713) + w.u64(len(meta) + len(raw)) + w.u64(len(meta))
    return lead, meta, raw


def raw_data(w, types, rows, interleaved):
    out = []
    if interleaved:
        for row in rows:
            for t, v in zip(types, row):
                out.append(struct.pack(w.e + FORMATS[t], int(v) if t == T_I32 else v))
    else:
        for c, t in enumerate(types):
            fmt = w.e + str(len(rows)) + FORMATS[t]
            values = [int(r[c]) if t == T_I32 else r[c] for r in rows]
            out.append(struct.pack(fmt, *values))
    return b"".join(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("out")
    ap.add_argument("--layout", choices=["contiguous", "interleaved"], default="contiguous")
    ap.add_argument("--big-endian", action="store_true")
    ap.add_argument("--one-segment", action="store_true")
    ap.add_argument("--segment-rows", type=int, default=0)
    ap.add_argument("--index", action="store_true")
    ap.add_argument("--int32", nargs="*", default=[])
    ap.add_argument("--float32", nargs="*", default=[])
    ap.add_argument("--rename", nargs="*", default=[])
    ap.add_argument("--rename-property", nargs="*", default=[])
    ap.add_argument("--group", default="Log")
    a = ap.parse_args()

    props, columns, rows = read_csv(a.csv)
    renames = dict(r.split("=", 1) for r in a.rename)
    prop_renames = dict(r.split("=", 1) for r in a.rename_property)
    props = [(prop_renames.get(k, k), v) for k, v in props]
    names = [renames.get(c, c) for c in columns]
    types = [T_I32 if c in a.int32 else T_F32 if c in a.float32 else T_F64 for c in columns]
    w = Writer(a.big_endian)
    inter = TOC_INTERLEAVED if a.layout == "interleaved" else 0

    def full_index(t, count):
        return w.u32(20) + w.u32(t) + w.u32(1) + w.u64(count)

    def channel(name, marker_or_index, properties=()):
        return w.text(path_of(a.group, name)) + marker_or_index + w.props(list(properties))

    n = len(rows)
    segs = []
    file_obj = w.text("/") + w.u32(NO_DATA) + w.props(props)
    group_obj = w.text(path_of(a.group)) + w.u32(NO_DATA) + w.props([("description", "written by make_tdms.py")])
    if a.segment_rows > 0:
        k = min(a.segment_rows, n)
        objs = [file_obj, group_obj] + [channel(nm, full_index(t, k)) for nm, t in zip(names, types)]
        segs.append(segment(w, TOC_NEW_LIST | inter, objs, raw_data(w, types, rows[:k], inter)))
        for first in range(k, n - n % k, k):
            segs.append(segment(w, inter, None, raw_data(w, types, rows[first:first + k], inter)))
        if n % k:
            objs = [channel(nm, full_index(t, n % k)) for nm, t in zip(names, types)]
            segs.append(segment(w, inter, objs, raw_data(w, types, rows[n - n % k:], inter)))
    elif a.one_segment or n < 5:
        objs = [file_obj, group_obj] + [channel(nm, full_index(t, n)) for nm, t in zip(names, types)]
        segs.append(segment(w, TOC_NEW_LIST | inter, objs, raw_data(w, types, rows, inter)))
    else:
        c = n // 5
        chunk = lambda first, count: raw_data(w, types, rows[first:first + count], inter)
        # 1: full metadata, one chunk of c rows
        objs = [file_obj, group_obj] + [
            channel(nm, full_index(t, c), [("unit_string", "V")]) for nm, t in zip(names, types)]
        segs.append(segment(w, TOC_NEW_LIST | inter, objs, chunk(0, c)))
        # 2: no metadata (the previous segment's), two chunks
        segs.append(segment(w, inter, None, chunk(c, c) + chunk(2 * c, c)))
        # 3: metadata only: a file property added
        segs.append(segment(w, inter, [w.text("/") + w.u32(NO_DATA) + w.props([("segments", "5")])], b""))
        # 4: incremental metadata: every channel "same index as before", one chunk
        objs = [channel(nm, w.u32(SAME_INDEX)) for nm in names]
        segs.append(segment(w, inter, objs, chunk(3 * c, c)))
        # 5: incremental metadata: a new value count for every channel, the rest of the rows
        rest = n - 4 * c
        objs = [channel(nm, full_index(t, rest)) for nm, t in zip(names, types)]
        segs.append(segment(w, inter, objs, chunk(4 * c, rest)))
    with open(a.out, "wb") as f:
        for lead, meta, raw in segs:
            f.write(lead + meta + raw)
    if a.index:
        with open(a.out + "_index", "wb") as f:
            for lead, meta, _raw in segs:
                f.write(b"TDSh" + lead[4:] + meta)
    return 0


if __name__ == "__main__":
    sys.exit(main())
