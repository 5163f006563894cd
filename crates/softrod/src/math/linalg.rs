//! Small dense linear algebra: the one 6×6 LU, one general LU and one symmetric positive
//! definite inverse (Cholesky), written on plain arrays because at these sizes they are
//! several times faster than the generic routines.

use nalgebra::{Matrix3, Matrix6};

/// Partial pivoting on column `k` of the row-major 6×6 `a`: the row `p >= k` of the largest
/// `|a[p][k]|` (the first on ties), `None` if that pivot is zero or not finite (singular to
/// working precision). Shared by [`Lu6::new`] and [`Inverse6::new`].
#[inline(always)]
fn pivot_row(a: &[[f64; 6]; 6], k: usize) -> Option<usize> {
    let mut p = k;
    let mut best = a[k][k].abs();
    for i in k + 1..6 {
        if a[i][k].abs() > best {
            best = a[i][k].abs();
            p = i;
        }
    }
    (best > 0.0 && best.is_finite()).then_some(p)
}

/// LU factorisation with partial pivoting of a 6×6 matrix (no allocation).
#[derive(Debug, Clone, Copy)]
pub struct Lu6 {
    a: [[f64; 6]; 6],
    inv_diag: [f64; 6],
    perm: [usize; 6],
}

impl Lu6 {
    /// Factorises `m`; `None` if it is singular to working precision or not finite.
    #[inline]
    pub fn new(m: &Matrix6<f64>) -> Option<Self> {
        let mut a = [[0.0; 6]; 6];
        for i in 0..6 {
            for j in 0..6 {
                a[i][j] = m[(i, j)];
            }
        }
        let mut perm = [0, 1, 2, 3, 4, 5];
        let mut inv_diag = [0.0; 6];
        for k in 0..6 {
            let p = pivot_row(&a, k)?;
            if p != k {
                a.swap(p, k);
                perm.swap(p, k);
            }
            let inv = 1.0 / a[k][k];
            inv_diag[k] = inv;
            for i in k + 1..6 {
                let f = a[i][k] * inv;
                a[i][k] = f;
                for j in k + 1..6 {
                    a[i][j] -= f * a[k][j];
                }
            }
        }
        Some(Self { a, inv_diag, perm })
    }

    /// Solves `M x = b`.
    #[inline]
    pub fn solve(&self, b: &[f64; 6]) -> [f64; 6] {
        let mut x = [0.0; 6];
        for i in 0..6 {
            let mut v = b[self.perm[i]];
            for j in 0..i {
                v -= self.a[i][j] * x[j];
            }
            x[i] = v;
        }
        for i in (0..6).rev() {
            let mut v = x[i];
            for j in i + 1..6 {
                v -= self.a[i][j] * x[j];
            }
            x[i] = v * self.inv_diag[i];
        }
        x
    }

    /// `M⁻¹`.
    pub fn inverse(&self) -> Matrix6<f64> {
        let mut m = Matrix6::zeros();
        for j in 0..6 {
            let mut e = [0.0; 6];
            e[j] = 1.0;
            let col = self.solve(&e);
            for i in 0..6 {
                m[(i, j)] = col[i];
            }
        }
        m
    }
}

/// The inverse of a 6×6 matrix, by Gauss–Jordan elimination with partial pivoting, kept for
/// repeated solves: each is one 6×6 matrix–vector product (no allocation, no triangular
/// sweeps). For the well-conditioned local systems of the constitutive solve, solved many
/// times per factorisation (chord steps, sensitivity columns).
#[derive(Debug, Clone, Copy)]
pub struct Inverse6 {
    /// The inverse, row-major.
    inv: [[f64; 6]; 6],
}

impl Inverse6 {
    /// Inverts `m`; `None` if it is singular to working precision or not finite (a zero or
    /// non-finite pivot, as [`Lu6::new`]).
    #[inline]
    pub fn new(m: &Matrix6<f64>) -> Option<Self> {
        let mut a = [[0.0; 6]; 6];
        let mut b = [[0.0; 6]; 6];
        for i in 0..6 {
            for j in 0..6 {
                a[i][j] = m[(i, j)];
            }
            b[i][i] = 1.0;
        }
        for k in 0..6 {
            let p = pivot_row(&a, k)?;
            if p != k {
                a.swap(p, k);
                b.swap(p, k);
            }
            let inv = 1.0 / a[k][k];
            let (ak, bk) = (a[k].map(|v| v * inv), b[k].map(|v| v * inv));
            for i in 0..6 {
                let f = if i == k { 0.0 } else { a[i][k] };
                for j in 0..6 {
                    a[i][j] -= f * ak[j];
                    b[i][j] -= f * bk[j];
                }
            }
            a[k] = ak;
            b[k] = bk;
        }
        if !b.iter().all(|r| r.iter().all(|v| v.is_finite())) {
            return None;
        }
        Some(Self { inv: b })
    }

