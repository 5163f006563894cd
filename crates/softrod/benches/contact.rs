//! A contact solve of the two-segment NiTi tendon robot against one sphere vs its
//! contact-free solve (both from a straight initial guess), and a pinned tip.
//!
//! Run: `cargo bench -p softrod --bench contact`.
#![allow(missing_docs, clippy::unwrap_used)]

#[path = "../tests/common/robot.rs"]
mod robot;

use std::hint::black_box;
use std::sync::Arc;

use criterion::{criterion_group, criterion_main, Criterion};
use softrod::{
    solve_constrained, solve_statics, Actuation, Loads, Obstacle, RobotModel, SolveOptions,
    TipConstraint,
};

fn niti() -> Arc<RobotModel> {
    robot::niti_model(Loads::default(), None, 0.0)
}

fn bench(c: &mut Criterion) {
    let model = niti();
    let opts = SolveOptions::default();
    let act = Actuation::tensions(&[3.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    let sphere = [Obstacle::sphere([0.0, 0.07, 0.25], 0.06).unwrap()];
    let touched = solve_constrained(&model, &act, &opts, None, &sphere).unwrap();
    assert!(
        !touched.contacts.is_empty(),
        "the benchmark case must touch the sphere"
    );
    let free = solve_statics(&model, &act, &opts).unwrap();
    let tip = free.tip_position();
    let pin = TipConstraint::pin([tip[0] * 0.9, tip[1] * 0.9, tip[2]]).unwrap();
    let mut g = c.benchmark_group("niti_contact");
    g.bench_function("contact_free", |b| {
        b.iter(|| solve_statics(black_box(&model), &act, &opts).unwrap())
    });
    g.bench_function("sphere_contact", |b| {
        b.iter(|| solve_constrained(black_box(&model), &act, &opts, None, &sphere).unwrap())
    });
    g.bench_function("pinned_tip", |b| {
        b.iter(|| solve_constrained(black_box(&model), &act, &opts, Some(&pin), &[]).unwrap())
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
