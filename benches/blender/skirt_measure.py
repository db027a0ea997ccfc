"""Seam gaps and penetration of a skirt's OBJ frames, the same way for drape and Blender.

    python3 benches/blender/skirt_measure.py --body BODY.obj --frames DIR \
        [--fps 30] [--weld-gap 0.005] [--rest-speed 0.05 --rest-window 0.5] [--out FILE.json]
    python3 benches/blender/skirt_measure.py --no-body --frames DIR ...

DIR holds one OBJ per frame (`frame_00000.obj`, `frame_00001.obj`, ... in
name order, frame 0 the start): drape's `--obj-dir` output, or what skirt.py
writes for Blender. Per frame it measures

- the seam gap: the largest distance between the two vertices of any `l`
  pair (a sewing pair). drape writes `l` pairs for open seams only, so a
  frame without any is one whose seams are welded (gap 0 by construction);
  Blender's seams never weld and every frame has all pairs;
- the penetration: how deep any cloth vertex lies inside the body. The body
  OBJ (drape's skinned mannequin, `drape body-frames`) is a union of convex
  parts (boxes, capsules, a sphere, tessellated; where two parts overlap the
  surface of one runs inside the other), so each connected component is a
  convex polyhedron: a point is inside it when it is behind every face plane,
  and its depth is its distance to the nearest face plane (exact for a convex
  polyhedron). The depth into the body is the largest over the components
  that hold the point (a lower bound where parts overlap).

The seams are closed at the first frame whose every pair is within
`--weld-gap` (drape's weld_gap, 5 mm). Per frame it also takes the largest
vertex move since the previous frame (where both have the same vertices:
not across drape's welds), and the frame at rest by drape's criterion
(`simulation.rest`): the first frame with the seams closed since the frame
`--rest-window` s before it and every move over that window under
`--rest-speed` / fps. `--no-body` skips the penetration (for a body that is
not a union of convex parts, such as a scanned one: garment-check.py
measures that). Pure Python (no numpy), so that
Blender's bundled interpreter can import the OBJ reader too.
"""

import argparse
import json
import math
import os
import sys


def read_obj(path):
    """Positions, faces (0-based vertex indices), `vt` per face corner, the
    `l` pairs (0-based, in file order), the `g` group of each face and the
    `# seam NAME` comment that precedes each pair."""
    v, vt, faces, face_vt, face_group, pairs, pair_seam = [], [], [], [], [], [], []
    group = None
    seam = None
    with open(path) as fh:
        for line in fh:
            if line.startswith("v "):
                _, x, y, z = line.split()[:4]
                v.append((float(x), float(y), float(z)))
            elif line.startswith("vt "):
                parts = line.split()
                vt.append((float(parts[1]), float(parts[2])))
            elif line.startswith("f "):
                idx, tex = [], []
                for tok in line.split()[1:]:
                    fields = tok.split("/")
                    idx.append(int(fields[0]) - 1)
                    tex.append(int(fields[1]) - 1 if len(fields) > 1 and fields[1] else None)
                faces.append(idx)
                face_vt.append(tex)
                face_group.append(group)
            elif line.startswith("l "):
                idx = [int(tok.split("/")[0]) - 1 for tok in line.split()[1:]]
                # an `l` element sews its consecutive vertices: a b -> one pair
                for a, b in zip(idx[:-1], idx[1:]):
                    pairs.append((a, b))
                    pair_seam.append(seam)
            elif line.startswith("g ") or line.startswith("o "):
                group = line.split(None, 1)[1].strip()
            elif line.startswith("# seam "):
                seam = line[len("# seam "):].strip()
    return {"v": v, "vt": vt, "faces": faces, "face_vt": face_vt, "face_group": face_group,
            "pairs": pairs, "pair_seam": pair_seam}


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


NEAR = 0.02  # m: distances beyond this are reported as this


def _point_triangle(p, a, b, c):
    """Distance from p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5)."""
    ab, ac, ap = _sub(b, a), _sub(c, a), _sub(p, a)
    d1, d2 = _dot(ab, ap), _dot(ac, ap)
    if d1 <= 0.0 and d2 <= 0.0:
        return math.dist(p, a)
    bp = _sub(p, b)
    d3, d4 = _dot(ab, bp), _dot(ac, bp)
    if d3 >= 0.0 and d4 <= d3:
        return math.dist(p, b)
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        t = d1 / (d1 - d3)
        return math.dist(p, (a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]))
    cp = _sub(p, c)
    d5, d6 = _dot(ab, cp), _dot(ac, cp)
    if d6 >= 0.0 and d5 <= d6:
        return math.dist(p, c)
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        t = d2 / (d2 - d6)
        return math.dist(p, (a[0] + t * ac[0], a[1] + t * ac[1], a[2] + t * ac[2]))
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        t = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return math.dist(p, (b[0] + t * (c[0] - b[0]), b[1] + t * (c[1] - b[1]), b[2] + t * (c[2] - b[2])))
    den = 1.0 / (va + vb + vc)
    v, w = vb * den, vc * den
    q = (a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w, a[2] + ab[2] * v + ac[2] * w)
    return math.dist(p, q)


