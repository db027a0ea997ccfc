#!/usr/bin/env bash
# A GarmentCode example (scenes/garmentcode/NAME.toml, the shirt by default)
# against Blender 3.4, side by side: writes the shared inputs (the unsewn
# garment at frame 0 with its `l` sewing pairs, the body turned z-up), runs
# drape on garmentcode_rest.toml and Blender on skirt.py N times each, the
# two alternated (no `nice`: this is the measurement), measures both frame
# sets the same way (skirt_measure.py for the seams and the rest,
# garment-check.py for penetration, stretch and the last move) and prints
# the table. Usage, from anywhere:
#
#   benches/blender/garmentcode.sh [-p NAME] [-n RUNS] [-d DRAPE] [-w WORKDIR]
#                                  [-s CAP] [-q QUALITY] [-T SECONDS] [-P PYTHON] [-G CHECK]
#
#   -p NAME     the pattern scene scenes/garmentcode/NAME.toml (default shirt)
#   -n RUNS     timed runs of each simulator (default 3)
#   -d DRAPE    the drape binary (default: `drape` on PATH)
#   -w WORKDIR  inputs, frames, logs and JSON (default benches/blender/garmentcode, git-ignored)
#   -s CAP      Blender's sewing_force_max in N per sewn pair (default 0: no cap,
#               Blender's default; `drape`: drape's largest initial pull of a pair)
#   -q QUALITY  Blender's substeps per frame (default: drape's steps per frame)
#   -T SECONDS  Blender's simulated time (default: drape's, up to the frame it
#               came to rest on)
#   -P PYTHON   a python3 with numpy and libigl, for garment-check.py (default python3)
#   -G CHECK    garment-check.py (default ../shared/tools/garment-check.py beside the repository)
#
# Needs Debian's blender package (3.4): apt-get install -y blender
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
name=shirt
runs=3
drape="drape"
work="$here/garmentcode"
cap=0
quality=()
duration=""
py=python3
check="$root/../shared/tools/garment-check.py"
while [[ $# -gt 0 ]]; do
  case "$1" in
    -p) name="$2"; shift 2 ;;
    -n) runs="$2"; shift 2 ;;
    -d) drape="$2"; shift 2 ;;
    -w) work="$2"; shift 2 ;;
    -s) cap="$2"; shift 2 ;;
    -q) quality=(--quality "$2"); shift 2 ;;
    -T) duration="$2"; shift 2 ;;
    -P) py="$2"; shift 2 ;;
    -G) check="$2"; shift 2 ;;
    -h|--help) sed -n '2,26p' "$0"; exit 0 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
command -v blender >/dev/null || { echo "blender not found: apt-get install -y blender" >&2; exit 1; }
command -v "$drape" >/dev/null || { echo "drape not found: cargo install --path . or -d PATH" >&2; exit 1; }
[[ -f "$check" ]] || { echo "garment-check.py not found at $check: give -G" >&2; exit 1; }
"$py" -c 'import numpy, igl' || { echo "$py lacks numpy or libigl: give -P" >&2; exit 1; }
drape="$(command -v "$drape")"
pattern_scene="$root/scenes/garmentcode/$name.toml"
[[ -f "$pattern_scene" ]] || { echo "no pattern scene $pattern_scene" >&2; exit 1; }
mkdir -p "$work"
work="$(cd "$work" && pwd)"

# ------------------------------------------------------------------ inputs
# The garment: frame 0 of the pattern scene (the panels placed around the
# body, the stitches open as `l` pairs). The body: the scene's obstacle file
# turned z-up as the scene turns it.
tmp="$work/tmp"
rm -rf "$tmp" && mkdir -p "$tmp"
"$drape" run "$pattern_scene" --no-record --obj-dir "$tmp/garment" \
    --set simulation.duration=0.034 -q >"$tmp/garment.log" 2>&1
