//! Tendon friction on the two-segment NiTi robot (tensions [4, 0, 0, 0, 2, 0] N, 50 RK4
//! steps): the frictionless solve at the default nodes and at the friction mesh, and the
//! frictional solve (μ = 0.1 and 0.2) from rest and as an unloading step, side by side; and
//! the tendons through 8 disks per segment (tensions `τ (1, 0, 0.3, 0, 0.5, 0.1)` N, from
//! rest, default options) with the exact and the forward-difference Jacobian of the guide
//! forces, beside the same tendons in continuous channels.
//!
//! Run: `cargo bench -p softrod --bench friction`.
#![allow(missing_docs, clippy::unwrap_used)]

#[path = "../tests/common/robot.rs"]
mod robot;

use std::hint::black_box;
use std::sync::Arc;

use criterion::{criterion_group, criterion_main, Criterion};
use softrod::nalgebra::Vector3;
use softrod::{
    friction_mesh, solve_frictional, solve_statics, solve_statics_at, Actuation, FrictionOptions,
    GuideMethod, Integrator, Loads, RobotModel,
};

fn niti(mu: f64) -> Arc<RobotModel> {
    niti_with(mu, Loads::default())
}

fn niti_with(mu: f64, loads: Loads) -> Arc<RobotModel> {
    robot::niti_model(loads, None, mu)
}

/// The NiTi robot with its tendons through 8 equally spaced disks per segment (coefficient
/// `mu` at each).
fn guided(mu: f64) -> Arc<RobotModel> {
    robot::guided_niti(mu, 8)
}

fn guides(c: &mut Criterion) {
    let exact = FrictionOptions::default();
    let fd = FrictionOptions {
        guide_method: GuideMethod::NewtonFiniteDifferences,
        ..Default::default()
    };
    let mut g = c.benchmark_group("guides_niti");
    g.sample_size(10);
    for (mu, tau) in [(0.0, 1.0), (0.2, 4.0)] {
        let act = Actuation::tensions(&[tau, 0.0, 0.3 * tau, 0.0, 0.5 * tau, 0.1 * tau]);
        let channel = niti(mu);
        let disks = guided(mu);
        g.bench_function(format!("mu_{mu}_tau_{tau}_channel"), |b| {
            b.iter(|| solve_frictional(black_box(&channel), &act, &exact, None).unwrap())
        });
        g.bench_function(format!("mu_{mu}_tau_{tau}_guided_exact"), |b| {
            b.iter(|| solve_frictional(black_box(&disks), &act, &exact, None).unwrap())
        });
        g.bench_function(format!("mu_{mu}_tau_{tau}_guided_fd"), |b| {
            b.iter(|| solve_frictional(black_box(&disks), &act, &fd, None).unwrap())
        });
    }
    g.finish();
}

fn friction(c: &mut Criterion) {
    let mut opts = FrictionOptions::default();
    opts.statics.integrator = Integrator::Rk4 { steps: 50 };
    let act = Actuation::tensions(&[4.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    let release = Actuation::tensions(&[3.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    let plain = niti(0.0);
    let mesh = friction_mesh(&plain, &opts.statics.integrator);
    let mut g = c.benchmark_group("friction_niti");
    g.bench_function("frictionless", |b| {
        b.iter(|| solve_statics(black_box(&plain), &act, &opts.statics).unwrap())
    });
    g.bench_function("frictionless_at_friction_mesh", |b| {
        b.iter(|| solve_statics_at(black_box(&plain), &act, &opts.statics, &mesh).unwrap())
    });
    for mu in [0.1, 0.2] {
        let model = niti(mu);
        g.bench_function(format!("mu_{mu}_from_rest"), |b| {
            b.iter(|| solve_frictional(black_box(&model), &act, &opts, None).unwrap())
        });
        let first = solve_frictional(&model, &act, &opts, None).unwrap();
        g.bench_function(format!("mu_{mu}_unloading_step"), |b| {
            b.iter(|| solve_frictional(black_box(&model), &release, &opts, Some(&first)).unwrap())
        });
    }
    g.finish();
    // With a tip force (N): Newton on the base wrench, one frictional march per iterate.
    let tip = Loads::tip_force(Vector3::new(0.05, -0.02, 0.0));
    let plain = niti_with(0.0, tip.clone());
    let mut g = c.benchmark_group("friction_niti_tip_force");
    g.bench_function("frictionless", |b| {
        b.iter(|| solve_statics(black_box(&plain), &act, &opts.statics).unwrap())
    });
    for mu in [0.1, 0.2] {
        let model = niti_with(mu, tip.clone());
        g.bench_function(format!("mu_{mu}_from_rest"), |b| {
            b.iter(|| solve_frictional(black_box(&model), &act, &opts, None).unwrap())
        });
        let first = solve_frictional(&model, &act, &opts, None).unwrap();
        g.bench_function(format!("mu_{mu}_unloading_step"), |b| {
            b.iter(|| solve_frictional(black_box(&model), &release, &opts, Some(&first)).unwrap())
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(2));
    targets = friction, guides
}
criterion_main!(benches);
