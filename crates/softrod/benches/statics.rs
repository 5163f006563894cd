//! Cosserat-rod statics: the two-segment NiTi tendon robot (cold and warm-started solves,
//! unloaded and with a 0.05 N tip force), a 1 m four-tendon robot under gravity and a planar
//! soft cantilever under a tip force.
//!
//! Run: `CARGO_TARGET_DIR=... cargo bench -p softrod --bench statics`.
#![allow(missing_docs, clippy::unwrap_used)]

#[path = "../tests/common/robot.rs"]
mod robot;

use std::sync::Arc;

use criterion::{criterion_group, criterion_main, Criterion};
use softrod::nalgebra::Vector3;
use softrod::{
    solve_statics, Actuation, LinearElastic, Loads, RobotModel, Rod, Section, SolveOptions,
};
use std::hint::black_box;

/// The two-segment NiTi robot under `loads`.
fn niti(loads: Loads) -> Arc<RobotModel> {
    robot::niti_model(loads, None, 0.0)
}

fn statics(c: &mut Criterion) {
    let opts = SolveOptions::default();
    let act = Actuation::tensions(&[4.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    let changed = Actuation::tensions(&[4.08, 0.0, 0.0, 0.0, 2.04, 0.0]);
    let mut g = c.benchmark_group("statics_two_segment_niti");
    for (suffix, loads) in [
        ("", Loads::default()),
        // The same robot with a small tip force, so that Newton iterations are needed.
        (
            "_with_tip_force",
            Loads::tip_force(Vector3::new(0.05, 0.0, 0.0)),
        ),
    ] {
        let model = niti(loads);
        let prev = solve_statics(&model, &act, &opts).unwrap();
        let warm = SolveOptions {
            warm_start: Some(prev.warm_start()),
            ..opts
        };
        g.bench_function(format!("cold{suffix}"), |b| {
            b.iter(|| solve_statics(&model, black_box(&act), &opts).unwrap())
        });
        g.bench_function(format!("warm_2pct{suffix}"), |b| {
            b.iter(|| solve_statics(&model, black_box(&changed), &warm).unwrap())
        });
    }
    g.finish();

    let mut g = c.benchmark_group("statics_four_tendon_1m");
    let model = robot::four_tendon_gravity();
    let act4 = Actuation::tensions(&[2.0, 0.0, 1.0, 0.0]);
    g.bench_function("gravity_cold", |b| {
        b.iter(|| solve_statics(&model, black_box(&act4), &opts).unwrap())
    });
    g.finish();

    let soft = Rod::new(
        0.27,
        Section::circular(0.01).unwrap(),
        LinearElastic::new(110e3, 0.5).unwrap(),
    )
    .unwrap();
    let model = RobotModel::rod_only(soft, Loads::tip_force(Vector3::new(0.02, 0.0, 0.0))).unwrap();
    let none = Actuation::default();
    let mut g = c.benchmark_group("statics_soft_cantilever");
    g.bench_function("tip_force_0.02N", |b| {
        b.iter(|| solve_statics(black_box(&model), &none, &opts).unwrap())
    });
    g.finish();
}

criterion_group!(benches, statics);
criterion_main!(benches);
