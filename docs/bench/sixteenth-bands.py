#!/usr/bin/env python3
"""Issue 14, sixteenth session: where on the sheet a ladder's error lies.

Reads a `drape bench` SCENE-samples.csv (u, v in material coordinates, then
each run's error at that sample point, m: the RMS over the frames, or the last
frame's at rest) and prints, for bands of material distance from the sheet's
centre, the RMS over the points in the band of each named column.

Usage: sixteenth-bands.py SAMPLES.csv [COLUMN ...] (default: every column)
"""
import csv
import math
import sys

rows = list(csv.reader(open(sys.argv[1])))
head, data = rows[0], [list(map(float, r)) for r in rows[1:]]
cols = sys.argv[2:] or head[2:]
bands = [(0, 0.3), (0.3, 0.5), (0.5, 0.7), (0.7, 0.9), (0.9, 1.2), (0, 9)]
print("RMS error, m, over the sample points at material distance r (m) from the centre")
print(f"{'run':<46}" + "".join(f"{f'r {a}-{b}' if b < 9 else 'all':>11}" for a, b in bands))
print(f"{'(sample points)':<46}"
      + "".join(f"{sum(lo <= math.hypot(d[0], d[1]) < hi for d in data):>11}" for lo, hi in bands))
for c in cols:
    j = head.index(c)
    out = []
    for lo, hi in bands:
        sel = [d[j] for d in data if lo <= math.hypot(d[0], d[1]) < hi]
        out.append(math.sqrt(sum(x * x for x in sel) / len(sel)))
    print(f"{c:<46}" + "".join(f"{x:11.2e}" for x in out))
