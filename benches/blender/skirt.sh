#!/usr/bin/env bash
# The skirt against Blender 3.4, side by side, one after the other: writes the shared
# inputs (the unsewn skirt OBJ and the mannequin at rest as an OBJ), runs drape
# on skirt_rest.toml and Blender on skirt.py N times each (no `nice`: this is
# the measurement), measures seams and penetration of both the same way
# (skirt_measure.py) and prints the table. Usage, from anywhere:
#
#   benches/blender/skirt.sh [-n RUNS] [-d DRAPE] [-w WORKDIR] [-s CAP]... [-R]
#
#   -n RUNS     timed repetitions of each simulator and setting (default 3)
#   -d DRAPE    the drape binary (default: `drape` on PATH)
#   -w WORKDIR  inputs, frames, logs and JSON (default benches/blender/skirt, git-ignored)
#   -s CAP      Blender's sewing_force_max in N per sewn pair: a number (0 = no cap,
#               Blender's default) or `drape` (drape's largest initial pull of a
#               pair); repeatable; default: -s 0 -s drape
#   -R          skip the seam-closing runs at one substep per frame
#
# Needs Debian's blender package (3.4): apt-get install -y blender
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
runs=3
drape="drape"
work="$here/skirt"
caps=()
fine=1
while [[ $# -gt 0 ]]; do
  case "$1" in
    -n) runs="$2"; shift 2 ;;
    -d) drape="$2"; shift 2 ;;
    -w) work="$2"; shift 2 ;;
    -s) caps+=("$2"); shift 2 ;;
    -R) fine=0; shift ;;
    -h|--help) sed -n '2,19p' "$0"; exit 0 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
[[ ${#caps[@]} -gt 0 ]] || caps=(0 drape)
command -v blender >/dev/null || { echo "blender not found: apt-get install -y blender" >&2; exit 1; }
command -v "$drape" >/dev/null || { echo "drape not found: cargo install --path . or -d PATH" >&2; exit 1; }
drape="$(command -v "$drape")"
mkdir -p "$work"
work="$(cd "$work" && pwd)"

# ------------------------------------------------------------------ inputs
# The skirt: frame 0 of scenes/skirt.toml (two panels wrapped on the 0.21 m
# cylinder, seams open, `l` pairs). The body: the mannequin's skinned mesh at
# t = 0 (its keys start at 0.5 s; the arms are held 25 deg out from t = 0).
tmp="$work/tmp"
rm -rf "$tmp" && mkdir -p "$tmp"
(cd "$root" && "$drape" run scenes/skirt.toml --no-record --obj-dir "$tmp/skirt" \
    --set simulation.duration=0.034 -q >"$tmp/skirt.log" 2>&1)
cp "$tmp/skirt/frame_00000.obj" "$work/skirt.obj"
(cd "$root" && "$drape" body-frames scenes/skirt.toml "$tmp/body" \
    --set obstacle.0.surface=skinned_mesh --set simulation.duration=0.034 >"$tmp/body.log" 2>&1)
cp "$tmp/body/frame_0000.obj" "$work/body.obj"
rm -rf "$tmp"
blender --version | head -1
"$drape" --version 2>/dev/null || true
echo "inputs: $(sha256sum "$work/skirt.obj" | cut -c1-16) skirt.obj, $(sha256sum "$work/body.obj" | cut -c1-16) body.obj"
echo "runs=$runs caps=${caps[*]} nproc=$(nproc) load: $(cut -d' ' -f1-3 /proc/loadavg)"

scene="$here/skirt_rest.toml"
if [[ "$work" != "$here/skirt" ]]; then
  # skirt_rest.toml reads skirt/*.obj beside itself: give it a copy that reads $work.
  sed "s#\"skirt/#\"$work/#" "$here/skirt_rest.toml" >"$work/skirt_rest.toml"
  scene="$work/skirt_rest.toml"
fi

# ------------------------------------------------------------------- drape
for i in $(seq 1 "$runs"); do
  "$drape" run "$scene" --no-record -q --summary "$work/drape_run$i.json" >"$work/drape_run$i.log" 2>&1
  python3 - "$work/drape_run$i.json" "$i" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1]))
print(f"drape run {sys.argv[2]}: simulation_wall_s={d['simulation_wall_s']:.3f} "
      f"welded_at={[s['welded_at'] for s in d['seams']]} max_penetration={d['max_penetration']}")
EOF
done
# The frames for skirt_measure.py (a separate run: drape is deterministic).
rm -rf "$work/drape_frames"
"$drape" run "$scene" --no-record -q --obj-dir "$work/drape_frames" \
    --summary "$work/drape_frames.json" >"$work/drape_frames.log" 2>&1
python3 "$here/skirt_measure.py" --body "$work/body.obj" --frames "$work/drape_frames" \
    --label drape --out "$work/drape_measure.json"

# ----------------------------------------------------------------- blender
for cap in "${caps[@]}"; do
  capargs=()
  [[ "$cap" == "drape" ]] || capargs=(--sewing-force-max "$cap")
  for i in $(seq 1 "$runs"); do
    frames=()
    [[ $i -eq 1 ]] && frames=(--frames-dir "$work/blender_cap${cap}_frames")
    [[ $i -eq 1 ]] && rm -rf "$work/blender_cap${cap}_frames"
    out="$work/blender_cap${cap}_run$i.json"
    if ! blender -b --factory-startup -t 0 --python "$here/skirt.py" -- \
        --skirt "$work/skirt.obj" --body "$work/body.obj" "${capargs[@]}" "${frames[@]}" \
        --out "$out" >"$work/blender_cap${cap}_run$i.log" 2>&1 || [[ ! -s "$out" ]]; then
      echo "blender run failed, see $work/blender_cap${cap}_run$i.log" >&2
      exit 1
    fi
    python3 - "$out" "$cap" "$i" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1]))
