#!/bin/bash
# Issue 14, seventeenth session (docs/speed-vs-error.md, "Seventeenth sitting",
# "Is 5 s at rest?"): do the adaptive runs at uniform 128's edges on
# hanging_sheet_rest differ from uniform 128 in their rest shape, or only in
# how far each has settled by the scene's 5 s? The three nearest adaptive runs
# against uniform 128 itself as the reference, at 5 s and at 10 s.
# Output: docs/bench/seventeenth-hanging_sheet_rest-settle-{5,10}s.md.
# Usage, from the repository root: cargo build --release && docs/bench/seventeenth-settle.sh
D=${DRAPE:-./target/release/drape}
for dur in 5 10; do
  "$D" bench scenes/hanging_sheet_rest.toml --ladder docs/bench/hanging_sheet_rest-128-base.toml \
    --rungs "red_green 16 L6 6deg s0.04,red_green 32 L5 8deg s0.04,red_green 64 L3 8deg s0.04" \
    --reference-resolution 128 --no-floor --duration $dur --out-dir bench-out/settle-$dur
done
