//! Inverse statics of the two-segment NiTi tendon robot (default RK4 options): one forward
//! evaluation with its actuation Jacobian, one probe (the march of the state alone, for the
//! curvature), the inverse cold (from zero tensions) and warm (from the solution at a target
//! 1 mm away).
//!
//! Run: `cargo bench -p softrod --bench inverse`.
#![allow(missing_docs, clippy::unwrap_used)]

#[path = "../tests/common/robot.rs"]
mod robot;

use std::hint::black_box;
use std::sync::Arc;

use criterion::{criterion_group, criterion_main, Criterion};
use softrod::nalgebra::Vector3;
use softrod::{
    inverse_statics, solve_statics, Actuation, CosseratForward, Forward, InverseOptions,
    InverseWarmStart, Loads, RobotModel, SolveOptions, Target,
};

fn niti() -> Arc<RobotModel> {
    robot::niti_model(Loads::default(), None, 0.0)
}

fn bench(c: &mut Criterion) {
    let model = niti();
    let o = SolveOptions::default();
    let t = robot::NITI_REFERENCE_TENSIONS;
    let tip = robot::niti_reference_tip(&model, &o);
    let opts = InverseOptions::default();
    let (first, _) = inverse_statics(&model, &Target::tip(tip), &opts, &o, None).unwrap();
    let warm = InverseWarmStart::from(&first);
    let moved = Target::tip(tip + Vector3::new(1e-3, 0.0, 0.0));
    let mut g = c.benchmark_group("inverse_niti");
    let mut fwd = CosseratForward::new(&model, &o, None).unwrap();
    g.bench_function("evaluation_with_jacobian", |b| {
        b.iter(|| fwd.evaluate(black_box(&t), true).unwrap());
    });
    g.bench_function("probe", |b| {
        b.iter(|| fwd.probe(black_box(&t)).unwrap());
    });
    g.bench_function("forward_solve", |b| {
        b.iter(|| solve_statics(&model, &Actuation::tensions(black_box(&t)), &o).unwrap());
    });
    g.bench_function("cold", |b| {
        b.iter(|| inverse_statics(&model, &Target::tip(tip), &opts, &o, None).unwrap());
    });
    g.bench_function("warm_1mm", |b| {
        b.iter(|| inverse_statics(&model, &moved, &opts, &o, Some(&warm)).unwrap());
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30);
    targets = bench
}
criterion_main!(benches);
