/* Plain C reference kernels of drape's hinge-spring symplectic Euler step.
 * See kernel.c for the physics and main.c for the driver. */
#ifndef DRAPE_C_KERNEL_H
#define DRAPE_C_KERNEL_H

/* Per-vertex CSR list of neighbour springs: entries off[i]..off[i+1] of the
 * arrays belong to vertex i; each entry is the other end and the spring's rest
 * length, stiffness and damping (a spring appears once in each end's list). */
typedef struct {
    int n;           /* vertices */
    const int *off;  /* n + 1 offsets */
    const int *nbr;  /* other end of each entry */
    const double *rest, *k, *c;
} NeighbourCsr;

/* Springs as elements plus the per-vertex lists of the springs where the vertex
 * is the first (first_*) or the second (second_*) end: drape's own layout. */
typedef struct {
    int n, ns;                          /* vertices, springs */
    const int *a, *b;                   /* ends of each spring */
    const double *rest, *k, *c;         /* per spring */
    const int *first_off, *first;       /* CSR: springs with v[0] == i */
    const int *second_off, *second;     /* CSR: springs with v[1] == i */
} SpringElements;

/* One step, per-vertex gather: every vertex evaluates all its springs itself
 * (so every spring is evaluated twice, once from each end) from (x, v) and
 * writes its new state to (x_new, v_new). Positions and velocities are
 * interleaved xyz, 3 doubles per vertex. */
void step_gather(const NeighbourCsr *g, const double *mass, const double *x,
                 const double *v, double *x_new, double *v_new,
                 const double gravity[3], double dt);

/* One step, drape's two passes: each spring evaluates its force once into
 * f[3 * s] (element pass), then each vertex sums its slots in CSR order, adds
 * gravity and integrates in place (gather pass). */
void step_two_pass(const SpringElements *e, const double *mass, double *x,
                   double *v, double *f, const double gravity[3], double dt);

#endif
