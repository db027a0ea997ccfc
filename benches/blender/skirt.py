"""Blender peer benchmark of drape's skirt sewn onto the mannequin at rest.

Run (Blender 3.4, Debian's `blender` package), after skirt.sh has written the
inputs (or by hand, see README.md):

    blender -b --factory-startup --python benches/blender/skirt.py -- \
        --skirt benches/blender/skirt/skirt.obj --body benches/blender/skirt/body.obj \
        [--quality 7] [--fps 30] [--duration 2] [--sewing-force-max F] \
        [--frames-dir DIR] [--out FILE.json]

Builds the scene from scratch (no .blend) from the same two OBJ files that
benches/blender/skirt_rest.toml gives drape: the unsewn skirt (two panels,
their pattern coordinates as `vt`, the side seams as `l` pairs, which become
Blender's sewing edges: loose edges with `use_sewing_springs`) and the
mannequin at rest as a Collision object. Pins the same waistband vertices,
converts drape's material to Blender's units, times the `frame_set` loop
(common.py's, as drape_sphere.py) and writes a JSON summary; with --frames-dir
it also writes every frame (read back from the point cache after the timed
loop, common.py's read-back) as an OBJ with the sewing pairs as `l` lines,
for skirt_measure.py.
README.md beside this file maps every setting and says where the models
differ.
"""

import argparse
import json
import math
import os
import platform
import statistics
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402  (the scene set-up, timed loop and read-back drape_sphere.py uses)
from skirt_measure import read_obj  # noqa: E402  (the OBJ reader skirt_measure.py uses)

# ------------------------------------------------- drape's scene, skirt_rest.toml
# Keep in sync with skirt_rest.toml. --params FILE.json replaces any of them
# (garmentcode.sh writes one from its scene): the same keys in lower case,
# `pin_box` and `self_thickness` null for none.
SKIRT = {
    "gravity": -9.81,  # m/s^2
    "density": 0.2,  # kg/m^2
    "stretch": 300.0,  # N/m
    "bending": 2.0e-5,  # N m
    "damping": 0.001,  # s, stiffness-proportional
    "drag": 0.1,  # kg/(m^2 s)
    "sewing_stiffness": 50.0,  # N/m per m of seam
    "weld_gap": 0.005,  # m
    "self_thickness": 0.003,  # m
    "body_thickness": 0.004,  # m
    "friction_kinetic": 0.4,
    "pin_box": [[-0.15, -0.02], [0.15, 0.0]],  # material (u, v), m, every panel
    "dt": 0.005,  # s, drape's step before it is rounded to fill a frame
    "duration": 2.0,  # s
}
P = dict(SKIRT)  # the scene simulated: SKIRT with --params applied (main)

# Blender's cloth solver clock: gravity enters as 0.001 g per solver time unit
# squared (cloth_calc_force), so one unit is T = sqrt(0.001) s when gravity is
# physical; time_scale = 1 / (fps T) makes a frame 1/fps s. Stiffnesses (N/m =
# kg/s^2) are multiplied by T^2, damping and drag coefficients (kg/s) by T,
# forces (N) by T^2. See README.md (drape_sphere's `--model matched`).
T = common.SOLVER_UNIT_S


def parse_args():
    p = argparse.ArgumentParser(prog="skirt.py")
    p.add_argument("--skirt", required=True, help="the unsewn skirt OBJ (skirt/skirt.obj)")
    p.add_argument("--body", required=True, help="the body OBJ (skirt/body.obj)")
    p.add_argument("--quality", type=int, default=None,
                   help="cloth steps per frame (default: drape's, ceil(1 / (fps dt)) = 7 at 30 fps)")
    p.add_argument("--collision-quality", type=int, default=2, help="Blender's default 2")
    p.add_argument("--fps", type=float, default=30.0)
    p.add_argument("--duration", type=float, default=None,
                   help="simulated seconds (default: the scene's, 2 for the skirt)")
    p.add_argument("--params", default=None,
                   help="JSON of drape's scene values that replace the skirt's (SKIRT's keys)")
    p.add_argument("--weightless", type=float, default=0.0,
                   help="gravity off for this many seconds from the start, then on (the cloth's "
                        "effector weight for gravity, keyed per frame); drape's weightless phase")
    p.add_argument("--sewing-force-max", type=float, default=None,
                   help="Blender's max sewing force in N (converted to solver units); default: "
                        "drape's largest initial pull of one sewn pair (stiffness x its share "
                        "of the seam x its gap in the OBJ); 0 = no cap (Blender's default)")
    p.add_argument("--frames-dir", default=None, help="write every frame here as an OBJ")
    common.add_out_option(p)
    return p.parse_args(common.script_argv())


