"""Blender peer benchmark of drape's scenes/tablecloth.toml.

Run (Blender 3.4, Debian's `blender` package):

    blender -b --factory-startup --python benches/blender/tablecloth.py -- \
        [--resolution 128] [--quality N] [--fps 30] [--frames N] [--duration 4] \
        [--diagonals alternating|regular|quads] [--model default|matched] \
        [--collision-quality 2] [--out FILE.json]

Builds the scene from scratch (no .blend): a 1.6 m square cloth, a uniform
grid of `--resolution` segments per side centred at (0, 0, 1.0) m, dropped
onto a table (a box top and four box legs) above a floor plane, all fixed
Collision objects; simulates it with Blender's cloth modifier, times exactly
the simulation (the `frame_set` loop, as drape_sphere.py) and writes a JSON
summary. After the timed loop it reads every frame back from the point cache
and measures the penetration into the table and the floor, the centre
vertex's height and the cloth's bounding box.

The same measure runs on drape's frames, without Blender:

    drape run scenes/tablecloth.toml --no-record --obj-dir DIR
    python3 benches/blender/tablecloth.py --obj-dir DIR [--fps 30] [--out FILE.json]

README.md beside this file maps the scene and the material to Blender's and
says where the two models differ; the code shared with drape_sphere.py is in
common.py.
"""

import argparse
import glob
import json
import math
import os
import platform
import statistics
import sys
import time

try:
    import bpy
except ImportError:  # plain python3: only the measure of OBJ frames (--obj-dir)
    bpy = None

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402  (the code shared with drape_sphere.py; its options without Blender)

