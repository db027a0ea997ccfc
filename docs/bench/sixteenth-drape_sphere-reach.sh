#!/bin/bash
# Issue 14, sixteenth session: how soon the ball's impact reaches drape_sphere's
# skirt, and what share of uniform 128's time comes after the first contact.
# Output: docs/bench/sixteenth-drape_sphere-reach.txt. Needs python3 (no numpy).
# Run from the repository root after `cargo build --release`; writes to $OUT
# (default /tmp/reach).
set -euo pipefail
D=${DRAPE:-target/release/drape}
OUT=${OUT:-/tmp/reach}
S=scenes/drape_sphere.toml
W=simulation.duration=0.5333333333333333
mkdir -p "$OUT"
# The same sheet without the ball (everything above [[obstacle]]).
sed '/^\[\[obstacle\]\]/,$d' $S > "$OUT/free.toml"
# 1. uniform 128: per-frame stepping time.
$D run $S -q --no-edges --set adapt.method=none --set cloth.resolution=128 --set $W -o "$OUT/u128-30.rrd"
$D inspect "$OUT/u128-30.rrd" --frames
# 2. uniform 128 with and without the ball, and uniform 32 (red-green 32's
#    base mesh) with it, at the scene's 30 frames a second (four 8.33 ms
#    steps a frame, none retried in these runs), every frame as an OBJ file.
for run in "sphere $S 128" "free $OUT/free.toml 128" "u32 $S 32"; do
  set -- $run
  $D run $2 -q --no-edges --set adapt.method=none --set cloth.resolution=$3 \
    --set $W -o "$OUT/$1.rrd" --obj-dir "$OUT/obj-$1" | tail -1
done
python3 - "$OUT" <<'PY'
import math, sys
out = sys.argv[1]
def load(d, k):
    return [tuple(map(float, l.split()[1:4]))
            for l in open(f"{out}/obj-{d}/frame_{k:05d}.obj") if l.startswith('v ')]
bands = [(0, 0.3), (0.3, 0.5), (0.5, 0.7), (0.7, 0.9), (0.9, 1.2)]
head = "frame  t ms   " + "  ".join(f"r {a}-{b:<4}" for a, b in bands)
# (a) uniform 128 on the ball against the same sheet falling freely: the largest
# distance in each band of material radius (m from the centre), m.
x0 = load('free', 0)
r = [math.hypot(p[0], p[1]) for p in x0]
corners = [0, 128, 16512, 16640]
print("\n(a) uniform 128 with the ball against without it: largest distance per band, m")
print(head + "    corners")
for k in range(8, 17):
    a, b = load('sphere', k), load('free', k)
    d = [math.dist(p, q) for p, q in zip(a, b)]
    row = [max(d[i] for i in range(len(d)) if lo <= r[i] < hi) for lo, hi in bands]
    print(f"{k:3d} {k * 1000 / 30:7.1f}  " + "  ".join(f"{x:9.2e}" for x in row)
          + f"  {max(d[i] for i in corners):9.2e}")
# (b) uniform 32 against uniform 128, both on the ball, at uniform 32's vertices
# (every fourth of uniform 128's): RMS distance per band, m.
key = {(round(p[0], 9), round(p[1], 9)): i for i, p in enumerate(load('sphere', 0))}
c0 = load('u32', 0)
idx = [key[(round(p[0], 9), round(p[1], 9))] for p in c0]
rc = [math.hypot(p[0], p[1]) for p in c0]
print("\n(b) uniform 32 against uniform 128, both on the ball: RMS distance per band, m")
print(head)
for k in range(8, 17):
    a, b = load('u32', k), load('sphere', k)
    d = [math.dist(p, b[j]) for p, j in zip(a, idx)]
    row = []
    for lo, hi in bands:
        s = [d[i] ** 2 for i in range(len(d)) if lo <= rc[i] < hi]
        row.append(math.sqrt(sum(s) / len(s)))
    print(f"{k:3d} {k * 1000 / 30:7.1f}  " + "  ".join(f"{x:9.2e}" for x in row))
PY