# Where two panels start joined (a centre front or back seam whose sides
# coincide), frame 0 holds pairs of `v` lines at one position. drape's OBJ
# reader keeps two `v` lines an `l` pairs distinct, but took equal positions
# for one vertex when this bench was measured; each repeat is still moved by
# the least step of its x (one unit in the last place: 5e-324 m at x = 0,
# under 1e-16 m on the shirt, less than its neighbours along the seam
# already lie apart), as measured, so both simulators read the same
# distinct vertices.
python3 - "$tmp/garment/frame_00000.obj" "$work/garment.obj" <<'EOF'
import math, sys
seen, moved = set(), 0
with open(sys.argv[1]) as src, open(sys.argv[2], "w") as out:
    for line in src:
        p = line.split()
        if p and p[0] == "v":
            x, y, z = (float(t) for t in p[1:4])
            if (x, y, z) in seen:
                while (x, y, z) in seen:
                    x = math.nextafter(x, math.inf)
                moved += 1
                line = f"v {x!r} {y!r} {z!r}\n"
            seen.add((x, y, z))
        out.write(line)
print(f"garment.obj: {moved} vertices at the position of another moved by one unit in the last place of x")
EOF
rm -rf "$tmp"

scene="$here/garmentcode_rest.toml"
if [[ "$work" != "$here/garmentcode" ]]; then
  # garmentcode_rest.toml reads garmentcode/*.obj beside itself: give it a copy that reads $work.
  sed "s#\"garmentcode/#\"$work/#" "$here/garmentcode_rest.toml" >"$work/garmentcode_rest.toml"
  scene="$work/garmentcode_rest.toml"
fi
# The body z-up, and the check that garmentcode_rest.toml simulates what the
# pattern scene does.
body_source="$(python3 - "$pattern_scene" "$here/garmentcode_rest.toml" "$work/body.obj" <<'EOF'
import os, sys, tomllib
pattern_path, rest_path, body_out = sys.argv[1:]
pat = tomllib.load(open(pattern_path, "rb"))
rest = tomllib.load(open(rest_path, "rb"))
diff = []
for table in ("simulation", "material"):
    if pat[table] != rest[table]:
        diff.append(f"[{table}]: {pat[table]} != {rest[table]}")
if pat["cloth"].get("sewing") != rest["cloth"].get("sewing"):
    diff.append(f"[cloth.sewing]: {pat['cloth'].get('sewing')} != {rest['cloth'].get('sewing')}")
for key in ("thickness", "friction_static", "friction_kinetic"):
    if pat["obstacle"][0].get(key) != rest["obstacle"][0].get(key):
        diff.append(f"obstacle {key}: {pat['obstacle'][0].get(key)} != {rest['obstacle'][0].get(key)}")
for key in ("pin", "air", "self_collision", "wind"):
    if (key in pat) != (key in rest):
        diff.append(f"[{key}] in one scene only")
ob = pat["obstacle"][0]
if len(pat["obstacle"]) != 1 or ob.get("shape") != "mesh" or ob.get("scale", 1.0) != 1.0 \
        or ob.get("rotation") != [90.0, 0.0, 0.0] or ob.get("position", [0.0, 0.0, 0.0]) != [0.0, 0.0, 0.0]:
    diff.append(f"the body is not one mesh obstacle in metres turned y up -> z up: {ob}")
if diff:
    sys.exit("garmentcode_rest.toml differs from " + pattern_path + ":\n  " + "\n  ".join(diff))
# (x, y, z) -> (x, -z, y): the obstacle's rotation [90, 0, 0], exactly.
src = os.path.join(os.path.dirname(pattern_path), ob["path"])
with open(src) as fh, open(body_out, "w") as out:
    out.write(f"# {os.path.basename(src)} turned z-up: (x, y, z) -> (x, -z, y)\n")
    for line in fh:
        p = line.split()
        if p and p[0] == "v":
            x, y, z = p[1:4]
            z = z[1:] if z.startswith("-") else "-" + z
            out.write(f"v {x} {z} {y}\n")
        elif p and p[0] in ("f", "o", "g"):
            out.write(line)
