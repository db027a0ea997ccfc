# Sourced by the sittings' scripts (fourteenth- to seventeenth-sitting.sh):
# `run NAME ARGS...` runs `drape bench ARGS... --out-dir $O/NAME` with its output
# in $O/NAME.log, and prints its start (with the load average) and end times.
# $D is the drape binary (DRAPE, default ./target/release/drape), $O the output
# directory (the script's first argument, or its own default).
D=${DRAPE:-./target/release/drape}
mkdir -p "$O"
run() {
  n=$1
  shift
  echo "=== $n start $(date -u +%T) load $(cut -d' ' -f1 /proc/loadavg)"
  echo "drape bench $* --out-dir $O/$n"
  "$D" bench "$@" --out-dir "$O/$n" >"$O/$n.log" 2>&1
  rc=$?
  echo "=== $n end $(date -u +%T) rc=$rc"
}
