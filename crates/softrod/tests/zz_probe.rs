#![allow(clippy::unwrap_used, missing_docs)]
mod common;
use softrod::{solve_constrained, solve_statics, Actuation, Loads, Obstacle, SolveOptions};
use std::time::Instant;

#[test]
fn probe() {
    let rod = common::niti_rod();
    let tendons = common::niti_tendons(&[3.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    let (model, act) = common::split(&rod, &tendons, &[], &Loads::default()).unwrap();
    let _ = Actuation::default();
    let opts = SolveOptions::default();
    let sphere = [Obstacle::sphere([0.0, 0.07, 0.25], 0.06).unwrap()];
    let n = std::env::var("N").map_or(30, |v| v.parse().unwrap());
    let mut tf = vec![];
    let mut tc = vec![];
    let mut sol = None;
    for _ in 0..n {
        let t = Instant::now();
        let f = solve_statics(&model, &act, &opts).unwrap();
        tf.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let s = solve_constrained(&model, &act, &opts, None, &sphere).unwrap();
        tc.push(t.elapsed().as_secs_f64());
        std::hint::black_box(f);
        sol = Some(s);
    }
    tf.sort_by(f64::total_cmp);
    tc.sort_by(f64::total_cmp);
    let s = sol.unwrap();
    println!(
        "free {:.1} us, contact {:.1} us, ratio {:.1}; stats {:?}; contacts {:?}",
        tf[n / 2] * 1e6,
        tc[n / 2] * 1e6,
        tc[n / 2] / tf[n / 2],
        s.solution.stats,
        s.contacts
    );
}
