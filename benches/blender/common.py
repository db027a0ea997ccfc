"""Blender-side code shared by the peer benchmarks drape_sphere.py and tablecloth.py
(skirt.py uses the frame range, the timed loop and the read-back).

Imported from inside Blender (`blender -b --python SCRIPT`): each script puts
its own directory on sys.path first. Holds the command-line options both
scripts share, the scene set-up both scenes share (the frame range, drape's
rectangle grid, collider settings, drape's material in Blender's units), the
timed frame loop and the read-back of every frame from the point cache.
README.md beside this file explains each conversion. Without Blender (plain
python3, tablecloth.py --obj-dir) only the options are usable.
"""

import math
import os
import platform
import sys
import time
from array import array

try:
    import bpy
except ImportError:  # plain python3: only the command-line options
    bpy = None

# Blender's cloth solver runs in frames, not seconds: dt = time_scale /
# quality frames, and gravity enters as 0.001 * g per frame^2 (SIM_cloth_solve /
# cloth_calc_force). Gravity is therefore physical when one solver time unit is
# T = sqrt(0.001) s = 31.6 ms. Rates (damping, drag) and stiffnesses are
# converted with that T in --model matched; see README.md.
SOLVER_UNIT_S = math.sqrt(0.001)

# Blender's minimum for the cloth's own object-collision distance
# (collision_settings.distance_min); the collider's thickness_outer adds to it.
BLENDER_DISTANCE_MIN_FLOOR = 0.001


def script_argv():
    """The command line after Blender's `--`: the script's own options."""
    return sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []


def add_scene_options(p, *, toml, duration, quality_default, quality_help, fps=30.0):
    """Adds the options of drape_sphere.py and tablecloth.py that are the same
    in both, in this order: --quality (its default and help: the script's),
    --fps, --frames, --duration, --diagonals (its help names `toml`, the scene
    file) and --model. --out comes last: add_out_option."""
    p.add_argument("--quality", type=int, default=quality_default, help=quality_help)
    p.add_argument("--fps", type=float, default=fps,
                   help=f"scene frames per second (default {fps:g})")
    p.add_argument("--frames", type=int, default=None,
                   help="simulated frames (default: round(duration * fps))")
    p.add_argument("--duration", type=float, default=duration,
                   help=f"simulated seconds (default {duration:g})")
    p.add_argument("--diagonals", choices=["alternating", "regular", "quads"], default="alternating",
                   help=f"grid triangulation: drape's default 'alternating' (what {toml} "
                        "uses), drape's 'regular', or Blender quads")
    p.add_argument("--model", choices=["default", "matched"], default="default",
                   help="'default': Blender's default stiffness/damping, time_scale 1; "
                        "'matched': stiffness, damping and time scale converted from drape")


def add_out_option(p):
    """Adds --out, the JSON summary's file."""
    p.add_argument("--out", default=None, help="write the JSON summary here (also printed)")


def frame_count(args):
    """The simulated frames: --frames, or round(duration * fps)."""
    return args.frames if args.frames is not None else int(round(args.duration * args.fps))


def clear_scene():
    """Removes the factory start-up objects and meshes (cube, camera, light)."""
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    for me in list(bpy.data.meshes):
        bpy.data.meshes.remove(me)


def set_up_scene(fps, frames, gravity_z):
    """Sets the frame rate, the frame range and gravity. Frame 1 is the rest
    state (the cloth cache starts there); frames 2 .. frames+1 are simulated."""
    scene = bpy.context.scene
    # Integer fps through fps / fps_base.
    scene.render.fps = int(round(fps * 1000))
    scene.render.fps_base = 1000.0
    scene.frame_start = 1
    scene.frame_end = 1 + frames
    scene.use_gravity = True
    scene.gravity = (0.0, 0.0, gravity_z)
    return scene