print(os.path.abspath(src))
EOF
)"
blender --version | head -1
"$drape" --version 2>/dev/null || true
echo "pattern: $name; inputs: $(sha256sum "$work/garment.obj" | cut -c1-16) garment.obj, $(sha256sum "$work/body.obj" | cut -c1-16) body.obj"
echo "runs=$runs cap=$cap nproc=$(nproc) load: $(cut -d' ' -f1-3 /proc/loadavg)"

# drape's values for skirt.py (--params): the scene's, the preset's moduli as
# `drape check` states them (Blender's springs take one stiffness: the mean
# of warp and weft), its time step (Blender's substeps per frame: the same).
"$drape" check "$scene" >"$work/check.txt"
python3 - "$scene" "$work/check.txt" "$work/params.json" <<'EOF'
import json, re, sys, tomllib
scene_path, check_path, out = sys.argv[1:]
sc = tomllib.load(open(scene_path, "rb"))
text = open(check_path).read()
num = r"([0-9.eE+-]+)"
find = lambda pat: float(re.search(pat, text).group(1))
warp, weft = find(r"warp " + num + " N/m"), find(r"weft " + num + " N/m")
ob = sc["obstacle"][0]
params = {
    "gravity": sc["simulation"]["gravity"][2],
    "density": find(r"material: density " + num),
    "stretch": 0.5 * (warp + weft),
    "bending": find(r"rigidity " + num + " N m"),
    "damping": sc["material"]["damping"],
    "drag": sc.get("air", {}).get("drag", 0.0),
    "sewing_stiffness": sc["cloth"]["sewing"]["stiffness"],
    "weld_gap": sc["cloth"]["sewing"]["weld_gap"],
    "self_thickness": sc["self_collision"]["thickness"] if "self_collision" in sc else None,
    "body_thickness": ob["thickness"],
    "friction_kinetic": ob["friction_kinetic"],
    "pin_box": None,
    # the step drape takes: a frame over the steps per frame it states
    "dt": 1.0 / (sc["simulation"]["frame_rate"] * find(r"; ([0-9]+) steps per frame")),
    "duration": sc["simulation"]["duration"],
}
json.dump(params, open(out, "w"), indent=1)
print("params:", json.dumps(params))
EOF

# ---------------------------------------------------- drape and Blender, alternated
capargs=()
[[ "$cap" == "drape" ]] || capargs=(--sewing-force-max "$cap")
for i in $(seq 1 "$runs"); do
  "$drape" run "$scene" --no-record -q --summary "$work/drape_run$i.json" >"$work/drape_run$i.log" 2>&1
  if [[ $i -eq 1 ]]; then
    # Blender's schedule from drape's first run: its simulated time (to the
    # frame it came to rest on, or -T) and its weightless phase (until the
    # last seam welded, at most cloth.sewing.weightless).
    read -r bduration weightless < <(python3 - "$work/drape_run1.json" "$scene" "$duration" <<'EOF'
import json, sys, tomllib
d = json.load(open(sys.argv[1]))
sc = tomllib.load(open(sys.argv[2], "rb"))
welds = [s["welded_at"] for s in d["seams"]]
cap = sc["cloth"]["sewing"].get("weightless", 0.0)
weightless = min(cap, max(welds)) if None not in welds else cap
print(sys.argv[3] or d["sim_time"], weightless)
EOF
)
    echo "blender: duration ${bduration} s, weightless ${weightless} s (drape's)"
  fi
  python3 - "$work/drape_run$i.json" "$i" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1]))
welds = [s["welded_at"] for s in d["seams"]]
print(f"drape run {sys.argv[2]}: simulation_wall_s={d['simulation_wall_s']:.3f} "
      f"sim_time={d['sim_time']:.3f} rest={d['rest']} last_weld={max(w or 0 for w in welds):.4f} "
      f"open={sum(w is None for w in welds)} max_penetration={d['max_penetration']}")
