//! Compliance along the arm vs the statics solve alone, the tangent compliance, and a
//! 10 000-configuration workspace map of the two-segment NiTi tendon robot.
//!
//! Run: `CARGO_TARGET_DIR=... cargo bench -p softrod --bench compliance`.
#![allow(missing_docs, clippy::unwrap_used)]

#[path = "../tests/common/robot.rs"]
mod robot;

use std::sync::Arc;

use criterion::{criterion_group, criterion_main, Criterion};
use softrod::batch::workspace::{workspace_map, DEFAULT_CHUNK};
use softrod::compliance::{compliance, tangent_compliance, TendonControl};
use softrod::nalgebra::Vector3;
use softrod::{solve_statics, Actuation, Loads, RobotModel, SolveOptions};
use std::hint::black_box;

fn niti(loads: Loads) -> Arc<RobotModel> {
    robot::niti_model(loads, None, 0.0)
}

fn bench(c: &mut Criterion) {
    let opts = SolveOptions::default();
    let act = Actuation::tensions(&[4.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    for (name, loads) in [
        ("tendons_only", Loads::default()),
        ("tip_force", Loads::tip_force(Vector3::new(0.05, 0.0, 0.0))),
    ] {
        let model = niti(loads);
        let mut g = c.benchmark_group(format!("compliance_niti_{name}"));
        let sol = solve_statics(&model, &act, &opts).unwrap();
        g.bench_function("solve", |b| {
            b.iter(|| solve_statics(&model, black_box(&act), &opts).unwrap())
        });
        g.bench_function("compliance_along_arm", |b| {
            b.iter(|| compliance(black_box(&sol)).unwrap())
        });
        g.bench_function("compliance_with_stiffness_and_condition", |b| {
            b.iter(|| {
                let c = compliance(black_box(&sol)).unwrap();
                (c.stiffness_world(), c.stiffness_body())
            })
        });
        g.bench_function("solve_plus_compliance", |b| {
            b.iter(|| {
                let s = solve_statics(&model, black_box(&act), &opts).unwrap();
                compliance(&s).unwrap()
            })
        });
        for (mode, ctl) in [
            ("tension", TendonControl::Tension),
            ("length", TendonControl::Length),
        ] {
            g.bench_function(format!("tangent_tip_{mode}"), |b| {
                b.iter(|| tangent_compliance(black_box(&sol), ctl, None).unwrap())
            });
        }
        g.finish();
    }
    let model = niti(Loads::default());
    let mut tensions = Vec::with_capacity(60_000);
    for i in 0..100 {
        for j in 0..100 {
            // Boustrophedon rows so that neighbours in a chunk are close.
            let jj = if i % 2 == 0 { j } else { 99 - j };
            let mut t = [0.0; 6];
            t[0] = 4.0 * i as f64 / 99.0;
            t[4] = 2.0 * jj as f64 / 99.0;
            tensions.extend_from_slice(&t);
        }
    }
    let mut g = c.benchmark_group("workspace_map_niti");
    g.sample_size(10);
    g.bench_function("10000_configurations", |b| {
        b.iter(|| {
            workspace_map(
                &model,
                &Actuation::default(),
                black_box(&tensions),
                &opts,
                DEFAULT_CHUNK,
                None,
            )
            .unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
