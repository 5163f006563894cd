//! Instruction-count harness (`valgrind --tool=callgrind`): N inverse statics of the
//! two-segment NiTi tendon robot (default RK4 options), cold from zero tensions (mode 0), warm
//! from the solution at a target 1 mm away (mode 1), or N forward evaluations with the
//! actuation Jacobian (mode 2). Prints the iterations and evaluations of each case on stderr.
//!
//! Run: `cargo build --release -p softrod --example inverse_count` then
//! `valgrind --tool=callgrind target/release/examples/inverse_count MODE N`.
#![allow(missing_docs, clippy::unwrap_used)]

use std::sync::Arc;

#[path = "../tests/common/robot.rs"]
mod robot;

use softrod::nalgebra::Vector3;
use softrod::{
    solve_inverse, CosseratForward, Forward, InverseOptions, InverseWarmStart, Loads, RobotModel,
    SolveOptions, Target,
};

fn niti() -> Arc<RobotModel> {
    robot::niti_model(Loads::default(), None, 0.0)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mode: usize = args.get(1).map_or(1, |a| a.parse().unwrap());
    let n: usize = args.get(2).map_or(10, |a| a.parse().unwrap());
    let model = niti();
    let o = SolveOptions::default();
    let t = robot::NITI_REFERENCE_TENSIONS;
    let tip = robot::niti_reference_tip(&model, &o);
    let io = InverseOptions::default();
    let target = Target::tip(tip);
    let moved = Target::tip(tip + Vector3::new(1e-3, 0.0, 0.0));
    let mut fwd = CosseratForward::new(&model, &o, None).unwrap();
    let cold = solve_inverse(&mut fwd, &target, &io, None).unwrap();
    eprintln!(
        "cold: iterations {} evaluations {} probes {} a {:?}",
        cold.iterations, cold.evaluations, cold.probes, cold.actuation
    );
    let w = InverseWarmStart::from(&cold);
    let warm = solve_inverse(&mut fwd, &moved, &io, Some(&w)).unwrap();
    eprintln!(
        "warm: iterations {} evaluations {} probes {} a {:?} error {:e}",
        warm.iterations, warm.evaluations, warm.probes, warm.actuation, warm.position_error
    );
    // Ten 1 mm steps of a tracked path (as the warm-tracking test of `tests/inverse.rs`).
    let mut w10 = w.clone();
    let mut total = 0u32;
    let mut probes = 0u32;
    for k in 1..=10 {
        let p = Target::tip(tip + Vector3::new(1e-3 * f64::from(k), 0.0, 0.0));
        let r = solve_inverse(&mut fwd, &p, &io, Some(&w10)).unwrap();
        total += u32::try_from(r.evaluations).unwrap();
        probes += u32::try_from(r.probes).unwrap();
        w10 = InverseWarmStart::from(&r);
    }
    eprintln!(
        "tracking: {:.1} evaluations and {:.1} probes per 1 mm step",
        f64::from(total) / 10.0,
        f64::from(probes) / 10.0
    );
    let mut acc = 0.0;
    for _ in 0..n {
        acc += match mode {
            0 => {
                solve_inverse(&mut fwd, &target, &io, None)
                    .unwrap()
                    .actuation[0]
            }
            1 => {
                solve_inverse(&mut fwd, &moved, &io, Some(&w))
                    .unwrap()
                    .actuation[0]
            }
            _ => fwd.evaluate(&t, true).unwrap().positions[0].x,
        };
    }
    println!("{acc}");
}
