"""Blender peer benchmark of drape's scenes/drape_sphere.toml.

Run (Blender 3.4, Debian's `blender` package):

    blender -b --factory-startup --python benches/blender/drape_sphere.py -- \
        [--quality 5] [--fps 30] [--frames N] [--duration 5] \
        [--diagonals alternating|regular|quads] [--model default|matched] \
        [--sphere-segments 64] [--method frame_set|bake] [--out FILE.json]

Builds the scene from scratch (no .blend): a 65 x 65 vertex cloth grid dropped
from z = 1.0 m onto a fixed UV sphere of radius 0.5 m, simulates it with
Blender's cloth modifier, times exactly the simulation and writes a JSON
summary. After the timed loop it reads every frame back from the point cache
and measures how deep the cloth goes into the ball. See README.md beside this
file for the mapping to drape's scene and where the two models differ; the
code shared with tablecloth.py is in common.py.
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

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402  (the code shared with tablecloth.py)

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


def parse_args():
    p = argparse.ArgumentParser(prog="drape_sphere.py")
    common.add_scene_options(p, toml="drape_sphere.toml", duration=DURATION, quality_default=5,
                             quality_help="cloth steps per frame (default 5)")
    p.add_argument("--sphere-segments", type=int, default=64,
                   help="UV sphere segments (rings = half of it; default 64)")
    p.add_argument("--method", choices=["frame_set", "bake"], default="frame_set",
                   help="step frames with scene.frame_set (default) or bpy.ops.ptcache.bake")
    common.add_out_option(p)
    return p.parse_args(common.script_argv())


def main():
    args = parse_args()
    frames = common.frame_count(args)
    sim_seconds = frames / args.fps

    common.clear_scene()
    scene = common.set_up_scene(args.fps, frames, GRAVITY)

    # ---------------------------------------------------------------- obstacle
    seg = args.sphere_segments
    bpy.ops.mesh.primitive_uv_sphere_add(segments=seg, ring_count=seg // 2,
                                         radius=SPHERE_RADIUS, location=(0.0, 0.0, 0.0))
    sphere = bpy.context.object
    sphere.name = "ball"
    coll = common.make_collider(sphere, THICKNESS, FRICTION_KINETIC)

    # ------------------------------------------------------------------- cloth
    me = common.grid_mesh(WIDTH, RESOLUTION, args.diagonals)
    cloth = bpy.data.objects.new("cloth", me)
    scene.collection.objects.link(cloth)
    cloth.location = (0.0, 0.0, CENTRE_Z)
    n_verts = len(me.vertices)
    n_tris = sum(len(p.vertices) - 2 for p in me.polygons)
    n_edges = len(me.edges)
    area = WIDTH * WIDTH

    mod, time_scale, avg_len = common.set_up_cloth(
        cloth, quality=args.quality, total_mass=DENSITY * area, area=area, drag=DRAG,
        model=args.model, fps=args.fps, stretch=STRETCH, bending=BENDING, damping=DAMPING,
        hinge_spacing=WIDTH / RESOLUTION)

    cache = mod.point_cache
    cache.frame_start = scene.frame_start
    cache.frame_end = scene.frame_end

    # ---------------------------------------------------------------- simulate
    if args.method == "frame_set":
        timed = common.time_frames(scene, cloth)
        wall, cpu, per_frame = timed["wall"], timed["cpu"], timed["per_frame"]
        iters_avg, iters_max = timed["iters_avg"], timed["iters_max"]
        wall_frames_only = sum(per_frame)
    else:
        scene.frame_set(scene.frame_start)
        per_frame, iters_avg, iters_max = [], [], 0
        override = {"scene": scene, "active_object": cloth, "object": cloth,
                    "point_cache": cache}
        cpu0 = time.process_time()
        with bpy.context.temp_override(**override):
            t0 = time.perf_counter()
            bpy.ops.ptcache.bake(bake=True)
            wall = time.perf_counter() - t0
        cpu = time.process_time() - cpu0
        wall_frames_only = None

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

    # Penetration, every frame (read back from the cache, outside the timing): the
    # depth of the deepest vertex inside drape's exact ball, radius - distance to
    # the centre, and inside the contact shell of radius + contact distance
    # (drape's thickness = the collider's thickness_outer + the cloth's distance_min).
    contact_distance = THICKNESS
    depth_per_frame, shell_per_frame, inside_per_frame = [], [], []
    for _, frame_pts in common.read_back_frames(scene, cloth, cache):
        r = [math.hypot(*p) for p in frame_pts]
        r_min = min(r)
        depth_per_frame.append(max(0.0, SPHERE_RADIUS - r_min))
        shell_per_frame.append(max(0.0, SPHERE_RADIUS + contact_distance - r_min))
        inside_per_frame.append(sum(1 for x in r if x < SPHERE_RADIUS))
    # frame k = 0 is the rest state, k = frames the last (drape's frame numbers)
    deepest = max(range(len(depth_per_frame)), key=depth_per_frame.__getitem__)

    overhead = common.no_cloth_frame_stepping(scene, mod)

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
            **common.cloth_settings(mod, n_verts),
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
        "max_penetration_m": depth_per_frame[deepest],
        "max_penetration_frame": deepest if depth_per_frame[deepest] > 0 else None,
        "max_penetration_s": deepest / args.fps if depth_per_frame[deepest] > 0 else None,
        "final_penetration_m": depth_per_frame[-1],
        "contact_distance_m": contact_distance,
        "max_penetration_of_contact_distance_m": max(shell_per_frame),
        "penetration_per_frame_m": [round(x, 6) for x in depth_per_frame],
        "vertices_inside_per_frame": inside_per_frame,
        "threads": common.threads(scene),
        "host": platform.node(),
        "cpu_model": common.cpu_model(),
    }
    text = json.dumps(out, indent=2)
    print("DRAPE_BLENDER_RESULT " + json.dumps(out))
    if args.out:
        with open(args.out, "w") as fh:
            fh.write(text + "\n")


if __name__ == "__main__":
    try:
        main()
    except Exception:
        import traceback
        traceback.print_exc()
        sys.exit(1)
    sys.exit(0)
