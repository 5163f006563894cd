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

#[path = "../tests/common/robot.rs"]
mod robot;

use std::hint::black_box;
use std::sync::Arc;

use softrod::nalgebra::Vector3;
use softrod::{
    solve_frictional, solve_statics, Actuation, FrictionOptions, Integrator, Loads, RobotModel,
};

fn niti(mu: f64) -> Arc<RobotModel> {
    robot::niti_model(Loads::tip_force(Vector3::new(0.05, -0.02, 0.0)), None, mu)
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