    /// The inverse of `I + C D` for a diagonal `C = diag(c)`, `c > 0`, and a symmetric
    /// positive semi-definite `D` (rows): `(I + C D)⁻¹ = S K⁻¹ S⁻¹`, `S = C^½`, with
    /// `K = I + S D S` (every eigenvalue >= 1) inverted by its 3×3 blocks,
    /// `K = [[A, B], [Bᵀ, E]]`: `W = A⁻¹ B`, `Z = (E - Bᵀ W)⁻¹`,
    /// `K⁻¹ = [[A⁻¹ + W Z Wᵀ, -W Z], [-Z Wᵀ, Z]]` (no pivoting needed: `A` and the Schur
    /// complement are `>= I`). About a quarter of the work of [`Self::new`]. `None` if a `c`
    /// is not positive or a block is singular.
    #[inline]
    pub fn of_compliance_stiffness(c: &[f64; 6], d: &[[f64; 6]; 6]) -> Option<Self> {
        if !c.iter().all(|&v| v > 0.0 && v.is_finite()) {
            return None;
        }
        let s = c.map(f64::sqrt);
        let k = |i: usize, j: usize| s[i] * d[i][j] * s[j] + if i == j { 1.0 } else { 0.0 };
        let a = Matrix3::from_fn(k);
        let bm = Matrix3::from_fn(|i, j| k(i, j + 3));
        let e = Matrix3::from_fn(|i, j| k(i + 3, j + 3));
        let ai = a.try_inverse()?;
        let w = ai * bm;
        let z = (e - bm.tr_mul(&w)).try_inverse()?;
        let q = -(w * z);
        let p = ai - q * w.transpose();
        let mut inv = [[0.0; 6]; 6];
        for i in 0..3 {
            for j in 0..3 {
                inv[i][j] = s[i] * p[(i, j)] / s[j];
                inv[i][j + 3] = s[i] * q[(i, j)] / s[j + 3];
                inv[i + 3][j] = s[i + 3] * q[(j, i)] / s[j];
                inv[i + 3][j + 3] = s[i + 3] * z[(i, j)] / s[j + 3];
            }
        }
        if !inv.iter().all(|r| r.iter().all(|v| v.is_finite())) {
            return None;
        }
        Some(Self { inv })
    }

    /// Solves `M x = b`.
    #[inline(always)]
    pub fn solve(&self, b: &[f64; 6]) -> [f64; 6] {
        let mut x = [0.0; 6];
        for i in 0..6 {
            let r = &self.inv[i];
            x[i] =
                r[0] * b[0] + r[1] * b[1] + r[2] * b[2] + r[3] * b[3] + r[4] * b[4] + r[5] * b[5];
        }
        x
    }

    /// `M⁻¹ (c ∘ b)`: the solve of a right-hand side scaled component-wise by `c`.
    #[inline(always)]
    pub fn solve_scaled(&self, c: &[f64; 6], b: &[f64; 6]) -> [f64; 6] {
        self.solve(&std::array::from_fn(|k| c[k] * b[k]))
    }
}

/// Largest dimension [`DenseLu`] factorises without heap storage (the shooting problems and
/// PCC chains of up to four segments).
const SMALL: usize = 12;

/// LU factorisation with partial pivoting of an `n × n` matrix (column-major storage); up to
/// `12 × 12` in place, without allocation.
#[derive(Debug, Clone)]
pub struct DenseLu {
    n: usize,
    small: [f64; SMALL * SMALL],
    small_perm: [usize; SMALL],
    lu: Vec<f64>,
    perm: Vec<usize>,
    scratch: Vec<f64>,
}