EOF
  frames=()
  [[ $i -eq 1 ]] && rm -rf "$work/blender_frames" && frames=(--frames-dir "$work/blender_frames")
  out="$work/blender_run$i.json"
  if ! blender -b --factory-startup -t 0 --python "$here/skirt.py" -- \
      --skirt "$work/garment.obj" --body "$work/body.obj" --params "$work/params.json" \
      --duration "$bduration" --weightless "$weightless" "${capargs[@]}" "${quality[@]}" "${frames[@]}" \
      --out "$out" >"$work/blender_run$i.log" 2>&1 || [[ ! -s "$out" ]]; then
    echo "blender run failed, see $work/blender_run$i.log" >&2
    exit 1
  fi
  python3 - "$out" "$i" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1]))
print(f"blender run {sys.argv[2]}: wall_s={d['wall_s']:.3f} cpu_s={d['cpu_s']:.3f} frames={d['frames']} "
      f"quality={d['quality']} seams_closed_s={d['seams_closed_s']} final_gap_mm={1e3 * d['final_gap_max_m']:.3f} "
      f"cg_mean={d['cg_iterations']['per_frame_avg_mean']:.1f}")
EOF
done
echo "load at the end: $(cut -d' ' -f1-3 /proc/loadavg)"
# drape's frames (a separate run: drape is deterministic).
rm -rf "$work/drape_frames"
"$drape" run "$scene" --no-record -q --obj-dir "$work/drape_frames" \
    --summary "$work/drape_frames.json" >"$work/drape_frames.log" 2>&1

