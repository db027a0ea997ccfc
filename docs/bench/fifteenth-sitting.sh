#!/bin/bash
# Issue 14, fifteenth session (docs/speed-vs-error.md, "Fifteenth session"): the
# tablecloth's impact with the sizing budget swept, on the fourteenth sitting's
# engine (the engine did not change between the two), nothing else running,
# with the bench's repetitions run round by round (new in this session). The
# sweep runs three times over, to show how far its time ratios move from one
# run of a ladder to the next.
# Usage, from the repository root:
#   cargo build --release && docs/bench/fifteenth-sitting.sh [OUT_DIR]
# The reference and floors are the fourteenth sitting's tablecloth ladder's
# (both ladders here have its reference): copy its cache, e.g.
#   for n in tc-impact tc-impact-angle tc-impact-angle-2 tc-impact-angle-3 tc-impact-angle-4; do mkdir -p bench-out/s16/$n && cp -a bench-out/s15/tc-impact/cache bench-out/s16/$n/; done
# or let the bench compute them first (uniform 256 and 240 and the turned
# diagonals, about 5 minutes on 2 cores).
set -u
O=${1:-bench-out/s16}
. "$(dirname "$0")/sitting-run.sh"
run tc-impact scenes/tablecloth.toml --duration 0.36666666666666664 --ladder docs/bench/tablecloth-128-impact.toml --reference-resolution 256 --mesh-floor 240 --pattern-floor --reps 5
run tc-impact-angle scenes/tablecloth.toml --duration 0.36666666666666664 --ladder docs/bench/tablecloth-128-impact-angle.toml --reference-resolution 256 --mesh-floor 240 --pattern-floor --reps 5
run tc-impact-angle-2 scenes/tablecloth.toml --duration 0.36666666666666664 --ladder docs/bench/tablecloth-128-impact-angle.toml --reference-resolution 256 --mesh-floor 240 --pattern-floor --reps 5
run tc-impact-angle-3 scenes/tablecloth.toml --duration 0.36666666666666664 --ladder docs/bench/tablecloth-128-impact-angle.toml --reference-resolution 256 --mesh-floor 240 --pattern-floor --reps 5
# Once more after the report gained the per-repetition range of the time ratios:
run tc-impact-angle-4 scenes/tablecloth.toml --duration 0.36666666666666664 --ladder docs/bench/tablecloth-128-impact-angle.toml --reference-resolution 256 --mesh-floor 240 --pattern-floor --reps 5
# The other target ladders of the fourteenth sitting, timed again the same way
# (5 repetitions round by round; their references and floors from that
# sitting's caches: for n in cant-tensor cant-80 hs-strain hs128 ds-contact; do
# mkdir -p bench-out/s16/$n && cp -a bench-out/s15/$n/cache bench-out/s16/$n/; done).
run cant-tensor scenes/cantilever.toml --ladder docs/bench/cantilever-tensor.toml --mesh-floor 130 --pattern-floor --reps 5
run cant-80 scenes/cantilever.toml --ladder docs/bench/cantilever-tensor-80.toml --mesh-floor 170 --reps 5
run ds-contact scenes/drape_sphere.toml --duration 0.5333333333333333 --ladder docs/bench/drape_sphere-128-contact.toml --mesh-floor 176 --pattern-floor --reps 5
run hs-strain scenes/hanging_sheet_rest.toml --ladder docs/bench/hanging_sheet_rest-strain.toml --mesh-floor 98 --reps 5
run hs128 scenes/hanging_sheet_rest.toml --ladder docs/bench/hanging_sheet_rest-128-base.toml --reference-resolution 192 --no-floor --pattern-floor --reps 5
echo "=== all done $(date -u +%T)"
