//! Independent oracles shared by the compliance tests (written from closed-form geometry,
//! not from the library): Castigliano's compliance of a circular arc and a block-wise
//! comparison of 6×6 compliances.
#![allow(dead_code, unused_imports, missing_docs)]

pub mod robot;
#[allow(unused_imports)] // not every test binary uses the shared robots
pub use robot::*;

use std::f64::consts::PI;

use softrod::nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

/// Entry-wise comparison, each 3×3 block relative to that block's largest entry of `exact`
/// (zero entries of `exact` must be below `tol` times the block scale).
pub fn assert_blocks_close(got: &Matrix6<f64>, exact: &Matrix6<f64>, tol: f64, what: &str) {
    for bi in 0..2 {
        for bj in 0..2 {
            let e = exact.fixed_view::<3, 3>(3 * bi, 3 * bj);
            let g = got.fixed_view::<3, 3>(3 * bi, 3 * bj);
            let scale = e.amax().max(g.amax());
            if scale == 0.0 {
                continue;
            }
            for i in 0..3 {
                for j in 0..3 {
                    let (x, y) = (g[(i, j)], e[(i, j)]);
                    let err = if y.abs() > 1e-3 * scale {
                        ((x - y) / y).abs()
                    } else {
                        (x - y).abs() / scale
                    };
                    assert!(
                        err <= tol,
                        "{what}: block ({bi},{bj}) entry ({i},{j}): {x:e} vs {y:e} (err {err:e})"
                    );
                }
            }
        }
    }
}

/// Gauss–Legendre nodes and weights on [-1, 1] (Newton on P_n), independent of the library.
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (1..=n)
        .map(|i| {
            let mut x = (PI * (i as f64 - 0.25) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// Castigliano: C_ij = ∫ Σ_k B_ki B_kj / S_k ds with B the map from the tip wrench to the
/// section's internal wrench (local components) of the stress-free arc of curvature `kappa`
/// about body y; written from the arc's closed-form geometry.
pub fn castigliano_arc(kappa: f64, l: f64, stiff: [f64; 6]) -> Matrix6<f64> {
    let p = |s: f64| {
        let t = kappa * s;
        Vector3::new((1.0 - t.cos()) / kappa, 0.0, t.sin() / kappa)
    };
    let r = |s: f64| {
        let t = kappa * s;
        Matrix3::new(t.cos(), 0.0, t.sin(), 0.0, 1.0, 0.0, -t.sin(), 0.0, t.cos())
    };
    let gl = gauss_legendre(30);
    let panels = 16;
    let mut c = Matrix6::zeros();
    for k in 0..panels {
        let (a, b) = (
            l * k as f64 / panels as f64,
            l * (k + 1) as f64 / panels as f64,
        );
        for &(x, w) in &gl {
            let s = 0.5 * (a + b) + 0.5 * (b - a) * x;
            let rt = r(s).transpose();
            let d = p(l) - p(s);
            // Section force = R^T F; section moment = R^T (M + d × F).
            let mut bm = Matrix6::zeros();
            let dx = Matrix3::new(0.0, -d.z, d.y, d.z, 0.0, -d.x, -d.y, d.x, 0.0);
            bm.fixed_view_mut::<3, 3>(0, 0).copy_from(&rt);
            bm.fixed_view_mut::<3, 3>(3, 0).copy_from(&(rt * dx));
            bm.fixed_view_mut::<3, 3>(3, 3).copy_from(&rt);
            let sinv =
                Matrix6::from_diagonal(&Vector6::from_iterator(stiff.iter().map(|v| 1.0 / v)));
            c += bm.transpose() * sinv * bm * (0.5 * (b - a) * w);
        }
    }
    c
}

/// Closed-form tip compliance of a straight uniform cantilever of length `l` along body z
/// (world axes): Euler–Bernoulli bending, axial, torsion, and Timoshenko shear when `gas`
/// (the shear stiffness `k G A`) is given.
pub fn timoshenko(l: f64, ei: f64, gj: f64, ea: f64, gas: Option<f64>) -> Matrix6<f64> {
    let lat = l.powi(3) / (3.0 * ei) + gas.map_or(0.0, |g| l / g);
    let mut c = Matrix6::zeros();
    c[(0, 0)] = lat;
    c[(1, 1)] = lat;
    c[(2, 2)] = if gas.is_some() { l / ea } else { 0.0 };
    c[(3, 3)] = l / ei;
    c[(4, 4)] = l / ei;
    c[(5, 5)] = l / gj;
    // Convention of se3.rs: a tip moment m_y moves the tip along +x, m_x along -y.
    c[(0, 4)] = l * l / (2.0 * ei);
    c[(4, 0)] = c[(0, 4)];
    c[(1, 3)] = -l * l / (2.0 * ei);
    c[(3, 1)] = c[(1, 3)];
    c
}

/// `(E I, G J, E A, k G A)` of a solid circular section of `radius` (m) of a linear material
/// (`E` Pa, Poisson's ratio `nu`) with shear coefficient `k`.
pub fn circular_constants(e: f64, nu: f64, radius: f64, k: f64) -> (f64, f64, f64, f64) {
    let g = e / (2.0 * (1.0 + nu));
    let a = PI * radius * radius;
    let i = PI * radius.powi(4) / 4.0;
    (e * i, g * 2.0 * i, e * a, k * g * a)
}

/// The tip criterion on a tip compliance `c` (SI, world) of a rod of length `l` and force
/// scale `fs` (`E I(0) / L²`): the smallest `1/μ` over the eigenvalues `μ` of the symmetric
/// part of `(E I(0) / L) D⁻¹ c D⁻¹`, directions of zero compliance (below 1e-9 of the
/// largest: the held normals) left out.
pub fn tip_criterion(c: &Matrix6<f64>, l: f64, fs: f64) -> f64 {
    let d = |i: usize| if i < 3 { l } else { 1.0 };
    let hat = Matrix6::from_fn(|i, k| c[(i, k)] * fs * l / (d(i) * d(k)));
    let eig = softrod::nalgebra::SymmetricEigen::new((hat + hat.transpose()) * 0.5).eigenvalues;
    let big = eig.amax();
    eig.iter()
        .filter(|mu| mu.abs() > 1e-9 * big)
        .map(|mu| 1.0 / mu)
        .fold(f64::INFINITY, f64::min)
}
