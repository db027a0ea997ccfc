//! Static equilibrium of the discrete model: Newton's method on the total energy
//! (elastic + gravitational) with the library's own forces, a positive
//! semi-definite approximation of the Hessian (exact for springs and membrane
//! triangles in tension, Gauss-Newton for dihedral hinges and shape triangles, springs in compression
//! without their negative transverse term), a backtracking line
//! search and a banded (envelope) Cholesky factorization. It finds the rest state
//! of a clamped strip in well under a second, where a dynamic run takes minutes;
//! the equilibrium is that of the discrete model, whatever the solver.

use drape::math::{Matrix3, Scalar, Vector, Vector2};
use drape::physics::forces::{ForceScratch, element_pass, energy, gather};
use drape::physics::{Elements, ExternalForces};

/// Symmetric positive definite matrix in envelope (skyline) storage, lower part.
struct Envelope {
    first: Vec<usize>,
    start: Vec<usize>,
    val: Vec<Scalar>,
}

impl Envelope {
    fn new(first: Vec<usize>) -> Envelope {
        let mut start = Vec::with_capacity(first.len() + 1);
        let mut len = 0;
        for (i, &f) in first.iter().enumerate() {
            start.push(len);
            len += i + 1 - f;
        }
        start.push(len);
        Envelope {
            first,
            start,
            val: vec![0.0; len],
        }
    }

    fn add(&mut self, i: usize, j: usize, v: Scalar) {
        if j <= i {
            self.val[self.start[i] + j - self.first[i]] += v;
        }
    }

    /// `y = A x` for the (unfactored) symmetric matrix.
    fn mul(&self, x: &[Scalar]) -> Vec<Scalar> {
        let mut y = vec![0.0; x.len()];
        for i in 0..x.len() {
            for j in self.first[i]..=i {
                let a = self.at(i, j);
                y[i] += a * x[j];
                if j < i {
                    y[j] += a * x[i];
                }
            }
        }
        y
    }

    fn at(&self, i: usize, j: usize) -> Scalar {
        self.val[self.start[i] + j - self.first[i]]
    }

    /// In-place Cholesky `A = L L^T`; false when a pivot is not positive.
    fn factor(&mut self) -> bool {
        let n = self.first.len();
        for i in 0..n {
            for j in self.first[i]..=i {
                let k0 = self.first[i].max(self.first[j]);
                let mut sum = self.at(i, j);
                let (si, sj) = (self.start[i] - self.first[i], self.start[j] - self.first[j]);
                for k in k0..j {
                    sum -= self.val[si + k] * self.val[sj + k];
                }
                if j == i {
                    if sum <= 0.0 || !sum.is_finite() {
                        return false;
                    }
                    self.val[si + i] = sum.sqrt();
                } else {
                    self.val[si + j] = sum / self.val[sj + j];
                }
            }
        }
        true
    }

    fn solve(&self, b: &mut [Scalar]) {
        let n = b.len();
        for i in 0..n {
            let lo = self.first[i];
            let row = &self.val[self.start[i]..self.start[i] + i - lo];
            let s: Scalar = b[i]
                - row
                    .iter()
                    .zip(&b[lo..i])
                    .map(|(l, x)| l * x)
                    .sum::<Scalar>();
            b[i] = s / self.at(i, i);
        }
        for i in (0..n).rev() {
            b[i] /= self.at(i, i);
            let (lo, bi) = (self.first[i], b[i]);
            let row = &self.val[self.start[i]..self.start[i] + i - lo];
            for (bk, l) in b[lo..i].iter_mut().zip(row) {
                *bk -= l * bi;
            }
        }
    }
}

/// What the solve did.
pub struct Equilibrium {
    /// Newton iterations over all load steps.
    pub iterations: usize,
    /// Largest force on a free vertex at the end, N.
    pub residual: Scalar,
}

