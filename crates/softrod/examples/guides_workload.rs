//! A fixed workload for instruction counts of the disk-guided solve: the two-segment NiTi
//! robot with its tendons through 8 disks per segment (guide coefficient `mu`), tensions
//! `tau (1, 0, 0.3, 0, 0.5, 0.1)` N from rest, `n` solves of one case: `exact` (Newton on the
//! guide forces with the exact Jacobian, the default), `fd` (the same Newton with the
//! forward-difference Jacobian) or `channel` (the same tendons in continuous channels of
//! coefficient `mu`). Prints the marches of one solve. Case `unload`: the default method's
//! unloading step from `tau` to `0.9 tau` (from the solution at `tau`, guides sticking
//! beyond the slip front), `n` times.
//!
//! Run: `valgrind --tool=callgrind target/release/examples/guides_workload exact 0.2 4 3`
//! (after `cargo build --release -p softrod --example guides_workload`); the count of one
//! solve is the difference of 3 and 1 solves divided by 2.
#![allow(missing_docs, clippy::unwrap_used)]

#[path = "../tests/common/robot.rs"]
mod robot;

use std::hint::black_box;
use std::sync::Arc;

use softrod::{solve_frictional, Actuation, FrictionOptions, GuideMethod, Loads, RobotModel};

/// The NiTi robot with its tendons through 8 equally spaced disks per segment (coefficient
/// `mu` at each).
fn guided(mu: f64) -> Arc<RobotModel> {
    robot::guided_niti(mu, 8)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let case = args.get(1).map_or("exact", String::as_str);
    let mu: f64 = args.get(2).map_or(0.2, |v| v.parse().unwrap());
    let tau: f64 = args.get(3).map_or(4.0, |v| v.parse().unwrap());
    let n: usize = args.get(4).map_or(1, |v| v.parse().unwrap());
    let mut opts = FrictionOptions::default();
    let model = match case {
        "channel" => robot::niti_model(Loads::default(), None, mu),
        "fd" => {
            opts.guide_method = GuideMethod::NewtonFiniteDifferences;
            guided(mu)
        }
        _ => guided(mu),
    };
    let act = Actuation::tensions(&[tau, 0.0, 0.3 * tau, 0.0, 0.5 * tau, 0.1 * tau]);
    let sol = solve_frictional(&model, &act, &opts, None).unwrap();
    if case == "unload" {
        let t = 0.9 * tau;
        let down = Actuation::tensions(&[t, 0.0, 0.3 * t, 0.0, 0.5 * t, 0.1 * t]);
        let back = solve_frictional(&model, &down, &opts, Some(&sol)).unwrap();
        println!(
            "unload, mu = {mu}, {tau} -> {t} N: {} marches",
            back.iterations
        );
        for _ in 0..n {
            black_box(solve_frictional(&model, &down, &opts, Some(&sol)).unwrap());
        }
        return;
    }
    println!(
        "{case}, mu = {mu}, tau = {tau} N: {} marches",
        sol.iterations
    );
    for _ in 0..n {
        black_box(solve_frictional(&model, &act, &opts, None).unwrap());
    }
}
