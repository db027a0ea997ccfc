#!/bin/sh
# Builds and runs the C reference kernel of the hinge-spring symplectic Euler step
# (see kernel.c). Arguments are passed to the driver: [resolution] [steps] [reps],
# default 256 200 7 (a 257 x 257 sheet, 66049 vertices).
# Needs gcc with OpenMP (libgomp, omp.h). The binary goes to target/c_kernel/.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
out="$here/../../target/c_kernel"
mkdir -p "$out"
if ! echo '#include <omp.h>
int main(void) { return omp_get_max_threads() < 1; }' | gcc -fopenmp -x c - -o "$out/omp_probe" 2>/dev/null; then
    echo "gcc cannot build OpenMP programs here (omp.h / libgomp missing?)" >&2
    exit 1
fi
CFLAGS="-O3 -march=native -fopenmp -std=c11 -Wall -Wextra"
gcc $CFLAGS -o "$out/c_kernel" "$here/main.c" "$here/kernel.c" -lm
echo "gcc $(gcc -dumpfullversion) $CFLAGS"
"$out/c_kernel" "$@"
