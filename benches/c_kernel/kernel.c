/* Plain C reference of drape's hinge-spring symplectic Euler step, f64.
 *
 * Physics per step, the same as drape's `Integrator::SymplecticEuler` with
 * `bending_model = "hinge_spring"`, spring damping and gravity (no drag, no
 * wind, no pins): stretch springs on every edge plus one hinge spring per
 * interior edge, each with the force of `spring_force` in
 * src/physics/forces.rs on its first end a,
 *     d = x_b - x_a, l = |d|, u = d / l,
 *     f_a = u * (k (l - L) + c (v_b - v_a) . u),   f_b = -f_a,
 * (zero when l == 0), gravity m g on each vertex, then
 *     v += dt f / m;  x += dt v.
 *
 * Two kernels, both parallelised with OpenMP over a static schedule:
 * - step_gather: the per-vertex gather the brief asks for; each vertex walks its
 *   neighbour springs and evaluates them itself (2 evaluations per spring, no
 *   scratch memory), writing to separate output arrays;
 * - step_two_pass: drape's own algorithm (one evaluation per spring into a
 *   scratch slot, then a per-vertex sum in CSR order and the update in place).
 */
#include <math.h>

#include "kernel.h"

/* Force on end a of the spring (a, b); see the header comment. */
static inline void spring_force(const double *xa, const double *xb,
                                const double *va, const double *vb,
                                double rest, double k, double c,
                                double out[3]) {
    double d0 = xb[0] - xa[0], d1 = xb[1] - xa[1], d2 = xb[2] - xa[2];
    double len = sqrt(d0 * d0 + d1 * d1 + d2 * d2);
    if (len <= 0.0) {
        out[0] = out[1] = out[2] = 0.0;
        return;
    }
    double u0 = d0 / len, u1 = d1 / len, u2 = d2 / len;
    double rel = (vb[0] - va[0]) * u0 + (vb[1] - va[1]) * u1 + (vb[2] - va[2]) * u2;
    double s = k * (len - rest) + c * rel;
    out[0] = u0 * s;
    out[1] = u1 * s;
    out[2] = u2 * s;
}

void step_gather(const NeighbourCsr *g, const double *mass, const double *x,
                 const double *v, double *x_new, double *v_new,
                 const double gravity[3], double dt) {
    const int n = g->n;
#pragma omp parallel for schedule(static)
    for (int i = 0; i < n; i++) {
        const double *xi = x + 3 * i, *vi = v + 3 * i;
        double f0 = 0.0, f1 = 0.0, f2 = 0.0;
        for (int e = g->off[i]; e < g->off[i + 1]; e++) {
            const int j = g->nbr[e];
            double fe[3];
            spring_force(xi, x + 3 * j, vi, v + 3 * j, g->rest[e], g->k[e], g->c[e], fe);
            f0 += fe[0];
            f1 += fe[1];
            f2 += fe[2];
        }
        const double m = mass[i];
        f0 += gravity[0] * m;
        f1 += gravity[1] * m;
        f2 += gravity[2] * m;
        const double h = dt / m;
        double w0 = vi[0] + f0 * h, w1 = vi[1] + f1 * h, w2 = vi[2] + f2 * h;
        v_new[3 * i + 0] = w0;
        v_new[3 * i + 1] = w1;
        v_new[3 * i + 2] = w2;
        x_new[3 * i + 0] = xi[0] + w0 * dt;
        x_new[3 * i + 1] = xi[1] + w1 * dt;
        x_new[3 * i + 2] = xi[2] + w2 * dt;
    }
}

void step_two_pass(const SpringElements *e, const double *mass, double *x,
                   double *v, double *f, const double gravity[3], double dt) {
    const int n = e->n, ns = e->ns;
#pragma omp parallel
    {
#pragma omp for schedule(static)
        for (int s = 0; s < ns; s++) {
            const int a = e->a[s], b = e->b[s];
            spring_force(x + 3 * a, x + 3 * b, v + 3 * a, v + 3 * b, e->rest[s],
                         e->k[s], e->c[s], f + 3 * s);
        }
        /* implicit barrier: every slot is written before any vertex reads */
#pragma omp for schedule(static)
        for (int i = 0; i < n; i++) {
            double f0 = 0.0, f1 = 0.0, f2 = 0.0;
            for (int q = e->first_off[i]; q < e->first_off[i + 1]; q++) {
                const double *fs = f + 3 * e->first[q];
                f0 += fs[0];
                f1 += fs[1];
                f2 += fs[2];
            }
            for (int q = e->second_off[i]; q < e->second_off[i + 1]; q++) {
                const double *fs = f + 3 * e->second[q];
                f0 -= fs[0];
                f1 -= fs[1];
                f2 -= fs[2];
            }
            const double m = mass[i];
            f0 += gravity[0] * m;
            f1 += gravity[1] * m;
            f2 += gravity[2] * m;
            const double h = dt / m;
            double *vi = v + 3 * i, *xi = x + 3 * i;
            vi[0] += f0 * h;
            vi[1] += f1 * h;
            vi[2] += f2 * h;
            xi[0] += vi[0] * dt;
            xi[1] += vi[1] * dt;
            xi[2] += vi[2] * dt;
        }
    }
}
