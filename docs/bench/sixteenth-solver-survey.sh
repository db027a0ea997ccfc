#!/bin/bash
# Issue 14 / docs/performance.md, "Which factor" (sixteenth session): the direct
# solver's choice of factor, the build before the change (OLD, `25fa6a4`) and
# the build with it (NEW, `d10c340`) in turn on each run, nothing else running.
# Output: docs/bench/sixteenth-solver-survey.log. Usage, from the repository
# root, with both builds' binaries copied aside:
#   OLD=/tmp/drape-old NEW=/tmp/drape-new docs/bench/sixteenth-solver-survey.sh
# The TIPS field stays empty with these builds: it caught the break-evens that a
# scratch build of the rule printed in a first pass
# (sixteenth-solver-survey-scratch.log). Part D is the drape_sphere script.
set -u
OLD=${OLD:-/tmp/drape-old}
NEW=${NEW:-/tmp/drape-new}
S=scenes
echo "== A: hanging_sheet_rest uniform 128, 5 s, old build then new build (one run each) $(date -u +%H:%M:%S) load $(cut -d' ' -f1 /proc/loadavg)"
for b in old new; do
  bin=$OLD; [ $b = new ] && bin=$NEW
  rm -rf /tmp/survey-obj-$b
  $bin run $S/hanging_sheet_rest.toml -q --no-edges --set adapt.method=none --set cloth.resolution=128 --record-every 1000 -o /tmp/hs128-$b.rrd --obj-dir /tmp/survey-obj-$b 2>&1 | tail -1
  echo "   ($b done $(date -u +%H:%M:%S))"
done
echo "== B: survey $(date -u +%H:%M:%S)"
run() { name=$1; scene=$2; shift 2; for b in old new; do
  bin=$OLD; [ $b = new ] && bin=$NEW
  out=$(DRAPE_DEBUG_TIPS=1 $bin run $scene -q --no-record "$@" 2>&1)
  tips=$(echo "$out" | grep -o 'TIPS.*' | sort | uniq -c | sed 's/^ *//' | head -3 | tr '\n' ';')
  s=$(echo "$out" | tail -1)
  wall=$(echo "$s" | grep -o 'in [0-9.]* s wall' | grep -o '[0-9.]*')
  f=$(echo "$s" | grep -o '[0-9]* CG iterations, [0-9]* factorizations ([^)]*)')
  extra=$(echo "$s" | grep -o 'chord angle[^;.]*' | head -1)
  echo "$name | $b | wall $wall s | $f | $extra | $tips"
done; }
run "cantilever (scene)" $S/cantilever.toml
run "cantilever u40" $S/cantilever.toml --set adapt.method=none --set cloth.resolution=40
run "cantilever u80" $S/cantilever.toml --set adapt.method=none --set cloth.resolution=80
run "cantilever tensor 10 L4 r1" $S/cantilever.toml --set adapt.method=tensor --set cloth.resolution=10 --set adapt.max_level=4 --set adapt.refine_angle=1.0 --set adapt.coarsen_angle=0.1
run "hs_rest u64" $S/hanging_sheet_rest.toml --set adapt.method=none --set cloth.resolution=64
run "hs_rest 64 L3 8deg s0.04" $S/hanging_sheet_rest.toml --set adapt.method=red_green --set cloth.resolution=64 --set adapt.max_level=3 --set adapt.refine_angle=8.0 --set adapt.coarsen_angle=0.8 --set adapt.refine_strain=0.04 --set adapt.rollback=false
run "hs_rest 32 L5 8deg s0.04" $S/hanging_sheet_rest.toml --set adapt.method=red_green --set cloth.resolution=32 --set adapt.max_level=5 --set adapt.refine_angle=8.0 --set adapt.coarsen_angle=0.8 --set adapt.refine_strain=0.04 --set adapt.rollback=false
run "tablecloth u128 impact" $S/tablecloth.toml --set adapt.method=none --set cloth.resolution=128 --set simulation.duration=0.36666666666666664
run "drape_sphere u128 contact" $S/drape_sphere.toml --set adapt.method=none --set cloth.resolution=128 --set simulation.duration=0.5333333333333333
run "drape_sphere (scene)" $S/drape_sphere.toml
run "hanging_sheet (scene)" $S/hanging_sheet.toml
run "large_uniform (scene)" $S/large_uniform.toml
run "hs_rest 8 L6 8deg s0.05" $S/hanging_sheet_rest.toml --set adapt.method=red_green --set cloth.resolution=8 --set adapt.max_level=6 --set adapt.refine_angle=8.0 --set adapt.coarsen_angle=0.8 --set adapt.refine_strain=0.05 --set adapt.rollback=false
run "hs_rest 16 L6 6deg s0.04" $S/hanging_sheet_rest.toml --set adapt.method=red_green --set cloth.resolution=16 --set adapt.max_level=6 --set adapt.refine_angle=6.0 --set adapt.coarsen_angle=0.6 --set adapt.refine_strain=0.04 --set adapt.rollback=false
run "tablecloth 32 L4 o0.5 impact" $S/tablecloth.toml --set adapt.method=red_green --set cloth.resolution=32 --set adapt.max_level=4 --set adapt.refine_obstacle=0.5 --set simulation.duration=0.36666666666666664
run "flag (scene)" $S/flag.toml
echo "== D: drape_sphere reach $(date -u +%H:%M:%S)"
DRAPE=$NEW OUT=/tmp/reach docs/bench/sixteenth-drape_sphere-reach.sh > /tmp/reach.txt 2>&1
echo "== end $(date -u +%H:%M:%S)"
