//! A fixed workload for instruction counts of the frictional solve with a tip force: the
//! two-segment NiTi robot (tip force (0.05, -0.02, 0) N, tensions [4, 0, 0, 0, 2, 0] N, 40
//! RK4 steps), `n` solves of one case: `plain` (frictionless), `rest` (frictional from rest)
//! or `unload` (tendon 1 released to 3 N from the state at rest). Prints the marches and
//! cell steps of the frictional solves.
//!
//! Run: `valgrind --tool=callgrind target/release/examples/friction_workload rest 0.2 11`
//! (after `cargo build --release -p softrod --example friction_workload`); the count of one
//! solve is the difference of 11 and 1 solves divided by 10.
#![allow(missing_docs, clippy::unwrap_used)]

use std::hint::black_box;
use std::sync::Arc;

use softrod::nalgebra::Vector3;
use softrod::{
    solve_frictional, solve_statics, Actuation, FrictionOptions, Integrator, LinearElastic, Loads,
    RobotModel, Rod, Section, Tendon,
};

fn niti(mu: f64) -> Arc<RobotModel> {
    let rod = Rod::new(
        0.4,
        Section::circular(0.7e-3).unwrap(),
        LinearElastic::new(54e9, 0.3).unwrap(),
    )
    .unwrap();
    let tendons = (0..6)
        .map(|i| {
            let ang = [90.0f64, -30.0, 210.0][i % 3].to_radians();
            let end = Some(if i < 3 { 0.2 } else { 0.4 });
            Tendon::constant([0.01 * ang.cos(), 0.01 * ang.sin()], end)
                .unwrap()
                .with_friction(mu)
                .unwrap()
        })
        .collect();
    let loads = Loads::tip_force(Vector3::new(0.05, -0.02, 0.0));
    RobotModel::new(rod, tendons, Vec::new(), loads).unwrap()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let case = args.get(1).map_or("rest", String::as_str);
    let mu: f64 = args.get(2).map_or(0.2, |v| v.parse().unwrap());
    let n: usize = args.get(3).map_or(1, |v| v.parse().unwrap());
    let mut opts = FrictionOptions::default();
    opts.statics.integrator = Integrator::Rk4 { steps: 40 };
    let act = Actuation::tensions(&[4.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    let release = Actuation::tensions(&[3.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    let model = niti(if case == "plain" { 0.0 } else { mu });
    let first = solve_frictional(&model, &act, &opts, None).unwrap();
    let step = solve_frictional(&model, &release, &opts, Some(&first)).unwrap();
    println!(
        "from rest: {} marches, {} cell steps; unloading step: {} marches, {} cell steps",
        first.iterations, first.cell_steps, step.iterations, step.cell_steps
    );
    for _ in 0..n {
        match case {
            "plain" => {
                black_box(solve_statics(&model, &act, &opts.statics).unwrap());
            }
            "rest" => {
                black_box(solve_frictional(&model, &act, &opts, None).unwrap());
            }
            _ => {
                black_box(solve_frictional(&model, &release, &opts, Some(&first)).unwrap());
            }
        }
    }
}