# ---------------------------------------------------------------- drape's scene
# Copied from scenes/tablecloth.toml; keep in sync.
WIDTH = 1.6  # m
BASE_RESOLUTION = 32  # segments per side of drape's adaptive base mesh
MAX_LEVEL = 4  # drape's finest level: two 1-4 splits, each halving the edges
# The uniform mesh of drape's finest edges: 32 * 2^2 = 128 segments per side.
FINEST_RESOLUTION = BASE_RESOLUTION * 2 ** (MAX_LEVEL // 2)
CENTRE_Z = 1.0  # m
GRAVITY = -9.81  # m/s^2
DENSITY = 0.15  # kg/m^2
STRETCH = 200.0  # N/m
BENDING = 1.0e-5  # N m
DAMPING = 0.001  # s, stiffness-proportional
DRAG = 0.02  # kg/(m^2 s)
DT = 0.004  # s, drape's step before it is rounded down to fill a frame
FPS = 30.0  # drape's frame rate for this scene
DURATION = 4.0  # s
THICKNESS = 0.003  # m, drape's default obstacle thickness (the scene sets none)

# The obstacles: boxes by centre and half extents (m), and the floor, the
# half-space z < 0. Friction: drape's (static, kinetic); the legs and the floor
# set none, so drape's default 0.5 (kinetic = static) applies.
BOXES = [
    {"name": "table_top", "centre": (0.0, 0.0, 0.76), "half": (0.5, 0.5, 0.02),
     "friction": (0.6, 0.4)},
] + [
    {"name": f"leg_{'p' if x > 0 else 'm'}x_{'p' if y > 0 else 'm'}y",
     "centre": (x, y, 0.37), "half": (0.03, 0.03, 0.37), "friction": (0.5, 0.5)}
    for x, y in ((0.44, 0.44), (-0.44, 0.44), (0.44, -0.44), (-0.44, -0.44))
]
FLOOR = {"name": "floor", "z": 0.0, "friction": (0.5, 0.5)}
# Blender's floor is a finite square, far wider than the cloth can reach.
FLOOR_HALF_SIZE = 3.0  # m

# The cloth's middle for the through-the-top count: within this distance of the
# cloth's centre in x and y at rest (m), i.e. at least 0.2 m inside the table's edges.
MIDDLE_HALF_WIDTH = 0.3

# Above this height a point is outside every box (and above the floor).
BOXES_TOP_Z = max(b["centre"][2] + b["half"][2] for b in BOXES)


def default_quality(fps):
    """drape's steps per frame: its dt rounded down so that whole steps fill a
    frame, ceil(1 / (fps dt)); 9 at 30 fps (3.70 ms, drape's actual step)."""
    return math.ceil(1.0 / (fps * DT) - 1e-9)


def parse_args():
    argv = common.script_argv() if bpy is not None else sys.argv[1:]
    p = argparse.ArgumentParser(prog="tablecloth.py")
    p.add_argument("--resolution", type=int, default=FINEST_RESOLUTION,
                   help=f"segments per side of the uniform cloth grid, even (default "
                        f"{FINEST_RESOLUTION}: the uniform mesh of drape's finest edges; "
                        f"{BASE_RESOLUTION} is drape's base mesh)")
    common.add_scene_options(
        p, toml="tablecloth.toml", duration=DURATION, fps=FPS, quality_default=None,
        quality_help="cloth steps per frame (default: drape's, ceil(1 / (fps dt)) with "
                     "dt = 4 ms: 9 at 30 fps, a 3.70 ms substep)")
    p.add_argument("--collision-quality", type=int, default=2,
                   help="Blender's collision passes per substep (default 2, Blender's default)")
    p.add_argument("--obj-dir", default=None,
                   help="measure drape's OBJ frames (frame_*.obj) in this directory instead "
                        "of simulating; runs without Blender")
    common.add_out_option(p)
    args = p.parse_args(argv)
    if args.resolution < 2 or args.resolution % 2:
        p.error("--resolution must be even (the grid then has a vertex at the centre)")
    if args.obj_dir is None and bpy is None:
        p.error("simulating needs Blender (blender -b --python tablecloth.py -- ...); "
                "plain python3 only measures OBJ frames (--obj-dir)")
    return args


# ------------------------------------------------------------------- measures
# Plain Python on (x, y, z) tuples in world space, so that the same code
# measures Blender's frames and drape's.

def penetration(pts):
    """The deepest vertex inside an obstacle: its depth (m; inside a box: the
    distance to the box's nearest face; below the floor: -z), the obstacle's
    name, and the number of vertices inside any obstacle."""
    deepest, where, inside = 0.0, None, 0
    for x, y, z in pts:
        if z >= BOXES_TOP_Z:
            continue  # above every box and the floor
        depth, name = 0.0, None
        if z < FLOOR["z"]:
            depth, name = FLOOR["z"] - z, FLOOR["name"]
        for b in BOXES:
            (cx, cy, cz), (hx, hy, hz) = b["centre"], b["half"]
            dx = hx - abs(x - cx)
            if dx <= 0.0:
                continue
            dy = hy - abs(y - cy)
            if dy <= 0.0:
                continue
            dz = hz - abs(z - cz)
            if dz <= 0.0:
                continue
            d = min(dx, dy, dz)
            if d > depth:
                depth, name = d, b["name"]
        if depth > 0.0:
            inside += 1
            if depth > deepest:
                deepest, where = depth, name
    return deepest, where, inside


def through_table_top(pts, middle):
    """The number of the cloth's middle vertices (`middle`: their indices) that
    are below the table top's underside, within its x-y extent. The middle is
    the cloth within MIDDLE_HALF_WIDTH of its centre at rest, which starts at
    least 0.2 m inside the table's edges: it gets under the top only by passing
    through it (or by sliding 0.2 m off the table and curling under). The
    penetration depth cannot see a cloth that went through the 4 cm top and out
    of its underside; this count does."""
    (cx, cy, cz), (hx, hy, hz) = BOXES[0]["centre"], BOXES[0]["half"]
    count = 0
    for i in middle:
        x, y, z = pts[i]
        if z < cz - hz and abs(x - cx) < hx and abs(y - cy) < hy:
            count += 1
    return count


def middle_vertices(rest_xy):
    """Indices of the vertices within MIDDLE_HALF_WIDTH of the cloth's centre
    (in x and y) at rest; `rest_xy`: each vertex's rest (x, y) relative to the
    centre (drape's material coordinates)."""
    edge = MIDDLE_HALF_WIDTH + 1e-6  # grid lines on the boundary count (float32 mesh)
    return [i for i, (u, v) in enumerate(rest_xy) if abs(u) <= edge and abs(v) <= edge]


class Measure:
    """Per-frame penetration, centre height and lowest point of a sequence of
    frames (k = 0: the rest state), and the last frame's bounding box."""

    def __init__(self, centre_index, middle):
        self.centre_index = centre_index
        self.middle = middle
        self.depth, self.obstacle, self.inside, self.through = [], [], [], []
        self.centre_z, self.lowest_z = [], []
        self.bbox = None

    def add(self, pts):
        depth, where, inside = penetration(pts)
        self.depth.append(depth)
        self.obstacle.append(where)
        self.inside.append(inside)
        self.through.append(through_table_top(pts, self.middle))
        self.centre_z.append(pts[self.centre_index][2])
        self.lowest_z.append(min(p[2] for p in pts))
        self.bbox = ([min(p[k] for p in pts) for k in range(3)],
                     [max(p[k] for p in pts) for k in range(3)])

    def report(self, fps):
        """The measure's part of the JSON report."""
        k = max(range(len(self.depth)), key=self.depth.__getitem__)
        hit = self.depth[k] > 0.0
        by_obstacle = {}
        for d, name in zip(self.depth, self.obstacle):
            if name is not None:
                by_obstacle[name] = max(by_obstacle.get(name, 0.0), d)
        return {
            "max_penetration_m": self.depth[k],
            "max_penetration_frame": k if hit else None,
            "max_penetration_s": k / fps if hit else None,
            "max_penetration_obstacle": self.obstacle[k],
            "max_penetration_by_obstacle_m": by_obstacle,
            "final_penetration_m": self.depth[-1],
            "final_vertices_inside": self.inside[-1],
            "max_vertices_inside": max(self.inside),
            "middle_vertices": len(self.middle),
            "final_vertices_through_table_top": self.through[-1],
            "max_vertices_through_table_top": max(self.through),
            "final_bbox_min": self.bbox[0],
            "final_bbox_max": self.bbox[1],
            "lowest_z": self.bbox[0][2],
            "lowest_z_over_frames": min(self.lowest_z),
            "centre_vertex": self.centre_index,
            "final_centre_z": self.centre_z[-1],
            "per_frame": {
                "penetration_m": [round(x, 6) for x in self.depth],
                "vertices_inside": self.inside,
                "vertices_through_table_top": self.through,
                "centre_z": [round(z, 6) for z in self.centre_z],
                "lowest_z": [round(z, 6) for z in self.lowest_z],
            },
        }


def read_obj(path):
    """An OBJ frame of drape's: positions, and each vertex's material
    coordinate (its `vt`, through the faces' v/vt corners)."""
    v, vt, uv_of = [], [], {}
    with open(path) as fh:
        for line in fh:
            w = line.split()
            if not w:
                continue
            if w[0] == "v":
                v.append((float(w[1]), float(w[2]), float(w[3])))
            elif w[0] == "vt":
                vt.append((float(w[1]), float(w[2])))
            elif w[0] == "f":
                for corner in w[1:]:
                    parts = corner.split("/")
                    if len(parts) > 1 and parts[1]:
                        uv_of[int(parts[0]) - 1] = int(parts[1]) - 1
    uv = [vt[uv_of[i]] if i in uv_of else None for i in range(len(v))]
    return v, uv


def measure_obj_dir(args):
    """The measure of drape's OBJ frames (drape run --obj-dir): frame_00000.obj is
    the rest state. The centre vertex is the one at material (0, 0), looked up
    in every frame (adaptive remeshing renumbers vertices)."""
    files = sorted(glob.glob(os.path.join(args.obj_dir, "frame_*.obj")))
    if not files:
        raise SystemExit(f"no frame_*.obj in {args.obj_dir}")
    m = None
    vertices = []
    for path in files:
        pts, uv = read_obj(path)
        if any(t is None for t in uv):
            raise SystemExit(f"{path}: a vertex without vt (its material coordinate)")
        centre = min(range(len(pts)), key=lambda i: uv[i][0] ** 2 + uv[i][1] ** 2)
        if m is None:
            m = Measure(centre, [])
        m.centre_index = centre
        m.middle = middle_vertices(uv)
        m.add(pts)
        vertices.append(len(pts))
    out = {
        "engine": "drape",
        "source": os.path.abspath(args.obj_dir),
        "scene": "tablecloth",
        "fps": args.fps,
        "frames": len(files) - 1,
        "simulated_s": (len(files) - 1) / args.fps,
        "vertices": {"first": vertices[0], "last": vertices[-1], "max": max(vertices)},
        **m.report(args.fps),
    }
    del out["centre_vertex"]  # an index that changes with the adaptive mesh
    emit(out, args.out)


def emit(out, path):
    """Prints the result line and writes the JSON file."""
    print("DRAPE_BLENDER_RESULT " + json.dumps(out))
    if path:
        with open(path, "w") as fh:
            fh.write(json.dumps(out, indent=2) + "\n")


# ---------------------------------------------------------------- the scene

def box_object(name, centre, half):
    """A closed box mesh (8 vertices, 6 quads, normals outward: Blender's
    collision culling uses them), placed at `centre`."""
    import bmesh
    from mathutils import Matrix

    me = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bmesh.ops.create_cube(bm, size=2.0, matrix=Matrix.Diagonal((*half, 1.0)))
    bm.to_mesh(me)
    bm.free()
    me.update()
    ob = bpy.data.objects.new(name, me)
    ob.location = centre
    # every face's normal points away from the box's centre
    for poly in me.polygons:
        if poly.normal.dot(poly.center) <= 0.0:
            raise SystemExit(f"{name}: a face normal points inwards")
    return ob


def floor_object():
    """The floor: one square at z = 0, normal +z (counter-clockwise from above)."""
    s = FLOOR_HALF_SIZE
    me = bpy.data.meshes.new("floor")
    me.from_pydata([(-s, -s, 0.0), (s, -s, 0.0), (s, s, 0.0), (-s, s, 0.0)], [], [(0, 1, 2, 3)])
    me.validate()
    me.update()
    ob = bpy.data.objects.new("floor", me)
    ob.location = (0.0, 0.0, FLOOR["z"])
    return ob


def simulate(args):
    """Builds the scene in Blender, times the simulation, measures every frame
    and writes the JSON report."""
    t_start = time.perf_counter()
    n = args.resolution
    fps = args.fps
    frames = common.frame_count(args)
    quality = args.quality if args.quality is not None else default_quality(fps)

    common.clear_scene()
    scene = common.set_up_scene(fps, frames, GRAVITY)

    # --------------------------------------------------------------- obstacles
    colliders = []
    for b in BOXES:
        ob = box_object(b["name"], b["centre"], b["half"])
        scene.collection.objects.link(ob)
        colliders.append((b, ob, common.make_collider(ob, THICKNESS, b["friction"][1])))
    ob = floor_object()
    scene.collection.objects.link(ob)
    colliders.append((FLOOR, ob, common.make_collider(ob, THICKNESS, FLOOR["friction"][1])))

    # ------------------------------------------------------------------- cloth
    me = common.grid_mesh(WIDTH, n, args.diagonals)
    cloth = bpy.data.objects.new("cloth", me)
    scene.collection.objects.link(cloth)
    cloth.location = (0.0, 0.0, CENTRE_Z)
    n_verts = len(me.vertices)
    n_tris = sum(len(p.vertices) - 2 for p in me.polygons)
    area = WIDTH * WIDTH
    centre_index = (n // 2) * (n + 1) + n // 2  # vertex (n/2, n/2), at (0, 0, CENTRE_Z)

    mod, time_scale, avg_len = common.set_up_cloth(
        cloth, quality=quality, total_mass=DENSITY * area, area=area, drag=DRAG,
        model=args.model, fps=fps, stretch=STRETCH, bending=BENDING, damping=DAMPING,
        hinge_spacing=WIDTH / n)
    mod.collision_settings.collision_quality = args.collision_quality

    cache = mod.point_cache
    cache.frame_start = scene.frame_start
    cache.frame_end = scene.frame_end

    print(f"tablecloth.py: scene built in {time.perf_counter() - t_start:.2f} s "
          f"({n_verts} vertices, quality {quality}, {frames} frames)", flush=True)

    # ---------------------------------------------------------------- simulate
    timed = common.time_frames(scene, cloth)
    per_frame, iters_avg = timed["per_frame"], timed["iters_avg"]
    print(f"tablecloth.py: simulated in {timed['wall']:.2f} s", flush=True)

    # ----------------------------------------- measure (outside the timing)
    t_measure = time.perf_counter()
    rest_xy = [(v.co.x, v.co.y) for v in me.vertices]  # the grid, centred on the cloth
    measure = Measure(centre_index, middle_vertices(rest_xy))
    for _, pts in common.read_back_frames(scene, cloth, cache):
        measure.add(pts)
    print(f"tablecloth.py: frames read back and measured in "
          f"{time.perf_counter() - t_measure:.2f} s", flush=True)

    overhead = common.no_cloth_frame_stepping(scene, mod)

    coll0 = colliders[0][2]
    out = {
        "engine": "blender",
        "blender_version": bpy.app.version_string,
        "scene": "tablecloth",
        "method": "frame_set",
        "model": args.model,
        "diagonals": args.diagonals,
        "resolution": n,
        "vertices": n_verts,
        "triangles": n_tris,
        "faces": len(me.polygons),
        "edges": len(me.edges),
        "avg_spring_len_m": avg_len,
        "obstacles": [{
            "name": b["name"],
            **({"centre": list(b["centre"]), "half_extents": list(b["half"])}
               if "half" in b else {"plane_z": b["z"], "half_size": FLOOR_HALF_SIZE}),
            "drape_friction_static": b["friction"][0],
            "drape_friction_kinetic": b["friction"][1],
            "cloth_friction": coll.cloth_friction,
        } for b, _, coll in colliders],
        "fps": fps,
        "frames": frames,
        "simulated_s": frames / fps,
        "quality": quality,
        "substep_s": 1.0 / (fps * quality),
        "drape_dt_s": 1.0 / (fps * default_quality(fps)),
        "substeps_total": frames * quality,
        "time_scale": time_scale,
        "solver_time_units": frames * time_scale,
        "settings": {
            **common.cloth_settings(mod, n_verts),
            "collider_thickness_outer": coll0.thickness_outer,
            "collider_thickness_inner": coll0.thickness_inner,
            "collider_damping": coll0.damping,
            "collider_use_culling": coll0.use_culling,
            "collider_use_normal": coll0.use_normal,
            "contact_distance_m": THICKNESS,
            "gravity": list(scene.gravity),
        },
        "wall_s": timed["wall"],
        "wall_frames_s": sum(per_frame),
        "cpu_s": timed["cpu"],
        "cpu_over_wall": timed["cpu"] / timed["wall"] if timed["wall"] > 0 else None,
        "no_cloth_frame_stepping_s": overhead,
        "per_frame_wall_s": {
            "median": statistics.median(per_frame),
            "max": max(per_frame),
            "first": per_frame[0],
            "sum_of_top10": sum(sorted(per_frame)[-10:]),
            "all": [round(x, 5) for x in per_frame],
        },
        "cg_iterations": {
            "per_frame_avg_mean": statistics.fmean(iters_avg),
            "max": timed["iters_max"],
            "per_frame_avg": [round(x, 2) for x in iters_avg],
        },
        **measure.report(fps),
        "threads": common.threads(scene),
        "host": platform.node(),
        "cpu_model": common.cpu_model(),
    }
    emit(out, args.out)


def main():
    """Simulates in Blender, or with --obj-dir measures drape's frames."""
    args = parse_args()
    if args.obj_dir is not None:
        measure_obj_dir(args)
    else:
        simulate(args)


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
