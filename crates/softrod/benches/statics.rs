//! Cosserat-rod statics: the two-segment NiTi tendon robot (cold and warm-started solves) and
//! a planar soft cantilever under a tip force.
//!
//! Run: `CARGO_TARGET_DIR=... cargo bench -p softrod --bench statics`.
#![allow(missing_docs, clippy::unwrap_used)]

use criterion::{criterion_group, criterion_main, Criterion};
use softrod::nalgebra::Vector3;
use softrod::{solve_statics, LinearElastic, Loads, Rod, Section, SolveOptions, Tendon};
use std::hint::black_box;

fn two_segment(tensions: &[f64; 6]) -> Vec<Tendon> {
    (0..6)
        .map(|i| {
            let ang = [90.0f64, -30.0, 210.0][i % 3].to_radians();
            Tendon::constant(
                [0.01 * ang.cos(), 0.01 * ang.sin()],
                tensions[i],
                Some(if i < 3 { 0.2 } else { 0.4 }),
            )
            .unwrap()
        })
        .collect()
}

fn statics(c: &mut Criterion) {
    let rod = Rod::new(
        0.4,
        Section::circular(0.7e-3).unwrap(),
        LinearElastic::new(54e9, 0.3).unwrap(),
    )
    .unwrap();
    let opts = SolveOptions::default();
    let loads = Loads::default();
    let tendons = two_segment(&[4.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    let changed = two_segment(&[4.08, 0.0, 0.0, 0.0, 2.04, 0.0]);
    let prev = solve_statics(&rod, &tendons, &loads, &opts).unwrap();
    let warm = SolveOptions {
        warm_start: Some(prev.warm_start()),
        ..opts
    };
    let mut g = c.benchmark_group("statics_two_segment_niti");
    g.bench_function("cold", |b| {
        b.iter(|| solve_statics(&rod, black_box(&tendons), &loads, &opts).unwrap())
    });
    g.bench_function("warm_2pct", |b| {
        b.iter(|| solve_statics(&rod, black_box(&changed), &loads, &warm).unwrap())
    });
    // The same robot with a small tip force, so that Newton iterations are needed.
    let tip = Loads::tip_force(Vector3::new(0.05, 0.0, 0.0));
    g.bench_function("cold_with_tip_force", |b| {
        b.iter(|| solve_statics(&rod, black_box(&tendons), &tip, &opts).unwrap())
    });
    let prev_tip = solve_statics(&rod, &tendons, &tip, &opts).unwrap();
    let warm_tip = SolveOptions {
        warm_start: Some(prev_tip.warm_start()),
        ..opts
    };
    g.bench_function("warm_2pct_with_tip_force", |b| {
        b.iter(|| solve_statics(&rod, black_box(&changed), &tip, &warm_tip).unwrap())
    });
    g.finish();

    let soft = Rod::new(
        0.27,
        Section::circular(0.01).unwrap(),
        LinearElastic::new(110e3, 0.5).unwrap(),
    )
    .unwrap();
    let f = Loads::tip_force(Vector3::new(0.02, 0.0, 0.0));
    let mut g = c.benchmark_group("statics_soft_cantilever");
    g.bench_function("tip_force_0.02N", |b| {
        b.iter(|| solve_statics(black_box(&soft), &[], &f, &opts).unwrap())
    });
    g.finish();
}

criterion_group!(benches, statics);
criterion_main!(benches);
