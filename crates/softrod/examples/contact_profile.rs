//! One solve of the benchmark case of `benches/contact.rs` (the two-segment NiTi robot
//! against one sphere, or contact-free), for instruction counts under callgrind:
//!
//! `valgrind --tool=callgrind target/release/examples/contact_profile sphere`
//! (`free` for the contact-free solve, `pin` for the pinned tip).
#![allow(clippy::unwrap_used, clippy::print_stdout)]

#[path = "../tests/common/robot.rs"]
mod robot;

use std::sync::Arc;

use softrod::{
    solve_constrained, solve_statics, Actuation, Loads, Obstacle, RobotModel, SolveOptions,
    TipConstraint,
};

fn niti() -> Arc<RobotModel> {
    robot::niti_model(Loads::default(), None, 0.0)
}

fn main() {
    let which = std::env::args().nth(1).unwrap_or_else(|| "sphere".into());
    let model = niti();
    let opts = SolveOptions::default();
    let act = Actuation::tensions(&[3.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    let sphere = [Obstacle::sphere([0.0, 0.07, 0.25], 0.06).unwrap()];
    match which.as_str() {
        "free" => {
            let s = solve_statics(&model, &act, &opts).unwrap();
            println!("evaluations {}", s.stats.function_evaluations);
        }
        "pin" => {
            let free = solve_statics(&model, &act, &opts).unwrap();
            let tip = free.tip_position();
            let pin = TipConstraint::pin([tip[0] * 0.9, tip[1] * 0.9, tip[2]]).unwrap();
            let s = solve_constrained(&model, &act, &opts, Some(&pin), &[]).unwrap();
            println!(
                "iterations {} evaluations {}",
                s.solution.stats.iterations, s.solution.stats.function_evaluations
            );
        }
        _ => {
            let s = solve_constrained(&model, &act, &opts, None, &sphere).unwrap();
            println!(
                "iterations {} evaluations {} contacts {:?}",
                s.solution.stats.iterations, s.solution.stats.function_evaluations, s.contacts
            );
        }
    }
}