impl Default for DenseLu {
    fn default() -> Self {
        Self {
            n: 0,
            small: [0.0; SMALL * SMALL],
            small_perm: [0; SMALL],
            lu: Vec::new(),
            perm: Vec::new(),
            scratch: Vec::new(),
        }
    }
}

impl DenseLu {
    /// Factorises the column-major `n × n` matrix `a` into `self` (reusing its storage);
    /// `false` if it is singular to working precision or not finite.
    #[inline]
    pub fn factor(&mut self, n: usize, a: &[f64]) -> bool {
        self.n = n;
        let (lu, perm): (&mut [f64], &mut [usize]) = if n <= SMALL {
            (&mut self.small[..n * n], &mut self.small_perm[..n])
        } else {
            self.lu.resize(n * n, 0.0);
            self.perm.resize(n, 0);
            (&mut self.lu, &mut self.perm)
        };
        lu.copy_from_slice(&a[..n * n]);
        for (i, p) in perm.iter_mut().enumerate() {
            *p = i;
        }
        for k in 0..n {
            let (mut piv, mut best) = (k, lu[k + k * n].abs());
            for r in k + 1..n {
                let v = lu[r + k * n].abs();
                if v > best {
                    piv = r;
                    best = v;
                }
            }
            if !(best > 0.0 && best.is_finite()) {
                return false;
            }
            if piv != k {
                for c in 0..n {
                    lu.swap(k + c * n, piv + c * n);
                }
                perm.swap(k, piv);
            }
            let inv = 1.0 / lu[k + k * n];
            for r in k + 1..n {
                let f = lu[r + k * n] * inv;
                lu[r + k * n] = f;
                if f != 0.0 {
                    for c in k + 1..n {
                        lu[r + c * n] -= f * lu[k + c * n];
                    }
                }
            }
        }
        true
    }

    /// Solves `A x = b` in place (`b` of length `n`); `false` if the result is not finite.
    #[inline]
    pub fn solve_in_place(&mut self, b: &mut [f64]) -> bool {
        let n = self.n;
        let mut small_x = [0.0; SMALL];
        let (lu, perm, x): (&[f64], &[usize], &mut [f64]) = if n <= SMALL {
            (
                &self.small[..n * n],
                &self.small_perm[..n],
                &mut small_x[..n],
            )
        } else {
            self.scratch.resize(n, 0.0);
            (&self.lu, &self.perm, &mut self.scratch)
        };
        for (xi, &p) in x.iter_mut().zip(perm) {
            *xi = b[p];
        }
        for i in 0..n {
            let mut v = x[i];
            for j in 0..i {
                v -= lu[i + j * n] * x[j];
            }
            x[i] = v;
        }
        for i in (0..n).rev() {
            let mut v = x[i];
            for j in i + 1..n {
                v -= lu[i + j * n] * x[j];
            }
            x[i] = v / lu[i + i * n];
        }
        b[..n].copy_from_slice(x);
        x.iter().all(|v| v.is_finite())
    }
}

/// Cholesky factor of `A − shift·I` for the symmetric `n × n` matrix `a` (either storage
/// order: only the triangle below the diagonal of its row-major reading is used): the lower
/// factor `L` (row-major, `L Lᵀ = A − shift·I`) into `l`, whose storage is reused; `false` if
/// `A − shift·I` is not positive definite (a pivot not positive or not finite).
pub fn cholesky_factor(a: &[f64], n: usize, shift: f64, l: &mut Vec<f64>) -> bool {
    l.clear();
    l.extend_from_slice(&a[..n * n]);
    for i in 0..n {
        l[i * n + i] -= shift;
    }
    for j in 0..n {
        let mut d = l[j * n + j];
        for k in 0..j {
            d -= l[j * n + k] * l[j * n + k];
        }
        if !(d > 0.0 && d.is_finite()) {
            return false;
        }
        let d = d.sqrt();
        l[j * n + j] = d;
        for i in j + 1..n {
            let mut v = l[i * n + j];
            for k in 0..j {
                v -= l[i * n + k] * l[j * n + k];
            }
            l[i * n + j] = v / d;
        }
    }
    true
}

