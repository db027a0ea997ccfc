#!/usr/bin/env python3
"""Where a hanging sheet's error at rest is: shape against offset, and the
folds' amplitude row by row (docs/speed-vs-error-history.md, eleventh sitting).

Usage: fold-amplitude.py REFERENCE.json RUN.obj
  REFERENCE.json  a `drape bench` reference cache (bench-out/.../cache/*.json)
  RUN.obj         the run's last frame from `drape run --obj-dir`

The run's mesh is interpolated at the reference's sample points (material
coordinates, the OBJ's `vt`), as the bench does. Printed: the RMS error
relative to the diagonal; the offset (mean displacement) and what is left
without it (the shape error), per world axis; then per row of samples (every
second row, top to bottom) the folds' amplitude across the sheet, the RMS of
the out-of-plane coordinate y about the row's mean, in the reference and the
run. The sheet of scenes/hanging_sheet_rest.toml hangs in the xz plane, so y
is the out-of-plane direction. Python 3 standard library only.
"""
import collections
import json
import math
import sys


def load_obj(path):
    pos, tex, faces = [], [], []
    for line in open(path):
        p = line.split()
        if not p:
            continue
        if p[0] == "v":
            pos.append(tuple(map(float, p[1:4])))
        elif p[0] == "vt":
            tex.append((float(p[1]), float(p[2])))
        elif p[0] == "f":
            faces.append([tuple(int(i) - 1 for i in c.split("/")[:2]) for c in p[1:]])
    return pos, tex, faces


def locator(tex, faces, nb=32):
    lo_u, hi_u = min(t[0] for t in tex), max(t[0] for t in tex)
    lo_v, hi_v = min(t[1] for t in tex), max(t[1] for t in tex)

    def cell(u, v):
        i = int((u - lo_u) / (hi_u - lo_u) * nb)
        j = int((v - lo_v) / (hi_v - lo_v) * nb)
        return min(nb - 1, max(0, i)), min(nb - 1, max(0, j))

    buckets = collections.defaultdict(list)
    for f, face in enumerate(faces):
        ts = [tex[t] for _, t in face]
        a = cell(min(t[0] for t in ts), min(t[1] for t in ts))
        b = cell(max(t[0] for t in ts), max(t[1] for t in ts))
        for i in range(a[0], b[0] + 1):
            for j in range(a[1], b[1] + 1):
                buckets[(i, j)].append(f)
    return cell, buckets


def main():
    ref = json.load(open(sys.argv[1]))
    pos, tex, faces = load_obj(sys.argv[2])
    cell, buckets = locator(tex, faces)
    points, target = ref["points"], ref["frames"][-1]["positions"]

    def at(u, v):
        for f in buckets[cell(u, v)]:
            (pa, ta), (pb, tb), (pc, tc) = faces[f]
            a, b, c = tex[ta], tex[tb], tex[tc]
            d = (b[1] - c[1]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[1] - c[1])
            l1 = ((b[1] - c[1]) * (u - c[0]) + (c[0] - b[0]) * (v - c[1])) / d
            l2 = ((c[1] - a[1]) * (u - c[0]) + (a[0] - c[0]) * (v - c[1])) / d
            l3 = 1.0 - l1 - l2
            if min(l1, l2, l3) > -1e-9:
                return [l1 * pos[pa][k] + l2 * pos[pb][k] + l3 * pos[pc][k] for k in range(3)]
        raise SystemExit(f"sample ({u}, {v}) is not in the run's mesh")

    run = [at(u, v) for u, v in points]
    n, diag = len(points), ref["diagonal"]
    disp = [[r[k] - q[k] for k in range(3)] for r, q in zip(run, target)]
    mean = [sum(d[k] for d in disp) / n for k in range(3)]
    shape = [[d[k] - mean[k] for k in range(3)] for d in disp]
    rms = lambda ds: math.sqrt(sum(sum(x * x for x in d) for d in ds) / n)
    print(f"error {100 * rms(disp) / diag:.4f} % of the diagonal, offset "
          f"{100 * math.hypot(*mean) / diag:.4f} %, shape {100 * rms(shape) / diag:.4f} %")
    axes = ", ".join(f"{a} {1000 * math.sqrt(sum(d[k] ** 2 for d in shape) / n):.2f}"
                     for k, a in enumerate("xyz"))
    print(f"shape error per axis, RMS mm: {axes}")
    us = sorted({p[0] for p in points})
    vs = sorted({p[1] for p in points})
    index = {(p[0], p[1]): i for i, p in enumerate(points)}

    def amplitude(ys):
        m = sum(ys) / len(ys)
        return 1000 * math.sqrt(sum((y - m) ** 2 for y in ys) / len(ys))

    print("v (m)   fold amplitude, mm: reference  run")
    for v in reversed(vs[::2]):
        row = [index[(u, v)] for u in us]
        a_ref = amplitude([target[i][1] for i in row])
        a_run = amplitude([run[i][1] for i in row])
        print(f"{v:6.3f}   {a_ref:6.2f}  {a_run:6.2f}")


if __name__ == "__main__":
    main()