def vertex_patterns(obj):
    """Each vertex's pattern coordinate (its `vt`) and panel (its `g`). In the
    unsewn OBJ every vertex has exactly one."""
    uv = [None] * len(obj["v"])
    panel = [None] * len(obj["v"])
    for f, tex, g in zip(obj["faces"], obj["face_vt"], obj["face_group"]):
        for i, t in zip(f, tex):
            if t is None:
                raise SystemExit("skirt OBJ: a face corner without vt")
            if uv[i] is not None and uv[i] != obj["vt"][t]:
                raise SystemExit(f"skirt OBJ: vertex {i + 1} has two pattern coordinates "
                                 "(a welded seam); give the unsewn frame 0")
            uv[i] = obj["vt"][t]
            panel[i] = g
    return uv, panel


def seam_pair_shares(obj):
    """Each sewn pair's share of its seam's length (drape: a pair's spring is
    stiffness x share): half the distance to each neighbour along the first
    side, in pattern coordinates."""
    uv, _ = vertex_patterns(obj)
    seams = {}
    for k, s in enumerate(obj["pair_seam"]):
        seams.setdefault(s, []).append(k)
    share = [0.0] * len(obj["pairs"])
    for s, ks in seams.items():
        a = [obj["pairs"][k][0] for k in ks]
        for j, k in enumerate(ks):
            left = math.dist(uv[a[j]], uv[a[j - 1]]) if j > 0 else 0.0
            right = math.dist(uv[a[j]], uv[a[j + 1]]) if j + 1 < len(ks) else 0.0
            share[k] = 0.5 * (left + right)
    return share


