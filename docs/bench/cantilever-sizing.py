"""How much of the cantilever the sizing rule must refine (issue 14, the "why"
behind the cantilever's missed target; docs/speed-vs-error-history.md).

Solves the heavy elastica of the strip in scenes/cantilever.toml (4 cm
overhang, bending length 2 cm: lambda = (L / c)^3 = 8) by shooting with RK4,
independently of drape's code, and applies red-green's sizing rule to the
exact curvature: a leaf whose grid cell has legs h splits while
kappa * D > refine_angle, D = 2 h / (3 sqrt 2) the centroid spacing of a
right isosceles triangle. Prints the fraction of the finest uniform mesh's
vertex density the rule keeps over the overhang, and over the whole strip
with the 1 cm clamp at the base cells. Needs numpy >= 2.0:
    python3 docs/bench/cantilever-sizing.py
"""
import numpy as np
lam = (0.04/0.02)**3   # (L/c)^3, L = 4 cm overhang, c = 2 cm bending length
N = 4000
s = np.linspace(0, 1, N+1)
def shoot(k0):
    # state: theta, theta' ; theta'' = -lam (1-s) cos(theta)
    th, dth = 0.0, k0
    ths=[th]; ks=[dth]
    h = 1.0/N
    f = lambda si, th, dth: (dth, -lam*(1-si)*np.cos(th))
    for i in range(N):
        si = s[i]
        a1 = f(si, th, dth)
        a2 = f(si+h/2, th+h/2*a1[0], dth+h/2*a1[1])
        a3 = f(si+h/2, th+h/2*a2[0], dth+h/2*a2[1])
        a4 = f(si+h, th+h*a3[0], dth+h*a3[1])
        th += h/6*(a1[0]+2*a2[0]+2*a3[0]+a4[0]); dth += h/6*(a1[1]+2*a2[1]+2*a3[1]+a4[1])
        ths.append(th); ks.append(dth)
    return np.array(ths), np.array(ks)
lo, hi = 0.0, lam
for _ in range(60):
    mid = (lo+hi)/2
    _, k = shoot(mid)
    if k[-1] > 0: hi = mid
    else: lo = mid
th, k = shoot((lo+hi)/2)
L = 0.04
kappa = k / L      # rad/m
xs, ys = np.trapezoid(np.cos(th), s), np.trapezoid(np.sin(th), s)
print("kappa at the clamp %.2f rad/m, tip slope %.2f deg, chord angle %.2f deg"
      % (kappa[0], np.degrees(th[-1]), np.degrees(np.arctan2(ys, xs))))
for q in (0.5, 0.25, 0.125, 1/16):
    idx = np.argmax(kappa < q*kappa[0])
    print("  kappa > %.3f kappa_max on the first %.0f %% of the overhang" % (q, 100*s[idx]))
D = 2/(3*np.sqrt(2))   # centroid spacing / leg of a right isosceles triangle
def fraction(r_deg, cells):
    r = np.radians(r_deg)
    finest = cells[-1]
    dens = np.empty_like(kappa)
    for i, kk in enumerate(kappa):
        h = cells[0]
        for c in cells[1:]:
            if kk*D*h > r: h = c
        dens[i] = (finest/h)**2
    over = np.trapezoid(dens, s)
    return over
for base, cells in (("10 L4", [0.005, 0.0025, 0.00125]), ("10 L6", [0.005, 0.0025, 0.00125, 0.000625])):
    for r in (2.0, 1.0, 0.5):
        f = fraction(r, cells)
        # whole strip: overhang 4 cm of 5; the clamp (1 cm) keeps the base cells
        whole = (0.8*f + 0.2*(cells[-1]/cells[0])**2)
        print(f"red_green {base} r{r}: overhang at {f:.3f} of the finest uniform's vertex density; whole strip {whole:.3f}")