/// Moves the free vertices of `x` to the equilibrium under `ext` (gravity applied
/// in `load_steps` equal increments). Free vertices are numbered along material
/// `u` so that the matrix is banded for strips along u.
pub fn solve(
    el: &Elements,
    ext: &ExternalForces,
    material: &[Vector2],
    x: &mut [Vector],
    fixed: &[bool],
    load_steps: usize,
) -> Result<Equilibrium, String> {
    let n = x.len();
    let mut order: Vec<usize> = (0..n).filter(|&i| !fixed[i]).collect();
    order.sort_by(|&a, &b| {
        (material[a].x, material[a].y)
            .partial_cmp(&(material[b].x, material[b].y))
            .unwrap()
    });
    let mut rank = vec![usize::MAX; n];
    for (r, &i) in order.iter().enumerate() {
        rank[i] = r;
    }
    let groups: Vec<Vec<usize>> = el
        .kinds
        .springs
        .springs
        .iter()
        .map(|s| s.v.map(|v| v as usize).to_vec())
        .chain(
            el.kinds
                .hinges
                .hinges
                .iter()
                .map(|h| h.v.map(|v| v as usize).to_vec()),
        )
        .chain(
            el.kinds
                .membrane
                .triangles
                .iter()
                .map(|t| t.v.map(|v| v as usize).to_vec()),
        )
        .chain(
            el.kinds
                .shapes
                .triangles
                .iter()
                .map(|t| t.slots().map(|(_, v)| v as usize).collect()),
        )
        .collect();
    let mut first_v: Vec<usize> = (0..order.len()).collect();
    for g in &groups {
        let lo = g.iter().map(|&v| rank[v]).min().unwrap();
        for &v in g {
            if rank[v] != usize::MAX {
                first_v[rank[v]] = first_v[rank[v]].min(lo);
            }
        }
    }
    let first: Vec<usize> = (0..3 * order.len()).map(|d| 3 * first_v[d / 3]).collect();
    let zero_v = vec![Vector::ZERO; n];
    let mut scratch = ForceScratch::default();
    let g_full = ext.gravity.unwrap_or(Vector::ZERO);
    let weight = el.total_mass() * g_full.length() / n as Scalar;
    let mut iterations = 0;
    let mut residual = Scalar::INFINITY;
    for step in 1..=load_steps {
        let load = ExternalForces {
            gravity: Some(g_full * (step as Scalar / load_steps as Scalar)),
            ..*ext
        };
        let total_energy = |x: &[Vector]| {
            let e = energy(el, &load, x, &zero_v);
            e.elastic + e.gravitational
        };
        let forces = |x: &[Vector], scratch: &mut ForceScratch| -> Vec<Vector> {
            element_pass(el, &load, &[], x, &zero_v, scratch);
            (0..n)
                .map(|i| {
                    if fixed[i] {
                        Vector::ZERO
                    } else {
                        gather(el, &load, scratch, i, Vector::ZERO)
                    }
                })
                .collect()
        };
        let mut f = forces(x, &mut scratch);
        for _ in 0..200 {
            residual = f.iter().map(|v| v.length()).fold(0.0, Scalar::max);
            if residual <= 1e-7 * weight {
                break;
            }
            iterations += 1;
            let mut k = Envelope::new(first.clone());
            assemble(el, x, &rank, &mut k);
            let unfactored = Envelope {
                first: k.first.clone(),
                start: k.start.clone(),
                val: k.val.clone(),
            };
            let mut shift = 0.0;
            let mut fac = k.val.clone();
            loop {
                let mut trial = Envelope {
                    first: k.first.clone(),
                    start: k.start.clone(),
                    val: fac.clone(),
                };
                if trial.factor() {
                    k = trial;
                    break;
                }
                shift = if shift == 0.0 { 1e-8 } else { shift * 10.0 };
                fac = k.val.clone();
                let scale = (0..first.len()).map(|i| k.at(i, i)).fold(0.0, Scalar::max);
                for i in 0..first.len() {
                    fac[k.start[i] + i - k.first[i]] += shift * scale;
                }
                if shift > 1.0 {
                    return Err("Hessian not positive definite".into());
                }
            }
            let rhs: Vec<Scalar> = order.iter().flat_map(|&i| f[i].to_array()).collect();
            let rhs = newton_direction(el, x, &rank, &unfactored, &k, &rhs);
            let dx: Vec<Vector> = (0..n)
                .map(|i| match rank[i] {
                    usize::MAX => Vector::ZERO,
                    r => Vector::new(rhs[3 * r], rhs[3 * r + 1], rhs[3 * r + 2]),
                })
                .collect();
            let e0 = total_energy(x);
            let slope: Scalar = f.iter().zip(&dx).map(|(a, b)| a.dot(*b)).sum();
            let mut alpha = 1.0;
            let mut accepted = false;
            for _ in 0..40 {
                let trial: Vec<Vector> = x.iter().zip(&dx).map(|(p, d)| *p + *d * alpha).collect();
                let e1 = total_energy(&trial);
                let f1 = forces(&trial, &mut scratch);
                let r1 = f1.iter().map(|v| v.length()).fold(0.0, Scalar::max);
                if e1 <= e0 - 1e-4 * alpha * slope || (alpha == 1.0 && r1 < 0.5 * residual) {
                    x.copy_from_slice(&trial);
                    f = f1;
                    accepted = true;
                    break;
                }
                alpha *= 0.5;
            }
            if !accepted {
                break;
            }
        }
    }
    if residual > 1e-5 * weight {
        return Err(format!(
            "no equilibrium: residual {residual:.3e} N vs weight per vertex {weight:.3e} N"
        ));
    }
    Ok(Equilibrium {
        iterations,
        residual,
    })
}

