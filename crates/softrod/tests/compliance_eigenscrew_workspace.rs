//! Eigenscrews of stiffnesses built from known screws; the workspace map against single solves.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use softrod::batch::workspace::workspace_map;
use softrod::compliance::eigenscrew::{eigenscrews, MatrixKind};
use softrod::compliance::{compliance, tangent_compliance, TendonControl};
use softrod::math::se3::{adjoint, delta};
use softrod::math::so3::exp_so3;
use softrod::nalgebra::{Matrix6, Vector3, Vector6};
use softrod::{Loads, SolveOptions};

/// Unit twist about the axis through `c` along unit `a` with pitch `h`: `[c × a + h a; a]`.
fn twist(a: Vector3<f64>, c: Vector3<f64>, h: f64) -> Vector6<f64> {
    let v = c.cross(&a) + a * h;
    Vector6::new(v.x, v.y, v.z, a.x, a.y, a.z)
}

#[test]
fn eigenscrews_recover_the_screws_a_stiffness_was_built_from() {
    // Six mutually reciprocal screws: on each coordinate axis pitches +h and -h, then moved
    // rigidly (the adjoint preserves reciprocity).
    let g = adjoint(
        &exp_so3(&Vector3::new(0.3, -0.5, 0.8)),
        &Vector3::new(0.05, -0.02, 0.1),
    );
    let pitches = [0.02, 0.05, 0.11];
    let kappas = [[300.0, -40.0], [120.0, -7.0], [55.0, -900.0]];
    let mut screws = Vec::new();
    let mut k = Matrix6::zeros();
    for ax in 0..3 {
        let mut a = Vector3::zeros();
        a[ax] = 1.0;
        for (sgn, kappa) in [(1.0, kappas[ax][0]), (-1.0, kappas[ax][1])] {
            let xi = g * twist(a, Vector3::zeros(), sgn * pitches[ax]);
            let dxi = delta() * xi;
            let sigma = xi.dot(&dxi);
            k += dxi * dxi.transpose() * (kappa / sigma);
            screws.push((kappa, xi));
        }
    }
    assert!(k.symmetric_eigen().eigenvalues.min() > 0.0);
    let d = eigenscrews(&k, MatrixKind::Stiffness).unwrap();
    for (kappa, xi) in &screws {
        let s = d
            .screws
            .iter()
            .find(|s| ((s.value - kappa) / kappa).abs() < 1e-10)
            .unwrap_or_else(|| panic!("eigenstiffness {kappa} not found"));
        let om = Vector3::new(xi[3], xi[4], xi[5]);
        let v = Vector3::new(xi[0], xi[1], xi[2]);
        let dir = om / om.norm();
        let pitch = om.dot(&v) / om.norm_squared();
        let point = om.cross(&v) / om.norm_squared();
        let got = Vector3::from(s.direction);
        assert!((got - dir).norm() < 1e-10 || (got + dir).norm() < 1e-10);
        assert!((s.pitch - pitch).abs() < 1e-10);
        assert!((Vector3::from(s.point) - point).norm() < 1e-10);
    }
    // The compliance has the same screws with eigenvalues 1/kappa.
    let dc = eigenscrews(&k.try_inverse().unwrap(), MatrixKind::Compliance).unwrap();
    for (kappa, _) in &screws {
        assert!(dc
            .screws
            .iter()
            .any(|s| ((s.value * kappa) - 1.0).abs() < 1e-9));
    }
    // Ellipsoids: eigen-decomposition of the compliance blocks.
    let c = k.try_inverse().unwrap();
    let ctt = c.fixed_view::<3, 3>(0, 0).into_owned();
    for (ax, dir) in d.translational.directions.iter().enumerate() {
        let u = Vector3::from(*dir);
        assert!((ctt * u - u * d.translational.semi_axes[ax]).norm() < 1e-10 * ctt.amax());
    }
}

#[test]
fn workspace_map_matches_single_solves() {
    let rod = common::niti_rod();
    let tendons = common::niti_tendons(&[0.0; 6]);
    let loads = Loads::default();
    let opts = SolveOptions::default();
    let mut tensions = Vec::new();
    for i in 0..6 {
        for j in 0..5 {
            let mut t = [0.0; 6];
            t[0] = 0.8 * i as f64;
            t[4] = 0.5 * j as f64;
            tensions.extend_from_slice(&t);
        }
    }
    let (model, base) = common::split(&rod, &tendons, &[], &loads).unwrap();
    let map = workspace_map(
        &model,
        &base,
        &tensions,
        &opts,
        7,
        Some(TendonControl::Length),
    )
    .unwrap();
    assert_eq!(map.len(), 30);
    for (i, row) in tensions.chunks(6).enumerate() {
        let ts: Vec<common::Tensioned> = tendons
            .iter()
            .zip(row)
            .map(|(t, &tau)| t.with_tension(tau).unwrap())
            .collect();
        let sol = common::solve(&rod, &ts, &loads, &opts).unwrap();
        let tip = Vector3::from(sol.tip_position());
        assert!(map[i].converged);
        assert!((Vector3::from(map[i].tip_position) - tip).norm() < 1e-9);
        let c = compliance(&sol).unwrap().tip_world();
        let ctt = c
            .fixed_view::<3, 3>(0, 0)
            .into_owned()
            .symmetric_eigen()
            .eigenvalues;
        assert!((map[i].max_translational_compliance - ctt.max()).abs() < 1e-8 * ctt.max());
        let t = tangent_compliance(&sol, TendonControl::Length, None).unwrap();
        let b = t.world.fixed_view::<3, 3>(0, 0).into_owned();
        let e = ((b + b.transpose()) * 0.5)
            .symmetric_eigen()
            .eigenvalues
            .max();
        assert!((map[i].tangent_max_translational_compliance - e).abs() < 1e-6 * e);
    }
}