/// Solves `L Lᵀ x = b` in place (`b` of length `n`) with the factor of [`cholesky_factor`];
/// `false` if the result is not finite.
pub fn cholesky_solve(l: &[f64], n: usize, b: &mut [f64]) -> bool {
    for i in 0..n {
        let mut v = b[i];
        for k in 0..i {
            v -= l[i * n + k] * b[k];
        }
        b[i] = v / l[i * n + i];
    }
    for i in (0..n).rev() {
        let mut v = b[i];
        for k in i + 1..n {
            v -= l[k * n + i] * b[k];
        }
        b[i] = v / l[i * n + i];
    }
    b[..n].iter().all(|v| v.is_finite())
}

/// Inverse of the symmetric positive definite sub-matrix of `c` on the indices `free` (the
/// other rows and columns of the result are zero), by Cholesky `C = L Lᵀ`, `C⁻¹ = L⁻ᵀ L⁻¹`;
/// `None` if a pivot is not positive.
pub fn spd_inverse_on(c: &Matrix6<f64>, free: &[usize]) -> Option<Matrix6<f64>> {
    let n = free.len();
    let sub = Matrix6::from_fn(|i, j| {
        if i < n && j < n {
            c[(free[i], free[j])]
        } else {
            0.0
        }
    });
    let inv = cholesky_inverse(&sub, n)?;
    let mut out = Matrix6::zeros();
    for (i, &a) in free.iter().enumerate() {
        for (j, &b) in free.iter().enumerate() {
            out[(a, b)] = inv[(i, j)];
        }
    }
    Some(out)
}

/// The one Cholesky inverse: `C⁻¹` of the leading `n × n` block of `c` (symmetric positive
/// definite; the rest of the result is zero), `None` if a pivot is not positive.
#[inline(always)]
fn cholesky_inverse(c: &Matrix6<f64>, n: usize) -> Option<Matrix6<f64>> {
    let mut l = [[0.0f64; 6]; 6];
    for j in 0..n {
        let mut d = c[(j, j)];
        for k in 0..j {
            d -= l[j][k] * l[j][k];
        }
        if !(d > 0.0 && d.is_finite()) {
            return None;
        }
        let dj = d.sqrt();
        l[j][j] = dj;
        for i in j + 1..n {
            let mut v = c[(i, j)];
            for k in 0..j {
                v -= l[i][k] * l[j][k];
            }
            l[i][j] = v / dj;
        }
    }
    // W = L⁻¹ (lower triangular), by forward substitution.
    let mut w = [[0.0f64; 6]; 6];
    for j in 0..n {
        w[j][j] = 1.0 / l[j][j];
        for i in j + 1..n {
            let mut v = 0.0;
            for k in j..i {
                v -= l[i][k] * w[k][j];
            }
            w[i][j] = v / l[i][i];
        }
    }
    // C⁻¹ = Wᵀ W.
    let mut out = Matrix6::zeros();
    for i in 0..n {
        for j in 0..=i {
            let mut v = 0.0;
            for k in i..n {
                v += w[k][i] * w[k][j];
            }
            out[(i, j)] = v;
            out[(j, i)] = v;
        }
    }
    Some(out)
}

/// `C⁻¹` of a symmetric positive definite 6×6 matrix (Cholesky), `None` if it is not.
pub fn spd_inverse(c: &Matrix6<f64>) -> Option<Matrix6<f64>> {
    cholesky_inverse(c, 6)
}