class Body:
    """The body OBJ as convex parts: per connected component its face planes
    (outward unit normal n, offset d: n.x = d on the face) and its box."""

    def __init__(self, path):
        obj = read_obj(path)
        v, faces = obj["v"], obj["faces"]
        parent = list(range(len(v)))

        def find(i):
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        for f in faces:
            for k in f[1:]:
                ra, rb = find(f[0]), find(k)
                if ra != rb:
                    parent[rb] = ra
        comp_faces = {}
        for f in faces:
            comp_faces.setdefault(find(f[0]), []).append(f)
        self.parts = []
        for root, fs in comp_faces.items():
            verts = sorted({i for f in fs for i in f})
            c = tuple(sum(v[i][k] for i in verts) / len(verts) for k in range(3))
            planes = {}
            for f in fs:
                n = _cross(_sub(v[f[1]], v[f[0]]), _sub(v[f[2]], v[f[0]]))
                ln = math.sqrt(_dot(n, n))
                if ln < 1e-15:
                    continue
                n = (n[0] / ln, n[1] / ln, n[2] / ln)
                d = _dot(n, v[f[0]])
                if _dot(n, c) > d:  # the centroid must lie behind the plane
                    n, d = (-n[0], -n[1], -n[2]), -d
                key = (round(n[0], 9), round(n[1], 9), round(n[2], 9), round(d, 9))
                planes[key] = (n, d)
            lo = tuple(min(v[i][k] for i in verts) for k in range(3))
            hi = tuple(max(v[i][k] for i in verts) for k in range(3))
            tris = [tuple(v[i] for i in f[k:k + 2] + f[:1]) for f in fs for k in range(1, len(f) - 1)]
            self.parts.append({"planes": list(planes.values()), "lo": lo, "hi": hi,
                               "tris": tris, "vertices": len(verts), "faces": len(fs)})
        self.vertex_count = len(v)
        self.face_count = len(faces)

    def signed_distance(self, p, reach=NEAR):
        """Signed distance of p to the body's surface, m: minus the depth inside
        (the largest over the parts that hold p), else the distance to the
        nearest part (exact, point to triangle), or `reach` when every part is
        farther than that."""
        depth = 0.0
        outside = reach
        for part in self.parts:
            lo, hi = part["lo"], part["hi"]
            if not (lo[0] - reach <= p[0] <= hi[0] + reach and lo[1] - reach <= p[1] <= hi[1] + reach
                    and lo[2] - reach <= p[2] <= hi[2] + reach):
                continue
            worst = -math.inf  # the largest signed plane distance: < 0 inside
            for n, d in part["planes"]:
                s = n[0] * p[0] + n[1] * p[1] + n[2] * p[2] - d
                if s > worst:
                    worst = s
            if worst < 0.0:
                depth = max(depth, -worst)
            elif depth == 0.0 and worst < outside:
                # a lower bound of the distance; the exact one when it is near
                outside = min(outside, min(_point_triangle(p, *t) for t in part["tris"]))
        return -depth if depth > 0.0 else outside

    def depth(self, p):
        """How deep p lies inside the body, m (0 outside)."""
        return max(0.0, -self.signed_distance(p, reach=0.0))


def measure_frame(body, obj, contact):
    v = obj["v"]
    gaps = [math.dist(v[a], v[b]) for a, b in obj["pairs"]]
    by_seam = {}
    for (a, b), seam, g in zip(obj["pairs"], obj["pair_seam"], gaps):
        by_seam[seam or "?"] = max(by_seam.get(seam or "?", 0.0), g)
    m = {"vertices": len(v), "pairs": len(gaps), "gap_max": max(gaps) if gaps else None,
         "gap_by_seam": by_seam, "lowest_z": min(p[2] for p in v)}
    if body is None:
        return m
    signed = [body.signed_distance(p) for p in v]
    depths = [max(0.0, -s) for s in signed]
    inside = [d for d in depths if d > 0.0]
    return {
        "clearance_min": min(signed),
        "vertices_within_contact": sum(1 for s in signed if s < contact),
        "vertices": len(v),
        "pairs": len(gaps),
        "gap_max": max(gaps) if gaps else None,
        "gap_by_seam": by_seam,
        "penetration_max": max(depths) if depths else 0.0,
        "vertices_inside": len(inside),
        "lowest_z": min(p[2] for p in v),
    }


