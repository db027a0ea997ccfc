"""Blender peer benchmark of drape's scenes/drape_sphere.toml.

Run (Blender 3.4, Debian's `blender` package):

    blender -b --factory-startup --python benches/blender/drape_sphere.py -- \
        [--quality 5] [--fps 30] [--frames N] [--duration 5] \
        [--diagonals alternating|regular|quads] [--model default|matched] \
        [--sphere-segments 64] [--method frame_set|bake] [--out FILE.json]

Builds the scene from scratch (no .blend): a 65 x 65 vertex cloth grid dropped
from z = 1.0 m onto a fixed UV sphere of radius 0.5 m, simulates it with
Blender's cloth modifier, times exactly the simulation and writes a JSON
summary. See README.md beside this file for the mapping to drape's scene and
where the two models differ.
"""

import argparse
import json
import math
import os
import platform
import statistics
import sys
import time

import bpy

# ---------------------------------------------------------------- drape's scene
# Copied from scenes/drape_sphere.toml; keep in sync.
WIDTH = 1.6  # m
RESOLUTION = 64  # segments per side -> 65 x 65 vertices
CENTRE_Z = 1.0  # m
SPHERE_RADIUS = 0.5  # m
GRAVITY = -9.81  # m/s^2
DENSITY = 0.15  # kg/m^2
STRETCH = 200.0  # N/m
BENDING = 1.0e-5  # N m
DAMPING = 0.001  # s, stiffness-proportional
DRAG = 0.02  # kg/(m^2 s)
THICKNESS = 0.003  # m
FRICTION_STATIC = 0.5
FRICTION_KINETIC = 0.3
DURATION = 5.0  # s

# Blender's cloth solver runs in frames, not seconds: dt = time_scale /
# quality frames, and gravity enters as 0.001 * g per frame^2 (SIM_cloth_solve /
# cloth_calc_force). Gravity is therefore physical when one solver time unit is
# T = sqrt(0.001) s = 31.6 ms. Rates (damping, drag) and stiffnesses are
# converted with that T in --model matched; see README.md.
SOLVER_UNIT_S = math.sqrt(0.001)

# Blender's minimum for the cloth's own object-collision distance
# (collision_settings.distance_min); the collider's thickness_outer adds to it.
BLENDER_DISTANCE_MIN_FLOOR = 0.001


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="drape_sphere.py")
    p.add_argument("--quality", type=int, default=5, help="cloth steps per frame (default 5)")
    p.add_argument("--fps", type=float, default=30.0, help="scene frames per second (default 30)")
    p.add_argument("--frames", type=int, default=None,
                   help="simulated frames (default: round(duration * fps))")
    p.add_argument("--duration", type=float, default=DURATION, help="simulated seconds (default 5)")
    p.add_argument("--diagonals", choices=["alternating", "regular", "quads"], default="alternating",
                   help="grid triangulation: drape's default 'alternating' (what drape_sphere.toml "
                        "uses), drape's 'regular', or Blender quads")
    p.add_argument("--model", choices=["default", "matched"], default="default",
                   help="'default': Blender's default stiffness/damping, time_scale 1; "
                        "'matched': stiffness, damping and time scale converted from drape")
    p.add_argument("--sphere-segments", type=int, default=64,
                   help="UV sphere segments (rings = half of it; default 64)")
    p.add_argument("--method", choices=["frame_set", "bake"], default="frame_set",
                   help="step frames with scene.frame_set (default) or bpy.ops.ptcache.bake")
    p.add_argument("--out", default=None, help="write the JSON summary here (also printed)")
    return p.parse_args(argv)


def clear_scene():
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    for me in list(bpy.data.meshes):
        bpy.data.meshes.remove(me)


def grid_mesh(diagonals):
    """drape's rectangle generator (src/mesh/generate.rs): vertex (i, j) at index
    j * 65 + i, u = -w/2 + w i / n; each square split along a-c (regular) or
    checkerboard-alternating a-c / b-d; or left as a quad."""
    n = RESOLUTION
    verts = [(-0.5 * WIDTH + WIDTH * i / n, -0.5 * WIDTH + WIDTH * j / n, 0.0)
             for j in range(n + 1) for i in range(n + 1)]

    def vid(i, j):
        return j * (n + 1) + i

    faces = []
    for j in range(n):
        for i in range(n):
            a, b, c, d = vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)
            if diagonals == "quads":
                faces.append((a, b, c, d))
                continue
            along_ac = diagonals == "regular" or (i + j) % 2 == 0
            if along_ac:
                faces += [(a, b, c), (a, c, d)]
            else:
                faces += [(a, b, d), (b, c, d)]
    me = bpy.data.meshes.new("cloth")
    me.from_pydata(verts, [], faces)
    me.validate()
    me.update()
    return me


