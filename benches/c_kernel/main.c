/* Driver of the C reference kernels (kernel.c): builds drape's 257 x 257 sheet
 * (1 m x 1 m, resolution 256, alternating diagonals) with the same springs as
 * `Elements::build` (consistent stretch rule, hinge springs, damping), the same
 * masses and the same rippled start as benches/step.rs, then times STEPS steps
 * REPS times at 1 and 2 OpenMP threads and prints the median vertex-steps/s.
 *
 * Usage: c_kernel [resolution] [steps] [reps]   (defaults 256 200 7)
 */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kernel.h"

/* Material of benches/step.rs. */
static const double DENSITY = 0.15, STRETCH = 200.0, BENDING = 1e-5, DAMPING = 0.001;

typedef struct { int a, b, t; } Half;

static int cmp_half(const void *p, const void *q) {
    const Half *x = p, *y = q;
    if (x->a != y->a) return x->a < y->a ? -1 : 1;
    if (x->b != y->b) return x->b < y->b ? -1 : 1;
    return (x->t > y->t) - (x->t < y->t);
}

static int cmp_double(const void *p, const void *q) {
    double x = *(const double *)p, y = *(const double *)q;
    return (x > y) - (x < y);
}

static void *xmalloc(size_t bytes) {
    void *p = malloc(bytes ? bytes : 1);
    if (!p) {
        fprintf(stderr, "out of memory\n");
        exit(1);
    }
    return p;
}

/* The vertex of triangle t that is neither a nor b. */
static int opposite(const int *tri, int a, int b) {
    for (int k = 0; k < 3; k++)
        if (tri[k] != a && tri[k] != b) return tri[k];
    return -1;
}

/* CSR offsets + entries from (vertex, entry) pairs, entries in pair order. */
static void csr(int n, int count, const int *vertex, const int *entry, int **off_out,
                int **list_out) {
    int *off = xmalloc(sizeof(int) * (n + 1)), *fill = xmalloc(sizeof(int) * n);
    int *list = xmalloc(sizeof(int) * count);
    memset(off, 0, sizeof(int) * (n + 1));
    for (int q = 0; q < count; q++) off[vertex[q] + 1]++;
    for (int i = 0; i < n; i++) off[i + 1] += off[i];
    memcpy(fill, off, sizeof(int) * n);
    for (int q = 0; q < count; q++) list[fill[vertex[q]]++] = entry[q];
    free(fill);
    *off_out = off;
    *list_out = list;
}

