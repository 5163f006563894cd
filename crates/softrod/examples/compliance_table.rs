//! Side by side: the paper's integrated tip compliance, the exact tangent compliance (tendons at
//! fixed tension and at fixed length) and a central finite difference of the nonlinear solve,
//! on the two-segment NiTi robot as load and actuation grow.
//!
//! Run: `cargo run --release -p softrod --example compliance_table`.
#![allow(clippy::unwrap_used, missing_docs)]

#[path = "../tests/common/robot.rs"]
mod common;

use softrod::compliance::{compliance, tangent_compliance, tangent_compliance_held, TendonControl};
use softrod::nalgebra::{Matrix3, Matrix6, Rotation3, Vector3, Vector6};
use softrod::{Integrator, LinearElastic, Loads, Rod, Section, SolveOptions, StaticsSolution};

fn rot(sol: &StaticsSolution) -> Matrix3<f64> {
    let r = sol.rotation.last().unwrap();
    Matrix3::new(
        r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1], r[2][2],
    )
}

/// Central difference (Richardson-extrapolated) of the tip twist w.r.t. the world tip wrench.
fn finite_difference(
    rod: &Rod,
    tendons: &[common::Tensioned],
    loads: &Loads,
    opts: &SolveOptions,
    sol: &StaticsSolution,
    scale: &Matrix6<f64>,
) -> Matrix6<f64> {
    let central = |j: usize, eps: f64| {
        let (mut p, mut m) = (loads.clone(), loads.clone());
        if j < 3 {
            p.tip_force[j] += eps;
            m.tip_force[j] -= eps;
        } else {
            p.tip_moment[j - 3] += eps;
            m.tip_moment[j - 3] -= eps;
        }
        let o = SolveOptions {
            warm_start: Some(sol.warm_start()),
            ..*opts
        };
        let (a, b) = (
            common::solve(rod, tendons, &m, &o).unwrap(),
            common::solve(rod, tendons, &p, &o).unwrap(),
        );
        let dp = Vector3::from(b.tip_position()) - Vector3::from(a.tip_position());
        let th = Rotation3::from_matrix_unchecked(rot(&b) * rot(&a).transpose()).scaled_axis();
        Vector6::new(dp.x, dp.y, dp.z, th.x, th.y, th.z) / (2.0 * eps)
    };
    let mut c = Matrix6::zeros();
    for j in 0..6 {
        let eps = 1e-3
            * if j < 3 {
                0.4 / scale[(j, j)]
            } else {
                1.0 / scale[(j, j)]
            };
        c.set_column(j, &((central(j, 0.5 * eps) * 4.0 - central(j, eps)) / 3.0));
    }
    c
}

/// Largest block-relative difference: max over the four 3×3 blocks of `|a - b|max / |b|max`.
fn rel(a: &Matrix6<f64>, b: &Matrix6<f64>) -> f64 {
    let mut worst = 0.0f64;
    for i in 0..2 {
        for j in 0..2 {
            let (x, y) = (
                a.fixed_view::<3, 3>(3 * i, 3 * j),
                b.fixed_view::<3, 3>(3 * i, 3 * j),
            );
            worst = worst.max((x - y).amax() / y.amax());
        }
    }
    worst
}

fn max_translational(c: &Matrix6<f64>) -> f64 {
    let t = c.fixed_view::<3, 3>(0, 0).into_owned();
    ((t + t.transpose()) * 0.5)
        .symmetric_eigen()
        .eigenvalues
        .max()
}

fn main() {
    let rod = Rod::new(
        0.4,
        Section::circular(0.7e-3).unwrap(),
        LinearElastic::new(54e9, 0.3).unwrap(),
    )
    .unwrap();
    let opts = SolveOptions {
        integrator: Integrator::Rk4 { steps: 200 },
        newton: softrod::NewtonOptions {
            tolerance: 1e-13,
            ..SolveOptions::default().newton
        },
        ..Default::default()
    };
    println!("Two-segment NiTi robot, tensions = scale x [4, 0, 0, 0, 2, 0] N, world tip force [f_x, 0, 0] N;");
    println!("largest translational tip compliance (m/N) and block-relative differences.\n");
    println!("| scale | f_x (N) | integrated | tangent (tension) | finite diff. | integrated vs tangent | tangent vs FD | tangent (all 6 lengths held) | ratio | tangent (tensioned held) | ratio |");
    println!("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for scale in [0.0, 0.5, 1.0] {
        for fx in [0.0, 0.1, 0.3] {
            let t = [4.0, 0.0, 0.0, 0.0, 2.0, 0.0].map(|v| v * scale);
            let tendons = common::niti_tendons(&t);
            let loads = Loads::tip_force(Vector3::new(fx, 0.0, 0.0));
            let sol = common::solve(&rod, &tendons, &loads, &opts).unwrap();
            let c = compliance(&sol).unwrap().tip_world();
            let ten = tangent_compliance(&sol, TendonControl::Tension, None).unwrap();
            let len = tangent_compliance(&sol, TendonControl::Length, None).unwrap();
            let tensioned: Vec<usize> = (0..6).filter(|&i| t[i] > 0.0).collect();
            let part = tangent_compliance_held(&sol, &tensioned, None).unwrap();
            let fd = finite_difference(&rod, &tendons, &loads, &opts, &sol, &ten.world);
            println!(
                "| {scale:.1} | {fx:.1} | {:.5} | {:.5} | {:.5} | {:.2e} | {:.2e} | {:.5} | {:.3} | {:.5} | {:.3} |",
                max_translational(&c),
                max_translational(&ten.world),
                max_translational(&fd),
                rel(&c, &ten.world),
                rel(&ten.world, &fd),
                max_translational(&len.world),
                max_translational(&len.world) / max_translational(&ten.world),
                max_translational(&part.world),
                max_translational(&part.world) / max_translational(&ten.world),
            );
        }
    }
}