def main():
    args = parse_args()
    if args.params:
        with open(args.params) as fh:
            given = json.load(fh)
        unknown = sorted(set(given) - set(SKIRT))
        if unknown:
            raise SystemExit(f"--params: unknown keys {unknown}; known: {sorted(SKIRT)}")
        P.update(given)
    if args.duration is None:
        args.duration = P["duration"]
    fps = args.fps
    frames = int(round(args.duration * fps))
    quality = args.quality if args.quality is not None else math.ceil(1.0 / (fps * P["dt"]) - 1e-9)

    common.clear_scene()
    scene = common.set_up_scene(fps, frames, P["gravity"])

    # ------------------------------------------------------------------ body
    body_obj = read_obj(args.body)
    body_me = bpy.data.meshes.new("body")
    body_me.from_pydata(body_obj["v"], [], body_obj["faces"])
    body_me.validate()
    body_me.update()
    body = bpy.data.objects.new("body", body_me)
    scene.collection.objects.link(body)
    body.modifiers.new("Collision", "COLLISION")
    coll = body.collision
    # Contact distance = cloth distance_min + collider thickness_outer = drape's 4 mm.
    coll.thickness_outer = P["body_thickness"] - common.BLENDER_DISTANCE_MIN_FLOOR
    coll.cloth_friction = 100.0 * P["friction_kinetic"]  # Blender's one coefficient is this x 0.01

    # ----------------------------------------------------------------- skirt
    sk = read_obj(args.skirt)
    uv, panel = vertex_patterns(sk)
    pairs = sk["pairs"]
    n = len(sk["v"])
    me = bpy.data.meshes.new("skirt")
    # The sewing pairs are loose edges: with use_sewing_springs each becomes a
    # zero-length spring (cloth_build_springs).
    # A corner pair that two stitches share (the same two vertices) is one edge.
    me.from_pydata(sk["v"], sorted({tuple(sorted(p)) for p in pairs}), sk["faces"])
    me.validate()
    me.update()
    cloth = bpy.data.objects.new("skirt", me)
    scene.collection.objects.link(cloth)
    if len(me.vertices) != n:
        raise SystemExit("the skirt mesh changed its vertices on building")
    loose = [e for e in me.edges if e.is_loose]
    distinct = len({tuple(sorted(p)) for p in pairs})
    if len(loose) != distinct:
        raise SystemExit(f"{len(loose)} loose edges for {distinct} distinct sewing pairs")

    # Rest shape: the flat pattern (drape's material space): every rest length
    # and rest bending angle then comes from it, as in drape. Both panels' patterns
    # overlap in (u, v), so each panel's lies in its own plane, 1 m apart, which only
    # the (zero-length) sewing springs see.
    cloth.shape_key_add(name="Basis", from_mix=False)
    flat = cloth.shape_key_add(name="pattern", from_mix=False)
    panels = sorted({p for p in panel if p is not None})
    offset = {p: float(k) for k, p in enumerate(panels)}
    for i, (u, v) in enumerate(uv):
        flat.data[i].co = (u, v, offset[panel[i]])
    flat.value = 0.0

    # Pins: the vertices inside drape's pin box in pattern coordinates.
    pinned = []
    if P["pin_box"] is not None:
        (u0, v0), (u1, v1) = P["pin_box"]
        eps = 1e-9
        pinned = [i for i, (u, v) in enumerate(uv)
                  if u0 - eps <= u <= u1 + eps and v0 - eps <= v <= v1 + eps]
        group = cloth.vertex_groups.new(name="pin")
        group.add(pinned, 1.0, "REPLACE")

    # --------------------------------------------- drape's material, converted
    faces = sk["faces"]
    area = 0.0
    edges = set()
    for f in faces:
        a, b, c = (uv[i] for i in f)
        area += 0.5 * abs((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))
        for x, y in ((f[0], f[1]), (f[1], f[2]), (f[2], f[0])):
            edges.add((min(x, y), max(x, y)))
    rest_len = [math.dist(uv[x], uv[y]) for x, y in edges]
    avg_len = sum(rest_len) / len(rest_len)  # Blender's avg_spring_len (structural springs)
    sum_l2 = sum(l * l for l in rest_len)
    # drape: k_e = stretch * sum(A_t) / L_e^2 per edge (its `consistent` rule).
    # Blender: one k for every spring, = tension_stiffness / avg_spring_len. The
    # uniform k with the same energy under a uniform biaxial stretch as drape's
    # springs: k sum(L^2) = sum(k_e L_e^2) = stretch * 3 * area.
    k_uniform = P["stretch"] * 3.0 * area / sum_l2  # N/m
    total_mass = P["density"] * area
    mass_per_vertex = total_mass / n

    mod = cloth.modifiers.new("Cloth", "CLOTH")
    s = mod.settings
    c = mod.collision_settings
    s.quality = quality
    s.time_scale = 1.0 / (fps * T)
    s.mass = mass_per_vertex
    s.rest_shape_key = flat
    if pinned:
        s.vertex_group_mass = "pin"  # weight 1: pinned (hard constraint, goal >= 0.999)
    s.tension_stiffness = k_uniform * T * T * avg_len
    s.compression_stiffness = k_uniform * T * T * avg_len
    s.tension_stiffness_max = s.tension_stiffness  # no structural vertex group
    s.compression_stiffness_max = s.compression_stiffness
    s.shear_stiffness = k_uniform * T * T * avg_len  # unused: triangles get no shear springs
    s.shear_stiffness_max = s.shear_stiffness
    # drape: c = damping * k per spring (kg/s); Blender: one absolute c per spring.
    c_spring = P["damping"] * k_uniform * T
    s.tension_damping = c_spring
    s.compression_damping = c_spring
    s.shear_damping = c_spring
    # Angular bending: Blender puts force k (theta - theta0) along each wing's normal,
    # spread over its vertices, with k = bending_stiffness * restlen * 0.1; on a
    # triangle that is a torque k h / 3 about the edge (h the wing's height,
    # sqrt(3)/2 L on an equilateral one). A hinge of drape's rigidity B on
    # equilateral triangles holds 2 B / sqrt(3) per radian, hence k = 4 B / L and
    # bending_stiffness = 40 B / L^2 (solver units: B T^2).
    s.bending_model = "ANGULAR"
    s.bending_stiffness = 40.0 * P["bending"] * T * T / (avg_len * avg_len)
    s.bending_stiffness_max = s.bending_stiffness
    s.bending_damping = 0.0  # explicit in Blender; drape's is ~1e-9 in these units
    # Air: Blender's drag is -0.01 air_damping v per vertex; drape's -drag A_i v.
    s.air_damping = P["drag"] * (area / n) * T / 0.01
    s.use_internal_springs = False
    s.use_pressure = False
    s.use_sewing_springs = True
    # drape's pull of a pair: sewing stiffness x share * gap, no cap. Blender's sewing
    # spring has the structural k (tension_stiffness / avg_spring_len) and a cap.
    shares = seam_pair_shares(sk)
    gaps0 = [math.dist(sk["v"][a], sk["v"][b]) for a, b in pairs]
    drape_pull0 = [P["sewing_stiffness"] * sh * g for sh, g in zip(shares, gaps0)]
    sew_max_n = max(drape_pull0) if args.sewing_force_max is None else args.sewing_force_max
    s.sewing_force_max = sew_max_n * T * T
    s.shrink_min = 0.0

    c.use_collision = True
    c.distance_min = common.BLENDER_DISTANCE_MIN_FLOOR
    c.collision_quality = args.collision_quality
    c.use_self_collision = P["self_thickness"] is not None
    if c.use_self_collision:
        # Self contacts are triangle pairs closer than 2 x self_distance_min (collision.cc).
        c.self_distance_min = 0.5 * P["self_thickness"]
    c.impulse_clamp = 0.0
    c.self_impulse_clamp = 0.0

    # The weightless phase: frame_set(f) steps the cloth from frame f - 1 to f
    # with the settings of frame f, so gravity's weight is 0 up to frame
    # frame_start + the weightless frames (the steps of the first --weightless s,
    # rounded up to whole frames) and 1 from the next (constant keys: a step).
    weightless_frames = int(math.ceil(args.weightless * fps - 1e-9))
    if weightless_frames > 0:
        w = s.effector_weights
        w.gravity = 0.0
        w.keyframe_insert("gravity", frame=scene.frame_start)
        w.keyframe_insert("gravity", frame=scene.frame_start + weightless_frames)
        w.gravity = 1.0
        w.keyframe_insert("gravity", frame=scene.frame_start + weightless_frames + 1)
        for fc in cloth.animation_data.action.fcurves:
            for kp in fc.keyframe_points:
                kp.interpolation = "CONSTANT"

    cache = mod.point_cache
    cache.frame_start = scene.frame_start
    cache.frame_end = scene.frame_end

    # ---------------------------------------------------------------- simulate
    timed = common.time_frames(scene, cloth)
    wall, cpu, per_frame = timed["wall"], timed["cpu"], timed["per_frame"]
    iters_avg, iters_max = timed["iters_avg"], timed["iters_max"]

    # ---------------- read back the cached frames (outside the timing)
    gap_per_frame = []
    if args.frames_dir:
        os.makedirs(args.frames_dir, exist_ok=True)
    for k, pts in common.read_back_frames(scene, cloth, cache):
        gap_per_frame.append(max(math.dist(pts[a], pts[b]) for a, b in pairs))
        if args.frames_dir:
            write_frame(os.path.join(args.frames_dir, f"frame_{k:05d}.obj"), pts, sk)
    closed = next((k for k, g in enumerate(gap_per_frame) if g < P["weld_gap"]), None)

    overhead = common.no_cloth_frame_stepping(scene, mod)

    out = {
        "engine": "blender",
        "blender_version": bpy.app.version_string,
        "scene": "skirt_rest" if not args.params else os.path.abspath(args.params),
        "params": P,
        "weightless_s": weightless_frames / fps,
        "skirt_obj": os.path.abspath(args.skirt),
        "body_obj": os.path.abspath(args.body),
        "vertices": n,
        "triangles": len(faces),
        "structural_springs": len(edges),
        "sewing_pairs": len(pairs),
        "pinned_vertices": len(pinned),
        "body_triangles": len(body_obj["faces"]),
        "pattern_area_m2": area,
        "avg_spring_len_m": avg_len,
        "k_uniform_n_per_m": k_uniform,
        "fps": fps,
        "frames": frames,
        "simulated_s": frames / fps,
        "quality": quality,
        "substep_s": 1.0 / (fps * quality),
        "substeps_total": frames * quality,
        "settings": {
            "time_scale": s.time_scale,
            "mass_per_vertex_kg": s.mass,
            "total_mass_kg": s.mass * n,
            "air_damping": s.air_damping,
            "tension_stiffness": s.tension_stiffness,
            "compression_stiffness": s.compression_stiffness,
            "shear_stiffness": s.shear_stiffness,
            "bending_model": s.bending_model,
            "bending_stiffness": s.bending_stiffness,
            "tension_damping": s.tension_damping,
            "compression_damping": s.compression_damping,
            "bending_damping": s.bending_damping,
            "use_sewing_springs": s.use_sewing_springs,
            "sewing_force_max": s.sewing_force_max,
            "sewing_force_max_n": sew_max_n,
            "sewing_spring_k_n_per_m": k_uniform,
            "drape_initial_pull_per_pair_n": {"max": max(drape_pull0), "min": min(drape_pull0)},
            "drape_sewing_k_per_pair_n_per_m": {"max": P["sewing_stiffness"] * max(shares),
                                                "min": P["sewing_stiffness"] * min(shares)},
            "rest_shape_key": s.rest_shape_key.name if s.rest_shape_key else None,
            "pin_group": s.vertex_group_mass,
            "collision_quality": c.collision_quality,
            "distance_min": c.distance_min,
            "use_self_collision": c.use_self_collision,
            "self_distance_min": c.self_distance_min,
            "self_friction": c.self_friction,
            "impulse_clamp": c.impulse_clamp,
            "self_impulse_clamp": c.self_impulse_clamp,
            "collider_thickness_outer": coll.thickness_outer,
            "collider_thickness_inner": coll.thickness_inner,
            "collider_cloth_friction": coll.cloth_friction,
            "collider_damping": coll.damping,
            "gravity": list(scene.gravity),
        },
        "wall_s": wall,
        "cpu_s": cpu,
        "cpu_over_wall": cpu / wall if wall > 0 else None,
        "no_cloth_frame_stepping_s": overhead,
        "per_frame_wall_s": {
            "median": statistics.median(per_frame),
            "max": max(per_frame),
            "all": [round(x, 5) for x in per_frame],
        },
        "solver_status": sorted(timed["statuses"]),
        "cg_iterations": {"per_frame_avg_mean": statistics.fmean(iters_avg), "max": iters_max},
        "initial_gap_max_m": gap_per_frame[0],
        "seams_closed_frame": closed,
        "seams_closed_s": closed / fps if closed is not None else None,
        "final_gap_max_m": gap_per_frame[-1],
        "gap_max_per_frame_m": [round(g, 6) for g in gap_per_frame],
        "threads": common.threads(scene),
        "host": platform.node(),
        "cpu_model": common.cpu_model(),
    }
    text = json.dumps(out, indent=2)
    print("DRAPE_BLENDER_RESULT " + json.dumps({k: out[k] for k in (
        "wall_s", "cpu_s", "frames", "quality", "seams_closed_s", "final_gap_max_m")}))
    if args.out:
        with open(args.out, "w") as fh:
            fh.write(text + "\n")


def write_frame(path, pts, sk):
    """The cloth at one frame, as drape writes its frames: positions, the
    panels' pattern coordinates and faces, and the open seams as `l` pairs."""
    with open(path, "w") as fh:
        fh.write("# blender frame\n")
        for p in pts:
            fh.write(f"v {p[0]!r} {p[1]!r} {p[2]!r}\n")
        for t in sk["vt"]:
            fh.write(f"vt {t[0]!r} {t[1]!r}\n")
        group = None
        for f, tex, g in zip(sk["faces"], sk["face_vt"], sk["face_group"]):
            if g != group:
                fh.write(f"g {g}\n")
                group = g
            fh.write("f " + " ".join(f"{i + 1}/{t + 1}" for i, t in zip(f, tex)) + "\n")
        seam = None
        for (a, b), s in zip(sk["pairs"], sk["pair_seam"]):
            if s != seam:
                fh.write(f"# seam {s}\n")
                seam = s
            fh.write(f"l {a + 1} {b + 1}\n")


if __name__ == "__main__":
    try:
        main()
    except SystemExit:
        raise
    except Exception:
        import traceback
        traceback.print_exc()
        sys.exit(1)
    sys.exit(0)