print(f"blender cap={sys.argv[2]} run {sys.argv[3]}: wall_s={d['wall_s']:.3f} cpu_s={d['cpu_s']:.3f} "
      f"seams_closed_s={d['seams_closed_s']} final_gap_mm={1e3 * d['final_gap_max_m']:.3f} "
      f"sewing_force_max_n={d['settings']['sewing_force_max_n']:.4g}")
EOF
  done
  python3 "$here/skirt_measure.py" --body "$work/body.obj" --frames "$work/blender_cap${cap}_frames" \
      --label "blender cap $cap" --out "$work/blender_cap${cap}_measure.json"
  if [[ $fine -eq 1 ]]; then
    # When the seams close, to one substep: one frame per substep (210 fps,
    # quality 1: the same 4.76 ms step and time scale per step as 30 fps x 7).
    blender -b --factory-startup -t 0 --python "$here/skirt.py" -- \
        --skirt "$work/skirt.obj" --body "$work/body.obj" "${capargs[@]}" --fps 210 \
        --out "$work/blender_cap${cap}_fine.json" >"$work/blender_cap${cap}_fine.log" 2>&1
  fi
done

# ------------------------------------------------------------------- table
python3 - "$work" "$runs" "$fine" "${caps[@]}" <<'EOF'
import json, os, statistics, sys
work, runs, fine, caps = sys.argv[1], int(sys.argv[2]), sys.argv[3] == "1", sys.argv[4:]
load = lambda name: json.load(open(os.path.join(work, name)))
rows = []
d_runs = [load(f"drape_run{i}.json") for i in range(1, runs + 1)]
dm = load("drape_measure.json")
welds = [s["welded_at"] for s in d_runs[0]["seams"]]
rows.append({
    "model": "drape (implicit Euler, sewing springs then weld)",
    "wall_s": [r["simulation_wall_s"] for r in d_runs],
    "seams_closed_s": max(welds) if None not in welds else None,
    "seams_closed_resolution_s": d_runs[0]["dt"],
    "seams_closed_frame_s": dm["seams_closed_s"],
    "gap_after_closing_mm": 1e3 * dm["gap_max_after_closing_m"],
    "penetration_final_mm": 1e3 * dm["penetration_final_m"],
    "penetration_max_frames_mm": 1e3 * dm["penetration_max_m"],
    "penetration_max_steps_mm": 1e3 * d_runs[0]["max_penetration"],
    "clearance_min_mm": 1e3 * dm["clearance_min_m"],
    "clearance_final_mm": 1e3 * dm["clearance_min_final_m"],
    "final_lowest_z_m": dm["final_lowest_z"],
    "vertices": d_runs[0]["vertices"]["max"],
})
for cap in caps:
    b_runs = [load(f"blender_cap{cap}_run{i}.json") for i in range(1, runs + 1)]
    bm = load(f"blender_cap{cap}_measure.json")
    fine_d = load(f"blender_cap{cap}_fine.json") if fine else None
    same = all(r["gap_max_per_frame_m"] == b_runs[0]["gap_max_per_frame_m"] for r in b_runs)
    rows.append({
        "model": f"Blender {b_runs[0]['blender_version']}, sewing_force_max "
                 f"{b_runs[0]['settings']['sewing_force_max_n']:.4g} N ({cap})",
        "wall_s": [r["wall_s"] for r in b_runs],
        "cpu_s": [r["cpu_s"] for r in b_runs],
        "seams_closed_s": fine_d["seams_closed_s"] if fine else bm["seams_closed_s"],
        "seams_closed_resolution_s": fine_d["substep_s"] if fine else 1 / b_runs[0]["fps"],
        "seams_closed_frame_s": bm["seams_closed_s"],
        "gap_after_closing_mm": None if bm["gap_max_after_closing_m"] is None
        else 1e3 * bm["gap_max_after_closing_m"],
        "final_gap_mm": 1e3 * bm["final_gap_max_m"],
        "penetration_final_mm": 1e3 * bm["penetration_final_m"],
        "penetration_max_frames_mm": 1e3 * bm["penetration_max_m"],
        "clearance_min_mm": 1e3 * bm["clearance_min_m"],
        "clearance_final_mm": 1e3 * bm["clearance_min_final_m"],
        "final_lowest_z_m": bm["final_lowest_z"],
        "runs_identical": same,
        "cg_iterations_mean": b_runs[0]["cg_iterations"]["per_frame_avg_mean"],
        "vertices": b_runs[0]["vertices"],
    })
for r in rows:
    r["wall_s_median"] = statistics.median(r["wall_s"])
summary = {"runs": runs, "rows": rows}
with open(os.path.join(work, "summary.json"), "w") as fh:
    json.dump(summary, fh, indent=1)
    fh.write("\n")
fmt = lambda x, f="{:.3f}": "-" if x is None else f.format(x)
print()
print("| model | wall s (median; runs) | seams closed, s | gap after, mm | penetration end / max, mm | clearance min, mm |")
print("|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r['model']} | {r['wall_s_median']:.2f} ({', '.join(f'{w:.2f}' for w in r['wall_s'])}) "
          f"| {fmt(r['seams_closed_s'])} (to {1e3 * r['seams_closed_resolution_s']:.2f} ms; frame {fmt(r['seams_closed_frame_s'])}) "
          f"| {fmt(r['gap_after_closing_mm'], '{:.2f}')} "
          f"| {r['penetration_final_mm']:.2f} / {r['penetration_max_frames_mm']:.2f} "
          f"| {r['clearance_min_mm']:.2f} |")
print(f"\nsummary: {os.path.join(work, 'summary.json')}")
EOF
