#!/bin/bash
# Issue 14, sixteenth session (docs/speed-vs-error.md, "Sixteenth session"):
# the one ladder whose runs the direct solver's new choice of factor changes
# (docs/performance.md, "Which factor"), run again on the new engine, nothing
# else running, 5 repetitions round by round. Its reference (uniform 192) and
# pattern floor are the fourteenth sitting's, from its cache: the new choice
# moves uniform 128's rest shape by 2.3e-10 m RMS (docs/performance.md), far
# below the floors. Copy the cache first, e.g.
#   mkdir -p bench-out/s17/hs128 && cp -a bench-out/s16/hs128/cache bench-out/s17/hs128/
# or let the bench compute them (uniform 192 and its turned diagonals, about
# 17 minutes on 2 cores).
# Usage, from the repository root:
#   cargo build --release && docs/bench/sixteenth-sitting.sh [OUT_DIR]
set -u
O=${1:-bench-out/s17}
. "$(dirname "$0")/sitting-run.sh"
run hs128 scenes/hanging_sheet_rest.toml --ladder docs/bench/hanging_sheet_rest-128-base.toml --reference-resolution 192 --no-floor --pattern-floor --reps 5
echo "=== all done $(date -u +%T)"