# ----------------------------------------------------------------- measure
weld_gap="$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["weld_gap"])' "$work/params.json")"
for sim in drape blender; do
  python3 "$here/skirt_measure.py" --no-body --frames "$work/${sim}_frames" --weld-gap "$weld_gap" \
      --label "$sim" --out "$work/${sim}_measure.json" >/dev/null
  last=("$work/${sim}_frames"/frame_*.obj)
  n=${#last[@]}
  "$py" "$check" "${last[$((n - 1))]}" "${last[$((n - 2))]}" "$body_source" \
      >"$work/${sim}_check.json"
done
# The deepest vertex inside the body in every frame (libigl's signed distance
# to the body file turned z-up, as garment-check.py measures the last frame).
"$py" - "$body_source" "$work" <<'EOF'
import glob, json, os, sys
import numpy as np
import igl
body, work = sys.argv[1:]
v, f = [], []
for line in open(body):
    p = line.split()
    if p and p[0] == "v":
        v.append([float(t) for t in p[1:4]])
    elif p and p[0] == "f":
        idx = [int(t.split("/")[0]) - 1 for t in p[1:]]
        f += [[idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1)]
v = np.array(v)
bv, bf = np.stack([v[:, 0], -v[:, 2], v[:, 1]], axis=1), np.array(f, dtype=np.int64)
for sim in ("drape", "blender"):
    depth = []
    for path in sorted(glob.glob(os.path.join(work, f"{sim}_frames", "frame_*.obj"))):
        x = np.array([[float(t) for t in line.split()[1:4]] for line in open(path) if line.startswith("v ")])
        depth.append(max(0.0, -float(igl.signed_distance(x, bv, bf)[0].min())))
    worst = int(np.argmax(depth))
    out = {"penetration_max_m": depth[worst], "penetration_max_frame": worst,
           "penetration_per_frame_m": [round(d, 6) for d in depth]}
    json.dump(out, open(os.path.join(work, f"{sim}_frames_penetration.json"), "w"))
    print(f"{sim}: deepest inside the body over {len(depth)} frames {1e3 * depth[worst]:.2f} mm (frame {worst})")
EOF

# ------------------------------------------------------------------- table
python3 - "$work" "$runs" <<'EOF'
import json, os, statistics, sys
work, runs = sys.argv[1], int(sys.argv[2])
load = lambda name: json.load(open(os.path.join(work, name)))
d_runs = [load(f"drape_run{i}.json") for i in range(1, runs + 1)]
b_runs = [load(f"blender_run{i}.json") for i in range(1, runs + 1)]
rows = []
for sim, timed in (("drape", d_runs), ("blender", b_runs)):
    m, c = load(f"{sim}_measure.json"), load(f"{sim}_check.json")
    pen = load(f"{sim}_frames_penetration.json")
    row = {"simulator": sim, "measure": {k: v for k, v in m.items() if k != "per_frame"},
           "garment_check": c, "penetration_frames": pen}
    if sim == "drape":
        welds = [s["welded_at"] for s in timed[0]["seams"]]
        row.update({
            "model": "drape (implicit Euler, sewing springs then weld, weightless while a seam is open)",
            "wall_s": [r["simulation_wall_s"] for r in timed],
            "simulated_s": timed[0]["sim_time"],
            "seams_closed_s": max(welds) if None not in welds else None,
            "seams_closed_what": "every stitch welded",
            "at_rest_s": timed[0]["rest"]["time"] if timed[0]["rest"]["at_rest"] else None,
            "vertices": timed[0]["vertices"]["max"],
            "steps": timed[0]["steps"],
        })
    else:
        rest = m["rest_frame"]
        row.update({
            "model": f"Blender {timed[0]['blender_version']}, sewing springs "
                     f"(sewing_force_max {timed[0]['settings']['sewing_force_max_n']:.4g} N), "
                     f"gravity off for {timed[0]['weightless_s']:.3f} s",
            "wall_s": [r["wall_s"] for r in timed],
            "cpu_s": [r["cpu_s"] for r in timed],
            "simulated_s": timed[0]["simulated_s"],
            "seams_closed_s": m["seams_closed_s"],
            "seams_closed_what": f"every pair within {1e3 * m['weld_gap_m']:.0f} mm",
            "at_rest_s": m["rest_s"],
            "wall_to_rest_s": [sum(r["per_frame_wall_s"]["all"][:rest]) for r in timed] if rest else None,
            "vertices": timed[0]["vertices"],
            "substeps": timed[0]["substeps_total"],
            "cg_iterations_mean": timed[0]["cg_iterations"]["per_frame_avg_mean"],
            "runs_identical": all(r["gap_max_per_frame_m"] == timed[0]["gap_max_per_frame_m"] for r in timed),
        })
    row["wall_s_median"] = statistics.median(row["wall_s"])
    rows.append(row)
ratio = [b / d for b, d in zip(rows[1]["wall_s"], rows[0]["wall_s"])]
summary = {"runs": runs, "rows": rows, "blender_over_drape_wall_per_pair": ratio}
with open(os.path.join(work, "summary.json"), "w") as fh:
    json.dump(summary, fh, indent=1)
    fh.write("\n")
f = lambda x, fmt="{:.3f}": "-" if x is None else fmt.format(x)
mm = lambda x: "-" if x is None else f"{1e3 * x:.2f}"
print()
print("| | wall s, median (runs) | simulated s | seams closed, s (frames) | largest gap after closing / at the end, mm "
      "| at rest, s (frames) | inside the body: end, mm (largest over the frames) | p95 stretch | last move, mm | vertices |")
print("|---|---|---|---|---|---|---|---|---|---|")
for r in rows:
    m, c = r["measure"], r["garment_check"]
    print(f"| {r['simulator']} | {r['wall_s_median']:.2f} ({', '.join(f'{w:.2f}' for w in r['wall_s'])}) "
          f"| {r['simulated_s']:.3f} | {f(r['seams_closed_s'])}, {r['seams_closed_what']} ({f(m['seams_closed_s'])}) "
          f"| {mm(m['gap_max_after_closing_m'])} / {mm(m['final_gap_max_m'])} "
          f"| {f(r['at_rest_s'])} ({f(m['rest_s'])}) | {c.get('pen_max_mm')} ({mm(r['penetration_frames']['penetration_max_m'])}, "
          f"frame {r['penetration_frames']['penetration_max_frame']}) | {c.get('stretch_p95')} "
          f"| {c.get('last_move_mm')} | {r['vertices']} |")
print(f"\nBlender / drape wall, run by run: {', '.join(f'{x:.2f}' for x in ratio)}")
if rows[1]["wall_to_rest_s"]:
    print(f"Blender's wall to its rest frame: {', '.join(f'{x:.2f}' for x in rows[1]['wall_to_rest_s'])}")
print(f"summary: {os.path.join(work, 'summary.json')}")
EOF