def grid_mesh(width, n, diagonals, name="cloth"):
    """drape's rectangle generator (src/mesh/generate.rs) for a square of side
    `width` with n segments per side: vertex (i, j) at index j * (n + 1) + i,
    u = -w/2 + w i / n, in the plane z = 0; each square split along a-c
    (regular) or checkerboard-alternating a-c / b-d; or left as a quad."""
    verts = [(-0.5 * width + width * i / n, -0.5 * width + width * j / n, 0.0)
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
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    me.validate()
    me.update()
    return me


def make_collider(ob, thickness, friction_kinetic):
    """Adds a Collision modifier with drape's contact distance and friction.

    Contact distance = cloth distance_min + collider thickness_outer (collision.cc,
    min_distance = (epsilon1 + epsilon2) * 8/9); drape's thickness is split between
    them, the cloth taking Blender's minimum. Blender has one friction coefficient
    (cloth_friction * 0.01, Coulomb-like on the impulse); drape's kinetic one is used.
    """
    ob.modifiers.new("Collision", "COLLISION")
    coll = ob.collision
    coll.thickness_outer = thickness - BLENDER_DISTANCE_MIN_FLOOR
    coll.cloth_friction = 100.0 * friction_kinetic
    return coll


def avg_spring_len(me):
    """Average length of the structural springs (= mesh edges), as cloth.cc computes it."""
    return sum((me.vertices[e.vertices[0]].co - me.vertices[e.vertices[1]].co).length
               for e in me.edges) / len(me.edges)


def set_up_cloth(cloth, *, quality, total_mass, area, drag, model, fps,
                 stretch, bending, damping, hinge_spacing):
    """Adds the Cloth modifier with drape's material in Blender's units.

    Always: uniform per-vertex mass, drape's air drag, collisions with Blender's
    smallest distance_min, no self-collision. `model` 'default' keeps Blender's
    default stiffness, damping and time scale; 'matched' converts drape's SI
    stretch (N/m), bending (N m) and stiffness-proportional damping (s), and
    sets time_scale so that gravity and the frame duration are both physical.
    `hinge_spacing` is the grid spacing h (m) of the bending conversion.
    Returns (modifier, time_scale, avg_spring_len).
    """
    me = cloth.data
    n_verts = len(me.vertices)
    mod = cloth.modifiers.new("Cloth", "CLOTH")
    s = mod.settings
    c = mod.collision_settings
    s.quality = quality
    s.mass = total_mass / n_verts  # Blender's mass is per vertex (kg)
    # Air: Blender's drag force is -0.01 * air_damping * v per vertex in solver units
    # (SIM_mass_spring_force_drag). drape: -drag * area * v, per vertex area share.
    drag_per_vertex = drag * area / n_verts  # kg/s
    s.air_damping = drag_per_vertex * SOLVER_UNIT_S / 0.01
    c.use_collision = True
    c.use_self_collision = False  # Blender's default; drape's scenes here have none either
    c.distance_min = BLENDER_DISTANCE_MIN_FLOOR

    avg_len = avg_spring_len(me)

    time_scale = 1.0
    if model == "matched":
        # Make one solver unit SOLVER_UNIT_S seconds while a frame is 1/fps s.
        time_scale = 1.0 / (fps * SOLVER_UNIT_S)
        t2 = SOLVER_UNIT_S ** 2
        # Linear spring: k = stiffness / avg_spring_len per spring (solver units).
        # For axis-aligned grid springs the membrane stiffness ~= k, so k = stretch.
        k_spring = stretch * t2
        s.tension_stiffness = k_spring * avg_len
        s.compression_stiffness = k_spring * avg_len
        s.shear_stiffness = k_spring * avg_len
        # Angular bending: torque = bending * restlen * 0.1 * angle. A discrete hinge of
        # rigidity D on a right-triangle grid has about 3 D per radian.
        s.bending_stiffness = 3.0 * bending * t2 / (0.1 * hinge_spacing)
        # Damping: drape's is stiffness-proportional, c = damping * k (kg/s per spring).
        c_spring = damping * stretch * SOLVER_UNIT_S
        s.tension_damping = c_spring
        s.compression_damping = c_spring
        s.shear_damping = c_spring
        # Angular bending is explicit in Blender (no Jacobian), so its default damping
        # (0.5) explodes at this vertex mass. drape's bending damping is
        # damping * hinge stiffness, i.e. ~1e-9 in these units: use 0.
        s.bending_damping = 0.0
    s.time_scale = time_scale
    return mod, time_scale, avg_len


def cloth_settings(mod, n_verts):
    """The cloth modifier's settings as the JSON reports them (before the colliders')."""
    s = mod.settings
    c = mod.collision_settings
    return {
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
    }


def time_frames(scene, cloth):
    """The timed loop: scene.frame_set(f) for every simulated frame, from a
    cloth at rest on frame_start. Returns wall and process CPU time of the loop,
    the wall time of each frame_set, the solver's CG iteration counts (its
    per-frame average, read after each frame, and the largest) and the set of
    solver statuses seen."""
    scene.frame_set(scene.frame_start)
    depsgraph = bpy.context.evaluated_depsgraph_get()

    def solver_result():
        ev = cloth.evaluated_get(depsgraph)
        r = ev.modifiers["Cloth"].solver_result
        return r.status, r.avg_iterations, r.max_iterations

    per_frame = []
    iters_avg = []
    iters_max = 0
    statuses = set()
    cpu0 = time.process_time()
    t0 = time.perf_counter()
    for f in range(scene.frame_start + 1, scene.frame_end + 1):
        tf = time.perf_counter()
        scene.frame_set(f)
        per_frame.append(time.perf_counter() - tf)
        st, avg_it, max_it = solver_result()
        statuses.update(st)
        iters_avg.append(avg_it)
        iters_max = max(iters_max, max_it)
    wall = time.perf_counter() - t0
    cpu = time.process_time() - cpu0
    return {"wall": wall, "cpu": cpu, "per_frame": per_frame,
            "iters_avg": iters_avg, "iters_max": iters_max, "statuses": statuses}


def world_positions(ob):
    """The evaluated object's vertex positions in world space, as (x, y, z) tuples."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    ev = ob.evaluated_get(depsgraph)
    me = ev.to_mesh()
    co = array("f", bytes(4 * 3 * len(me.vertices)))
    me.vertices.foreach_get("co", co)
    ev.to_mesh_clear()
    m = ev.matrix_world
    (a, b, c, tx), (d, e, f, ty), (g, h, i, tz) = (tuple(m[r]) for r in range(3))
    return [(a * x + b * y + c * z + tx, d * x + e * y + f * z + ty, g * x + h * y + i * z + tz)
            for x, y, z in zip(co[0::3], co[1::3], co[2::3])]


def read_back_frames(scene, ob, cache):
    """Yields (k, positions) for every frame k = 0 .. frames (k = 0: the rest
    state), read back from the cloth's point cache after the timed loop, so
    that measuring never adds to the timed frames. Call it with the scene on
    its last simulated frame; leaves it there.

    With a collider in the scene Blender flags the in-memory cache outdated
    while it simulates, and going back to the start frame would then clear it
    and simulate every frame again. `ptcache.bake_from_cache` first marks the
    frames already computed as baked, so that each frame_set reads its frame.
    The last frame read back must equal the state the timed loop left."""
    last = world_positions(ob)
    if not cache.is_baked:
        with bpy.context.temp_override(scene=scene, active_object=ob, object=ob,
                                       point_cache=cache):
            bpy.ops.ptcache.bake_from_cache()
    for k, f in enumerate(range(scene.frame_start, scene.frame_end + 1)):
        scene.frame_set(f)
        pts = world_positions(ob)
        if f == scene.frame_end and pts != last:
            raise RuntimeError("the last frame read back from the cache differs from "
                               "the simulated one")
        yield k, pts


def no_cloth_frame_stepping(scene, mod):
    """Depsgraph cost of stepping the same frames with the cloth modifier
    switched off (colliders still evaluated); reported, never subtracted.
    Leaves the modifier off."""
    mod.show_viewport = False
    scene.frame_set(scene.frame_start)
    t0 = time.perf_counter()
    for f in range(scene.frame_start + 1, scene.frame_end + 1):
        scene.frame_set(f)
    return time.perf_counter() - t0


def threads(scene):
    """Blender's thread settings and the CPUs this process may use."""
    return {
        "render_threads_mode": scene.render.threads_mode,
        "render_threads": scene.render.threads,
        "os_cpu_count": os.cpu_count(),
        "sched_affinity": len(os.sched_getaffinity(0)),
    }


def cpu_model():
    """The CPU's model name from /proc/cpuinfo."""
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()
