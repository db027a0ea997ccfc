#!/usr/bin/env bash
# Runs every shipped scene (scenes/*.toml and scenes/hard/*.toml) without
# recording and writes each run's summary, with the timing fields removed, to
# OUT/NAME.json. Two builds' outputs compared with `diff -r` show whether a
# change altered any result:
#
#   scripts/scene-summaries.sh target/release/drape /tmp/new
#   scripts/scene-summaries.sh /path/to/old/drape /tmp/old
#   diff -r /tmp/old /tmp/new
set -euo pipefail
drape=${1:?usage: scene-summaries.sh DRAPE OUT_DIR}
out=${2:?usage: scene-summaries.sh DRAPE OUT_DIR}
cd "$(dirname "$0")/.."
mkdir -p "$out"
for scene in scenes/*.toml scenes/hard/*.toml; do
    name=$(basename "$(dirname "$scene")")-$(basename "$scene" .toml)
    raw="$out/$name.raw.json"
    "$drape" run "$scene" --no-record --quiet --summary "$raw" > /dev/null 2>&1 || true
    if [ -s "$raw" ]; then
        python3 - "$raw" > "$out/$name.json" <<'PY'
import json, sys
TIMING = {"wall_time_s", "simulation_wall_s", "recording_wall_s", "vertex_steps_per_s",
          "recording"}
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items()
                if k not in TIMING and not k.endswith("_s") and not k.endswith("_ms")}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v
print(json.dumps(strip(json.load(open(sys.argv[1]))), indent=1, sort_keys=True))
PY
    else
        echo "no summary" > "$out/$name.json"
    fi
    rm -f "$raw"
    echo "$name done" >&2
done
