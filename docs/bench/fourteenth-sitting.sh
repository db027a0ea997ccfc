#!/bin/bash
# Issue 14, fourteenth sitting (docs/speed-vs-error.md, "The result"): every
# ladder behind the targets on one engine build, one after another, with
# nothing else running. Usage, from the repository root:
#   cargo build --release && docs/bench/fourteenth-sitting.sh [OUT_DIR]
# Each ladder writes OUT_DIR/NAME/ (report, CSVs, chart) and OUT_DIR/NAME.log.
# The references and floors are cached in OUT_DIR/NAME/cache/; without a cache
# they are computed first (uniform 192 at rest on hanging_sheet_rest and its
# turned-diagonal floor are the longest, tens of minutes each on 2 cores).
set -u
O=${1:-bench-out/s15}
. "$(dirname "$0")/sitting-run.sh"
run cant scenes/cantilever.toml --ladder docs/bench/cantilever.toml --reps 3
run cant-tensor scenes/cantilever.toml --ladder docs/bench/cantilever-tensor.toml --mesh-floor 130 --pattern-floor --reps 3
run cant-80 scenes/cantilever.toml --ladder docs/bench/cantilever-tensor-80.toml --mesh-floor 170 --reps 3
run ds-contact scenes/drape_sphere.toml --duration 0.5333333333333333 --ladder docs/bench/drape_sphere-128-contact.toml --mesh-floor 176 --pattern-floor --reps 3
run tc-impact scenes/tablecloth.toml --duration 0.36666666666666664 --ladder docs/bench/tablecloth-128-impact.toml --reference-resolution 256 --mesh-floor 240 --pattern-floor --reps 3
run hs-strain scenes/hanging_sheet_rest.toml --ladder docs/bench/hanging_sheet_rest-strain.toml --mesh-floor 98 --reps 3
run hs128 scenes/hanging_sheet_rest.toml --ladder docs/bench/hanging_sheet_rest-128-base.toml --reference-resolution 192 --no-floor --pattern-floor --reps 3
run tc scenes/tablecloth.toml --duration 2 --mesh-floor 112 --reps 3
run ds scenes/drape_sphere.toml --duration 2.5 --mesh-floor 98 --reps 3
run ds128 scenes/drape_sphere.toml --duration 1.5 --ladder docs/bench/drape_sphere-128.toml --mesh-floor 176 --reps 3
run tc128 scenes/tablecloth.toml --duration 2 --ladder docs/bench/tablecloth-128-192.toml --mesh-floor 176 --reps 3
run flag scenes/flag.toml --duration 1.5 --reps 2
run hs scenes/hanging_sheet.toml --duration 2 --reps 3
echo "=== all done $(date -u +%T)"