/// Matrix 1-norm (largest column sum of absolute values).
pub fn norm1(m: &Matrix6<f64>) -> f64 {
    m.column_iter()
        .map(|c| c.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// `C⁻¹` if `C` is symmetric positive definite (Cholesky), NaN otherwise; and the 1-norm
/// condition number `‖C‖₁ ‖C⁻¹‖₁` (infinite if `C` is not positive definite).
pub fn invert_spd(c: &Matrix6<f64>) -> (Matrix6<f64>, f64) {
    match spd_inverse(c) {
        Some(k) => {
            let cond = norm1(c) * norm1(&k);
            if cond.is_finite() {
                (k, cond)
            } else {
                (Matrix6::repeat(f64::NAN), f64::INFINITY)
            }
        }
        None => (Matrix6::repeat(f64::NAN), f64::INFINITY),
    }
}

/// `C⁻¹` by LU (NaN if singular) and the 1-norm condition number of `C`, for matrices that
/// need not be symmetric (tangents under follower loads).
pub fn invert_general(c: &Matrix6<f64>) -> (Matrix6<f64>, f64) {
    match Lu6::new(c) {
        Some(lu) => {
            let k = lu.inverse();
            (k, norm1(c) * norm1(&k))
        }
        None => (Matrix6::repeat(f64::NAN), f64::INFINITY),
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn spd() -> Matrix6<f64> {
        let a = Matrix6::from_fn(|i, j| 1.0 / (1.0 + i as f64 + j as f64));
        a * a.transpose() + Matrix6::identity() * 1e-3
    }

    #[test]
    fn cholesky_inverse_inverts_and_rejects_indefinite() {
        let c = spd();
        let (k, cond) = invert_spd(&c);
        assert!((k * c - Matrix6::identity()).amax() < 1e-9);
        assert!(cond.is_finite() && cond > 1.0);
        let (k, cond) = invert_spd(&(-c));
        assert!(k[(0, 0)].is_nan() && cond.is_infinite());
    }

    /// The Gauss–Jordan inverse solves what the LU solves, and refuses a singular matrix.
    #[test]
    fn inverse6_solves_what_lu6_solves() {
        let mut m = Matrix6::from_fn(|i, j| {
            ((i * 7 + j * 3) % 5) as f64 - 2.0 + if i == j { 0.5 } else { 0.0 }
        });
        m[(0, 0)] = 0.0; // a pivot is needed
        let b = [1.0, -2.0, 0.5, 3.0, -1.5, 2.5];
        let x = Inverse6::new(&m).unwrap().solve(&b);
        let y = Lu6::new(&m).unwrap().solve(&b);
        let r = m * nalgebra::Vector6::from(x) - nalgebra::Vector6::from(b);
        assert!(r.amax() < 1e-13, "{r}");
        for k in 0..6 {
            assert!((x[k] - y[k]).abs() < 1e-12 * (1.0 + y[k].abs()));
        }
        let mut s = m;
        for i in 0..6 {
            s[(i, 4)] = 0.0;
        }
        assert!(Inverse6::new(&s).is_none() && Lu6::new(&s).is_none());
        s[(2, 4)] = f64::NAN;
        assert!(Inverse6::new(&s).is_none());
    }

    /// The Cholesky form of `(I + C D)⁻¹` equals the Gauss–Jordan inverse of `I + C D`.
    #[test]
    fn inverse_of_compliance_stiffness_matches_the_general_inverse() {
        let c = [1e-5, 2e-5, 3e-6, 90.0, 95.0, 70.0];
        let g = Matrix6::from_fn(|i, j| ((i * 5 + j * 7) % 11) as f64 * 0.01 - 0.05);
        let d = g.transpose() * g * 4.0;
        let h = Matrix6::identity() + Matrix6::from_diagonal(&nalgebra::Vector6::from(c)) * d;
        let rows: [[f64; 6]; 6] = std::array::from_fn(|i| std::array::from_fn(|j| d[(i, j)]));
        let a = Inverse6::of_compliance_stiffness(&c, &rows).unwrap();
        let b = Inverse6::new(&h).unwrap();
        let e = [1.0, -2.0, 0.5, 3.0, -1.5, 2.5];
        let (x, y) = (a.solve(&e), b.solve(&e));
        for k in 0..6 {
            assert!(
                (x[k] - y[k]).abs() < 1e-12 * (1.0 + y[k].abs()),
                "{x:?} {y:?}"
            );
        }
        let mut z = c;
        z[2] = 0.0;
        assert!(Inverse6::of_compliance_stiffness(&z, &rows).is_none());
    }

    #[test]
    fn lu6_and_dense_lu_solve_the_same_system() {
        let m = Matrix6::from_fn(|i, j| {
            ((i * 7 + j * 3) % 5) as f64 - 1.5 + if i == j { 4.0 } else { 0.0 }
        });
        let b = [1.0, -2.0, 0.5, 3.0, 0.0, -1.0];
        let x = Lu6::new(&m).unwrap().solve(&b);
        let mut d = DenseLu::default();
        assert!(d.factor(6, m.as_slice()));
        let mut y = b;
        assert!(d.solve_in_place(&mut y));
        let r = m * nalgebra::Vector6::from(x) - nalgebra::Vector6::from(b);
        assert!(r.amax() < 1e-13);
        for k in 0..6 {
            assert!((x[k] - y[k]).abs() < 1e-13);
        }
        assert!((invert_general(&m).0 * m - Matrix6::identity()).amax() < 1e-12);
    }
}
