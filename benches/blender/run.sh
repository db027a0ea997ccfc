#!/usr/bin/env bash
# Blender peer benchmark of one of drape's scenes: runs a scene script N times
# (no `nice`: this is the measurement) and prints each run's wall time and
# penetration, then the raw wall times, their median, min and max. The script
# is drape_sphere.py (scenes/drape_sphere.toml, the default) or tablecloth.py
# (scenes/tablecloth.toml). Usage:
#
#   benches/blender/run.sh [-s SCRIPT] [-n RUNS] [-o OUTDIR] [-t THREADS] [-- script options]
#
#   -s SCRIPT   drape_sphere.py (default) or tablecloth.py, beside this file
#   -n RUNS     repetitions (default 3)
#   -o OUTDIR   where the per-run JSON and log files go (default benches/blender/results)
#   -t THREADS  passed to blender -t (default 0 = all cores)
#   after --    e.g. --fps 24 --quality 5 --model default (drape_sphere.py),
#               --resolution 64 --quality 9 --model matched --frames 30 (tablecloth.py)
#
# Needs Debian's blender package (3.4): apt-get install -y blender
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
script=drape_sphere.py
runs=3
outdir="$here/results"
threads=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    -s) script="$2"; shift 2 ;;
    -n) runs="$2"; shift 2 ;;
    -o) outdir="$2"; shift 2 ;;
    -t) threads="$2"; shift 2 ;;
    --) shift; break ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
    *) echo "unknown option $1 (script options go after --)" >&2; exit 2 ;;
  esac
done
script_args=("$@")
# The file names' tag: the script's options, after the scene's name for the tablecloth.
case "$(basename "$script")" in
  drape_sphere.py) script=drape_sphere.py; prefix="" ;;
  tablecloth.py) script=tablecloth.py; prefix="tablecloth_" ;;
  *) echo "unknown script $script (drape_sphere.py or tablecloth.py)" >&2; exit 2 ;;
esac

command -v blender >/dev/null || { echo "blender not found: apt-get install -y blender" >&2; exit 1; }
mkdir -p "$outdir"
tag="$prefix$(printf '%s' "${script_args[*]:-default}" | tr -c 'A-Za-z0-9._-' '_')"
stamp="$(date +%Y%m%d-%H%M%S)"
blender --version | head -1
echo "runs=$runs threads=$threads args: ${script_args[*]:-(defaults)}"

files=()
for i in $(seq 1 "$runs"); do
  out="$outdir/${stamp}_${tag}_run$i.json"
  log="$outdir/${stamp}_${tag}_run$i.log"
  if ! blender -b --factory-startup -t "$threads" --python "$here/$script" -- \
      "${script_args[@]}" --out "$out" >"$log" 2>&1 || [[ ! -s "$out" ]]; then
    echo "run $i failed, see $log" >&2
    exit 1
  fi
  files+=("$out")
  python3 - "$out" "$i" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
frame = d["max_penetration_frame"]
if d["scene"] == "tablecloth":
    print(f"run {sys.argv[2]}: wall_s={d['wall_s']:.3f} cpu_s={d['cpu_s']:.3f} "
          f"frames={d['frames']} quality={d['quality']} substeps={d['substeps_total']} "
          f"max_penetration_m={d['max_penetration_m']:.5f} "
          f"(frame {frame if frame is not None else '-'}, {d['max_penetration_obstacle'] or '-'}) "
          f"final_penetration_m={d['final_penetration_m']:.5f} "
          f"through_table_top={d['max_vertices_through_table_top']} "
          f"lowest_z={d['lowest_z']:.4f} centre_z={d['final_centre_z']:.4f} "
          f"cg_iters_mean={d['cg_iterations']['per_frame_avg_mean']:.2f}")
else:
    print(f"run {sys.argv[2]}: wall_s={d['wall_s']:.3f} cpu_s={d['cpu_s']:.3f} "
          f"frames={d['frames']} fps={d['fps']:g} quality={d['quality']} "
          f"substeps={d['substeps_total']} lowest_z={d['lowest_z']:.4f} "
          f"cg_iters_mean={d['cg_iterations']['per_frame_avg_mean']} "
          f"max_penetration_m={d['max_penetration_m']:.5f} "
          f"(frame {frame if frame is not None else '-'})")
PY
done

python3 - "${files[@]}" <<'PY'
import json, statistics, sys
ds = [json.load(open(f)) for f in sys.argv[1:]]
walls = [d["wall_s"] for d in ds]
d = ds[0]
tablecloth = d["scene"] == "tablecloth"
if tablecloth:
    print(f"blender {d['blender_version']} model={d['model']} diagonals={d['diagonals']} "
          f"resolution={d['resolution']} vertices={d['vertices']} triangles={d['triangles']} "
          f"fps={d['fps']:g} frames={d['frames']} quality={d['quality']} "
          f"substep_s={d['substep_s']:.5f} substeps={d['substeps_total']} "
          f"threads={d['threads']['render_threads']}")
else:
    print(f"blender {d['blender_version']} model={d['model']} diagonals={d['diagonals']} "
          f"vertices={d['vertices']} triangles={d['triangles']} fps={d['fps']:g} "
          f"frames={d['frames']} quality={d['quality']} substeps={d['substeps_total']} "
          f"threads={d['threads']['render_threads']}")
print("raw wall_s: " + " ".join(f"{w:.3f}" for w in walls))
print(f"median wall_s: {statistics.median(walls):.3f}  (min {min(walls):.3f}, max {max(walls):.3f})")
if tablecloth:
    pens = sorted({x["max_penetration_m"] for x in ds})
    print(f"max_penetration_m: {pens[0]:.5f}" if len(pens) == 1 else
          "max_penetration_m differs between runs: " + " ".join(f"{p:.5f}" for p in pens))
PY