/// Solves `H dx = f` for the Newton direction by conjugate gradients
/// preconditioned with the factored `k` (the assembled Hessian `unfactored`,
/// whose shape triangles hold their folds' fixed split), where `H` takes the
/// shape triangles' folds with their optimal splits (`shape.rs`): exact for
/// the bending energy minimised over the splits, which no sparse matrix holds.
fn newton_direction(
    el: &Elements,
    x: &[Vector],
    rank: &[usize],
    unfactored: &Envelope,
    k: &Envelope,
    f: &[Scalar],
) -> Vec<Scalar> {
    let mut dx = f.to_vec();
    k.solve(&mut dx);
    if el.kinds.shapes.fold_splits.count() == 0 {
        return dx;
    }
    let jac: Vec<_> = el
        .kinds
        .shapes
        .triangles
        .iter()
        .map(|t| t.angles(x).1)
        .collect();
    let apply = |p: &[Scalar]| -> Vec<Scalar> {
        let mut y = unfactored.mul(p);
        let at = |v: u32| match rank[v as usize] {
            usize::MAX => Vector::ZERO,
            r => Vector::new(p[3 * r], p[3 * r + 1], p[3 * r + 2]),
        };
        let rates: Vec<[Scalar; 3]> = el
            .kinds
            .shapes
            .triangles
            .iter()
            .zip(&jac)
            .map(|(t, j)| [0, 1, 2].map(|a| t.slots().map(|(s, v)| j[a][s].dot(at(v))).sum()))
            .collect();
        let mut splits = Vec::new();
        el.kinds
            .shapes
            .fold_splits
            .solve(&el.kinds.shapes.triangles, &rates, &mut splits);
        for ((t, j), r) in el.kinds.shapes.triangles.iter().zip(&jac).zip(&rates) {
            let (exact, fixed) = (t.moments(*r, &splits), t.times_m(*r));
            for (s, v) in t.slots() {
                let rv = rank[v as usize];
                if rv == usize::MAX {
                    continue;
                }
                let g: Vector = (0..3).map(|a| j[a][s] * (exact[a] - fixed[a])).sum();
                for d in 0..3 {
                    y[3 * rv + d] += g[d];
                }
            }
        }
        y
    };
    let dot = |a: &[Scalar], b: &[Scalar]| a.iter().zip(b).map(|(x, y)| x * y).sum::<Scalar>();
    let mut r: Vec<Scalar> = f.iter().zip(apply(&dx)).map(|(b, a)| b - a).collect();
    let mut z = r.clone();
    k.solve(&mut z);
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    let norm_f = dot(f, f).sqrt();
    for _ in 0..200 {
        if dot(&r, &r).sqrt() <= 1e-10 * norm_f {
            break;
        }
        let ap = apply(&p);
        let alpha = rz / dot(&p, &ap);
        for i in 0..dx.len() {
            dx[i] += alpha * p[i];
            r[i] -= alpha * ap[i];
        }
        z.copy_from_slice(&r);
        k.solve(&mut z);
        let rz_new = dot(&r, &z);
        for i in 0..p.len() {
            p[i] = z[i] + rz_new / rz * p[i];
        }
        rz = rz_new;
    }
    dx
}

/// Adds the element Hessians (module docs) of the free vertices to `k`.
fn assemble(el: &Elements, x: &[Vector], rank: &[usize], k: &mut Envelope) {
    let mut add_block = |a: usize, b: usize, m: Matrix3| {
        let (ra, rb) = (rank[a], rank[b]);
        if ra == usize::MAX || rb == usize::MAX {
            return;
        }
        for i in 0..3 {
            for j in 0..3 {
                k.add(3 * ra + i, 3 * rb + j, m.col(j)[i]);
            }
        }
    };
    for s in &el.kinds.springs.springs {
        let [a, b] = [s.v[0] as usize, s.v[1] as usize];
        let d = x[b] - x[a];
        let len = d.length();
        let dir = d / len;
        let nn = Matrix3::from_cols(dir * dir.x, dir * dir.y, dir * dir.z);
        let t = (1.0 - s.rest / len).max(0.0);
        let m = (nn + (Matrix3::IDENTITY - nn) * t) * s.k;
        add_block(a, a, m);
        add_block(b, b, m);
        add_block(a, b, -m);
        add_block(b, a, -m);
    }
    for t in &el.kinds.membrane.triangles {
        let (gauss_newton, geometric) = t.stiffness(x);
        let m = gauss_newton.combine(1.0, &geometric, 1.0);
        for i in 0..3 {
            for j in 0..3 {
                add_block(t.v[i] as usize, t.v[j] as usize, t.block(&m, i, j));
            }
        }
    }
    for h in &el.kinds.hinges.hinges {
        let (_, g) =
            drape::physics::bending::dihedral_angle_and_gradient(h.v.map(|i| x[i as usize]));
        for i in 0..4 {
            for j in 0..4 {
                let m = Matrix3::from_cols(g[i] * g[j].x, g[i] * g[j].y, g[i] * g[j].z) * h.k;
                add_block(h.v[i] as usize, h.v[j] as usize, m);
            }
        }
    }
    for t in &el.kinds.shapes.triangles {
        let (_, jac) = t.angles(x);
        for (i, vi) in t.slots() {
            for (j, vj) in t.slots() {
                let mut m = Matrix3::ZERO;
                for a in 0..3 {
                    for b in 0..3 {
                        let (gi, gj) = (jac[a][i], jac[b][j]);
                        m += Matrix3::from_cols(gi * gj.x, gi * gj.y, gi * gj.z) * t.m[a][b];
                    }
                }
                add_block(vi as usize, vj as usize, m);
            }
        }
    }
}