int main(int argc, char **argv) {
    const int res = argc > 1 ? atoi(argv[1]) : 256;
    const int steps = argc > 2 ? atoi(argv[2]) : 200;
    const int reps = argc > 3 ? atoi(argv[3]) : 7;
    const int nx = res, ny = res, n = (nx + 1) * (ny + 1), nt = 2 * nx * ny;
    const double w = 1.0, hgt = 1.0;

    /* Grid and triangles exactly as src/mesh/generate.rs::rectangle (all of
     * them counter-clockwise already). */
    double *mat = xmalloc(sizeof(double) * 2 * n);
    for (int j = 0; j <= ny; j++)
        for (int i = 0; i <= nx; i++) {
            mat[2 * (j * (nx + 1) + i) + 0] = -0.5 * w + w * i / (double)nx;
            mat[2 * (j * (nx + 1) + i) + 1] = -0.5 * hgt + hgt * j / (double)ny;
        }
    int *tri = xmalloc(sizeof(int) * 3 * nt), t = 0;
#define ID(i, j) ((j) * (nx + 1) + (i))
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            int a = ID(i, j), b = ID(i + 1, j), c = ID(i + 1, j + 1), d = ID(i, j + 1);
            int tt[2][3];
            if ((i + j) % 2 == 0) {
                int s[2][3] = {{a, b, c}, {a, c, d}};
                memcpy(tt, s, sizeof tt);
            } else {
                int s[2][3] = {{a, b, d}, {b, c, d}};
                memcpy(tt, s, sizeof tt);
            }
            memcpy(tri + 3 * t, tt, sizeof tt);
            t += 2;
        }
    double *area = xmalloc(sizeof(double) * nt), *mass = xmalloc(sizeof(double) * n);
    memset(mass, 0, sizeof(double) * n);
    for (t = 0; t < nt; t++) {
        const double *p = mat + 2 * tri[3 * t], *q = mat + 2 * tri[3 * t + 1],
                     *r = mat + 2 * tri[3 * t + 2];
        area[t] = 0.5 * fabs((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]));
        for (int k = 0; k < 3; k++) mass[tri[3 * t + k]] += DENSITY * area[t] / 3.0;
    }

    /* Edges in drape's order (sorted half-edges, src/mesh/topology.rs). */
    Half *half = xmalloc(sizeof(Half) * 3 * nt);
    for (t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            int a = tri[3 * t + k], b = tri[3 * t + (k + 1) % 3];
            half[3 * t + k] = (Half){a < b ? a : b, a < b ? b : a, t};
        }
    qsort(half, 3 * nt, sizeof(Half), cmp_half);
    const int cap = 6 * nt;
    int *sa = xmalloc(sizeof(int) * cap), *sb = xmalloc(sizeof(int) * cap);
    double *srest = xmalloc(sizeof(double) * cap), *sk = xmalloc(sizeof(double) * cap),
           *sc = xmalloc(sizeof(double) * cap);
    int ns = 0, nh = 0;
    int *hinge_t0 = xmalloc(sizeof(int) * 3 * nt), *hinge_t1 = xmalloc(sizeof(int) * 3 * nt);
    int *hinge_e0 = xmalloc(sizeof(int) * 3 * nt), *hinge_e1 = xmalloc(sizeof(int) * 3 * nt);
    for (int q = 0; q < 3 * nt;) {
        int r = q + 1;
        while (r < 3 * nt && half[r].a == half[q].a && half[r].b == half[q].b) r++;
        const int a = half[q].a, b = half[q].b;
        const double dx = mat[2 * b] - mat[2 * a], dy = mat[2 * b + 1] - mat[2 * a + 1];
        const double rest = sqrt(dx * dx + dy * dy);
        double sum_area = area[half[q].t] + (r - q == 2 ? area[half[q + 1].t] : 0.0);
        const double k = STRETCH * sum_area / (rest * rest); /* consistent rule */
        sa[ns] = a, sb[ns] = b, srest[ns] = rest, sk[ns] = k, sc[ns] = DAMPING * k, ns++;
        if (r - q == 2) {
            hinge_e0[nh] = a, hinge_e1[nh] = b;
            hinge_t0[nh] = half[q].t, hinge_t1[nh] = half[q + 1].t, nh++;
        }
        q = r;
    }
    const int n_stretch = ns;
    /* One hinge spring per interior edge between the two wing tips (paper A). */
    for (int h = 0; h < nh; h++) {
        int p = opposite(tri + 3 * hinge_t0[h], hinge_e0[h], hinge_e1[h]);
        int q = opposite(tri + 3 * hinge_t1[h], hinge_e0[h], hinge_e1[h]);
        const double dx = mat[2 * q] - mat[2 * p], dy = mat[2 * q + 1] - mat[2 * p + 1];
        const double rest = sqrt(dx * dx + dy * dy);
        const double k = BENDING / (rest * rest);
        sa[ns] = p, sb[ns] = q, srest[ns] = rest, sk[ns] = k, sc[ns] = DAMPING * k, ns++;
    }

    /* drape's layout: first / second end lists. */
    int *first_off, *first, *second_off, *second, *ids = xmalloc(sizeof(int) * ns);
    for (int s = 0; s < ns; s++) ids[s] = s;
    csr(n, ns, sa, ids, &first_off, &first);
    csr(n, ns, sb, ids, &second_off, &second);
    SpringElements el = {n, ns, sa, sb, srest, sk, sc, first_off, first, second_off, second};

    /* Gather layout: each spring once in each end's list, first-end springs then
     * second-end springs, with the other end and the constants inline. */
    int *g_off = xmalloc(sizeof(int) * (n + 1)), *g_nbr = xmalloc(sizeof(int) * 2 * ns);
    double *g_rest = xmalloc(sizeof(double) * 2 * ns), *g_k = xmalloc(sizeof(double) * 2 * ns),
           *g_c = xmalloc(sizeof(double) * 2 * ns);
    g_off[0] = 0;
    for (int i = 0, e = 0; i < n; i++) {
        for (int pass = 0; pass < 2; pass++) {
            const int *o = pass ? second_off : first_off, *l = pass ? second : first;
            for (int q = o[i]; q < o[i + 1]; q++) {
                const int s = l[q];
                g_nbr[e] = pass ? sa[s] : sb[s];
                g_rest[e] = srest[s], g_k[e] = sk[s], g_c[e] = sc[s];
                e++;
            }
        }
        g_off[i + 1] = e;
    }
    NeighbourCsr g = {n, g_off, g_nbr, g_rest, g_k, g_c};

    /* Automatic step as src/physics/timestep.rs (Gershgorin bound times SAFETY;
     * keep SAFETY in sync so that the consistency check compares equal steps). */
    const double SAFETY = 0.4;
    double *stiff = xmalloc(sizeof(double) * n), *damp = xmalloc(sizeof(double) * n);
    memset(stiff, 0, sizeof(double) * n);
    memset(damp, 0, sizeof(double) * n);
    for (int s = 0; s < ns; s++) {
        stiff[sa[s]] += 2 * sk[s], stiff[sb[s]] += 2 * sk[s];
        damp[sa[s]] += 2 * sc[s], damp[sb[s]] += 2 * sc[s];
    }
    double omega2 = 0, zeta = 0;
    for (int i = 0; i < n; i++) {
        omega2 = fmax(omega2, stiff[i] / mass[i]);
        zeta = fmax(zeta, damp[i] / mass[i]);
    }
    const double dt = SAFETY * (sqrt(zeta * zeta + 4 * omega2) - zeta) / omega2;
    const double gravity[3] = {0.0, 0.0, -9.81};

    double *x0 = xmalloc(sizeof(double) * 3 * n);
    for (int i = 0; i < n; i++) {
        const double u = mat[2 * i], v = mat[2 * i + 1];
        x0[3 * i] = u, x0[3 * i + 1] = v, x0[3 * i + 2] = 0.01 * sin(7.0 * u) * cos(5.0 * v);
    }
    double *x = xmalloc(sizeof(double) * 3 * n), *v = xmalloc(sizeof(double) * 3 * n);
    double *xn = xmalloc(sizeof(double) * 3 * n), *vn = xmalloc(sizeof(double) * 3 * n);
    double *f = xmalloc(sizeof(double) * 3 * ns), *times = xmalloc(sizeof(double) * reps);

    printf("grid %dx%d: %d vertices, %d triangles, %d stretch + %d hinge springs, dt %.4e s\n",
           nx + 1, ny + 1, n, nt, n_stretch, ns - n_stretch, dt);
    printf("%d steps x %d repetitions, median reported\n", steps, reps);
    for (int kernel = 0; kernel < 2; kernel++) {
        for (int threads = 1; threads <= 2; threads++) {
            omp_set_num_threads(threads);
            double zsum = 0.0, z2sum = 0.0, vxy2sum = 0.0;
            for (int r = -1; r < reps; r++) { /* r = -1: warm-up */
                memcpy(x, x0, sizeof(double) * 3 * n);
                memset(v, 0, sizeof(double) * 3 * n);
                const double start = omp_get_wtime();
                for (int s = 0; s < steps; s++) {
                    if (kernel == 0) {
                        step_gather(&g, mass, x, v, xn, vn, gravity, dt);
                        double *tmp = x; x = xn; xn = tmp;
                        tmp = v; v = vn; vn = tmp;
                    } else {
                        step_two_pass(&el, mass, x, v, f, gravity, dt);
                    }
                }
                const double elapsed = omp_get_wtime() - start;
                if (r >= 0) times[r] = elapsed;
                zsum = z2sum = vxy2sum = 0.0;
                for (int i = 0; i < n; i++) {
                    zsum += x[3 * i + 2], z2sum += x[3 * i + 2] * x[3 * i + 2];
                    vxy2sum += v[3 * i] * v[3 * i] + v[3 * i + 1] * v[3 * i + 1];
                }
            }
            qsort(times, reps, sizeof(double), cmp_double);
            const double median = times[reps / 2];
            printf("%-8s threads %d: %.3e vertex-steps/s (median %.4f s for %d steps; "
                   "min %.4f max %.4f)\n",
                   kernel == 0 ? "gather" : "two_pass", threads,
                   (double)n * steps / median, median, steps, times[0], times[reps - 1]);
            printf("         state after %d steps: mean z %.9e, rms z %.9e, "
                   "rms in-plane speed %.9e\n",
                   steps, zsum / n, sqrt(z2sum / n), sqrt(vxy2sum / n));
        }
    }
    return 0;
}