def main():
    args = parse_args()
    frames = args.frames if args.frames is not None else int(round(args.duration * args.fps))
    sim_seconds = frames / args.fps

    clear_scene()
    scene = bpy.context.scene
    # Integer fps through fps / fps_base.
    scene.render.fps = int(round(args.fps * 1000))
    scene.render.fps_base = 1000.0
    scene.frame_start = 1
    scene.frame_end = 1 + frames  # frame 1 is the rest state; frames 2..N+1 are simulated
    scene.use_gravity = True
    scene.gravity = (0.0, 0.0, GRAVITY)

    # ---------------------------------------------------------------- obstacle
    seg = args.sphere_segments
    bpy.ops.mesh.primitive_uv_sphere_add(segments=seg, ring_count=seg // 2,
                                         radius=SPHERE_RADIUS, location=(0.0, 0.0, 0.0))
    sphere = bpy.context.object
    sphere.name = "ball"
    sphere.modifiers.new("Collision", "COLLISION")
    coll = sphere.collision
    # Contact distance = cloth distance_min + collider thickness_outer (collision.cc,
    # min_distance = (epsilon1 + epsilon2) * 8/9). Split drape's 3 mm between them.
    coll.thickness_outer = THICKNESS - BLENDER_DISTANCE_MIN_FLOOR
    # Blender has one friction coefficient (cloth_friction * 0.01, Coulomb-like on
    # the impulse); drape's kinetic one is used.
    coll.cloth_friction = 100.0 * FRICTION_KINETIC

    # ------------------------------------------------------------------- cloth
    me = grid_mesh(args.diagonals)
    cloth = bpy.data.objects.new("cloth", me)
    scene.collection.objects.link(cloth)
    cloth.location = (0.0, 0.0, CENTRE_Z)
    n_verts = len(me.vertices)
    n_tris = sum(len(p.vertices) - 2 for p in me.polygons)
    n_edges = len(me.edges)
    area = WIDTH * WIDTH
    total_mass = DENSITY * area
    area_per_vertex = area / n_verts

    mod = cloth.modifiers.new("Cloth", "CLOTH")
    s = mod.settings
    c = mod.collision_settings
    s.quality = args.quality
    s.mass = total_mass / n_verts  # Blender's mass is per vertex (kg)
    # Air: Blender's drag force is -0.01 * air_damping * v per vertex in solver units
    # (SIM_mass_spring_force_drag). drape: -drag * area * v, per vertex area share.
    drag_per_vertex = DRAG * area_per_vertex  # kg/s
    s.air_damping = drag_per_vertex * SOLVER_UNIT_S / 0.01
    c.use_collision = True
    c.use_self_collision = False  # Blender's default; drape_sphere has no self-collision either
    c.distance_min = BLENDER_DISTANCE_MIN_FLOOR

    # avg spring length over structural springs (= mesh edges), as cloth.cc computes it
    avg_len = sum((me.vertices[e.vertices[0]].co - me.vertices[e.vertices[1]].co).length
                  for e in me.edges) / n_edges

    time_scale = 1.0
    if args.model == "matched":
        # Make one solver unit SOLVER_UNIT_S seconds while a frame is 1/fps s.
        time_scale = 1.0 / (args.fps * SOLVER_UNIT_S)
        t2 = SOLVER_UNIT_S ** 2
        # Linear spring: k = stiffness / avg_spring_len per spring (solver units).
        # For axis-aligned grid springs the membrane stiffness ~= k, so k = STRETCH.
        k_spring = STRETCH * t2
        s.tension_stiffness = k_spring * avg_len
        s.compression_stiffness = k_spring * avg_len
        s.shear_stiffness = k_spring * avg_len
        # Angular bending: torque = bending * restlen * 0.1 * angle. A discrete hinge of
        # rigidity D on a right-triangle grid has about 3 D per radian.
        h = WIDTH / RESOLUTION
        s.bending_stiffness = 3.0 * BENDING * t2 / (0.1 * h)
        # Damping: drape's is stiffness-proportional, c = DAMPING * k (kg/s per spring).
        c_spring = DAMPING * STRETCH * SOLVER_UNIT_S
        s.tension_damping = c_spring
        s.compression_damping = c_spring
        s.shear_damping = c_spring
        # Angular bending is explicit in Blender (no Jacobian), so its default damping
        # (0.5) explodes at this vertex mass. drape's bending damping is
        # DAMPING * hinge stiffness, i.e. ~1e-9 in these units: use 0.
        s.bending_damping = 0.0
    s.time_scale = time_scale

    cache = mod.point_cache
    cache.frame_start = scene.frame_start
    cache.frame_end = scene.frame_end

    scene.frame_set(scene.frame_start)
    depsgraph = bpy.context.evaluated_depsgraph_get()

    def solver_result():
        ev = cloth.evaluated_get(depsgraph)
        r = ev.modifiers["Cloth"].solver_result
        return r.status, r.avg_iterations, r.max_iterations

    # ---------------------------------------------------------------- simulate
    per_frame = []
    iters_avg = []
    iters_max = 0
    cpu0 = time.process_time()
    if args.method == "frame_set":
        t0 = time.perf_counter()
        for f in range(scene.frame_start + 1, scene.frame_end + 1):
            tf = time.perf_counter()
            scene.frame_set(f)
            per_frame.append(time.perf_counter() - tf)
            st, avg_it, max_it = solver_result()
            iters_avg.append(avg_it)
            iters_max = max(iters_max, max_it)
        wall = time.perf_counter() - t0
        wall_frames_only = sum(per_frame)
    else:
        override = {"scene": scene, "active_object": cloth, "object": cloth,
                    "point_cache": cache}
        with bpy.context.temp_override(**override):
            t0 = time.perf_counter()
            bpy.ops.ptcache.bake(bake=True)
            wall = time.perf_counter() - t0
        wall_frames_only = None
    cpu = time.process_time() - cpu0

    # Depsgraph overhead without the solver: step the same frames with the cloth
    # modifier off (sphere collision modifier still evaluated). Not subtracted.
    # ------------------------------------------------------------------ result
    scene.frame_set(scene.frame_end)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    ev = cloth.evaluated_get(depsgraph)
    ev_mesh = ev.to_mesh()
    mw = ev.matrix_world
    pts = [mw @ v.co for v in ev_mesh.vertices]
    lo = [min(p[k] for p in pts) for k in range(3)]
    hi = [max(p[k] for p in pts) for k in range(3)]
    min_r = min(p.length for p in pts)
    # a vertex inside the contact shell (radius + thickness), i.e. in contact
    in_contact = sum(1 for p in pts if p.length < SPHERE_RADIUS + 2 * THICKNESS)
    ev.to_mesh_clear()

    mod.show_viewport = False
    scene.frame_set(scene.frame_start)
    t0 = time.perf_counter()
    for f in range(scene.frame_start + 1, scene.frame_end + 1):
        scene.frame_set(f)
    overhead = time.perf_counter() - t0

    cache_ok = cache.is_baked if args.method == "bake" else None
    out = {
        "engine": "blender",
        "blender_version": bpy.app.version_string,
        "scene": "drape_sphere",
        "method": args.method,
        "model": args.model,
        "diagonals": args.diagonals,
        "vertices": n_verts,
        "triangles": n_tris,
        "faces": len(me.polygons),
        "edges": n_edges,
        "avg_spring_len_m": avg_len,
        "sphere_segments": seg,
        "sphere_rings": seg // 2,
        "sphere_faces": len(sphere.data.polygons),
        "fps": args.fps,
        "frames": frames,
        "simulated_s": sim_seconds,
        "quality": args.quality,
        "substeps_total": frames * args.quality,
        "time_scale": time_scale,
        "solver_time_units": frames * time_scale,
        "settings": {
            "mass_per_vertex_kg": s.mass,
            "total_mass_kg": s.mass * n_verts,
            "air_damping": s.air_damping,
            "tension_stiffness": s.tension_stiffness,
            "compression_stiffness": s.compression_stiffness,
            "shear_stiffness": s.shear_stiffness,
            "bending_stiffness": s.bending_stiffness,
            "bending_model": s.bending_model,
            "tension_damping": s.tension_damping,
            "compression_damping": s.compression_damping,
            "shear_damping": s.shear_damping,
            "bending_damping": s.bending_damping,
            "use_internal_springs": s.use_internal_springs,
            "use_pressure": s.use_pressure,
            "collision_quality": c.collision_quality,
            "distance_min": c.distance_min,
            "use_self_collision": c.use_self_collision,
            "impulse_clamp": c.impulse_clamp,
            "collider_thickness_outer": coll.thickness_outer,
            "collider_cloth_friction": coll.cloth_friction,
            "collider_damping": coll.damping,
            "gravity": list(scene.gravity),
        },
        "wall_s": wall,
        "wall_frames_s": wall_frames_only,
        "cpu_s": cpu,
        "cpu_over_wall": cpu / wall if wall > 0 else None,
        "no_cloth_frame_stepping_s": overhead,
        "per_frame_wall_s": {
            "median": statistics.median(per_frame) if per_frame else None,
            "max": max(per_frame) if per_frame else None,
            "first": per_frame[0] if per_frame else None,
            "sum_of_top10": sum(sorted(per_frame)[-10:]) if per_frame else None,
            "all": [round(x, 5) for x in per_frame],
        },
        "cg_iterations": {
            "per_frame_avg_mean": statistics.fmean(iters_avg) if iters_avg else None,
            "max": iters_max if iters_avg else None,
        },
        "bake_is_baked": cache_ok,
        "final_bbox_min": lo,
        "final_bbox_max": hi,
        "lowest_z": lo[2],
        "sphere_top_z": SPHERE_RADIUS,
        "min_distance_to_centre": min_r,
        "vertices_in_contact": in_contact,
        "threads": {
            "render_threads_mode": scene.render.threads_mode,
            "render_threads": scene.render.threads,
            "os_cpu_count": os.cpu_count(),
            "sched_affinity": len(os.sched_getaffinity(0)),
        },
        "host": platform.node(),
        "cpu_model": _cpu_model(),
    }
    text = json.dumps(out, indent=2)
    print("DRAPE_BLENDER_RESULT " + json.dumps(out))
    if args.out:
        with open(args.out, "w") as fh:
            fh.write(text + "\n")


def _cpu_model():
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


if __name__ == "__main__":
    try:
        main()
    except Exception:
        import traceback
        traceback.print_exc()
        sys.exit(1)
    sys.exit(0)