def measure(body_path, frames_dir, fps, weld_gap, contact, rest_speed=0.05, rest_window=0.5):
    body = Body(body_path) if body_path else None
    names = sorted(f for f in os.listdir(frames_dir) if f.endswith(".obj"))
    frames = []
    prev = None
    for k, name in enumerate(names):
        obj = read_obj(os.path.join(frames_dir, name))
        m = measure_frame(body, obj, contact)
        m["frame"] = k
        m["time_s"] = k / fps
        m["move_max"] = (max(math.dist(p, q) for p, q in zip(obj["v"], prev))
                         if prev is not None and len(prev) == len(obj["v"]) else None)
        prev = obj["v"]
        frames.append(m)

    def closed(m):
        return m["gap_max"] is None or m["gap_max"] < weld_gap

    window = int(round(rest_window * fps))
    still = rest_speed / fps
    rest = next((m for m in frames[window:] if all(
        closed(w) and w["move_max"] is not None and w["move_max"] < still
        for w in frames[m["frame"] - window + 1:m["frame"] + 1]) and closed(frames[m["frame"] - window])),
        None)
    rest_keys = {
        "rest_speed_m_s": rest_speed,
        "rest_window_s": rest_window,
        "rest_frame": rest["frame"] if rest else None,
        "rest_s": rest["time_s"] if rest else None,
        "final_move_max_m": frames[-1]["move_max"] if frames else None,
    }

    first_closed = next((m for m in frames if closed(m)), None)
    reopened = None
    if first_closed is not None:
        reopened = next((m["frame"] for m in frames[first_closed["frame"]:] if not closed(m)), None)
    gaps_after = [m["gap_max"] for m in frames[first_closed["frame"]:]] if first_closed else []
    gaps_after = [g for g in gaps_after if g is not None]
    out = {
        "body": None if body is None else {
            "path": body_path, "vertices": body.vertex_count, "triangles": body.face_count,
            "convex_parts": len(body.parts)},
        "frames_dir": frames_dir,
        "frames": len(frames),
        "fps": fps,
        "weld_gap_m": weld_gap,
        "initial_gap_max_m": frames[0]["gap_max"] if frames else None,
        "seams_closed_frame": first_closed["frame"] if first_closed else None,
        "seams_closed_s": first_closed["time_s"] if first_closed else None,
        "seams_reopened_frame": reopened,
        "gap_max_after_closing_m": max(gaps_after) if gaps_after else (0.0 if first_closed else None),
        "final_gap_max_m": frames[-1]["gap_max"] if frames else None,
        "final_lowest_z": frames[-1]["lowest_z"] if frames else None,
        **rest_keys,
    }
    if body is not None:
        pen = [m["penetration_max"] for m in frames]
        out.update({
            "penetration_final_m": pen[-1] if pen else None,
            "penetration_max_m": max(pen) if pen else None,
            "penetration_max_frame": pen.index(max(pen)) if pen else None,
            "vertices_inside_final": frames[-1]["vertices_inside"] if frames else None,
            "vertices_inside_max": max(m["vertices_inside"] for m in frames) if frames else None,
            "contact_distance_m": contact,
            "clearance_min_final_m": frames[-1]["clearance_min"] if frames else None,
            "clearance_min_m": min(m["clearance_min"] for m in frames) if frames else None,
            "vertices_within_contact_final": frames[-1]["vertices_within_contact"] if frames else None,
        })
    out["per_frame"] = frames
    return out


def main(argv):
    p = argparse.ArgumentParser(prog="skirt_measure.py")
    p.add_argument("--body", default=None, help="the body OBJ both simulators collided with")
    p.add_argument("--no-body", action="store_true", help="no penetration (no --body)")
    p.add_argument("--frames", required=True, help="directory of per-frame OBJ files")
    p.add_argument("--fps", type=float, default=30.0)
    p.add_argument("--weld-gap", type=float, default=0.005, help="m (drape's cloth.sewing.weld_gap)")
    p.add_argument("--contact", type=float, default=0.004,
                   help="m: count vertices closer than this to the body (drape's obstacle thickness)")
    p.add_argument("--rest-speed", type=float, default=0.05, help="m/s (drape's simulation.rest)")
    p.add_argument("--rest-window", type=float, default=0.5, help="s (drape's simulation.rest)")
    p.add_argument("--label", default=None)
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    if (args.body is None) != args.no_body:
        p.error("give --body BODY.obj or --no-body")
    r = measure(args.body, args.frames, args.fps, args.weld_gap, args.contact,
                args.rest_speed, args.rest_window)
    r["label"] = args.label
    text = json.dumps(r, indent=1)
    if args.out:
        with open(args.out, "w") as fh:
            fh.write(text + "\n")
    short = {k: r[k] for k in ("label", "frames", "initial_gap_max_m", "seams_closed_frame",
                               "rest_frame", "rest_s", "final_move_max_m",
                               "seams_closed_s", "seams_reopened_frame", "gap_max_after_closing_m",
                               "final_gap_max_m", "penetration_final_m", "penetration_max_m",
                               "penetration_max_frame", "vertices_inside_final",
                               "vertices_inside_max", "final_lowest_z", "clearance_min_final_m",
                               "clearance_min_m", "vertices_within_contact_final") if k in r}
    print(json.dumps(short))


if __name__ == "__main__":
    main(sys.argv[1:])
