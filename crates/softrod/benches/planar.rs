//! The planar arm of the planar cable-arm paper: one solve with 201 samples (closed form and ODE), and a batch.
//!
//! Run: `cargo bench -p softrod --bench planar`.
#![allow(missing_docs, clippy::unwrap_used)]

use criterion::{criterion_group, criterion_main, Criterion};
use softrod::integrate::AdaptiveOptions;
use softrod::{solve_planar, solve_planar_many, uniform_samples, PlanarCableArm, PlanarMethod};
use std::hint::black_box;

fn planar(c: &mut Criterion) {
    let arm = PlanarCableArm::published_arm();
    let s = uniform_samples(arm.length(), 201).unwrap();
    let mut g = c.benchmark_group("planar_published_arm_201_samples");
    for t in [1.0, 5.0] {
        g.bench_function(format!("closed_form_T{t}"), |b| {
            b.iter(|| solve_planar(&arm, black_box(t), &s, PlanarMethod::ClosedForm).unwrap())
        });
    }
    for rtol in [1e-6, 1e-10] {
        let m = PlanarMethod::Ode(AdaptiveOptions {
            rtol,
            atol: rtol * 1e-2,
            ..Default::default()
        });
        g.bench_function(format!("ode_rtol{rtol:e}_T1"), |b| {
            b.iter(|| solve_planar(&arm, black_box(1.0), &s, m).unwrap())
        });
    }
    g.finish();
    let tensions: Vec<f64> = (0..10_000).map(|i| 5.0 * i as f64 / 10_000.0).collect();
    let mut g = c.benchmark_group("planar_batch");
    g.sample_size(10);
    g.bench_function("closed_form_10000x201", |b| {
        b.iter(|| solve_planar_many(&arm, &tensions, &s, PlanarMethod::ClosedForm).unwrap())
    });
    g.finish();
}

criterion_group!(benches, planar);
criterion_main!(benches);
