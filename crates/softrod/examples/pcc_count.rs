//! Instruction-count harness (`valgrind --tool=callgrind`): N PCC statics solves of one case
//! of `benches/pcc.rs` (0 tendons only, 1 0.02 N, 2 0.1 N tip force, 3 tip wrench).
#![allow(missing_docs, clippy::unwrap_used)]
use softrod::nalgebra::Vector3;
use softrod::pcc::statics::{solve_pcc_statics, PccLoads, PccRobot, PccSolveOptions};
use softrod::pcc::{ElasticSegment, PccTendons};
use std::hint::black_box;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let case: usize = args[1].parse().unwrap();
    let n: usize = args[2].parse().unwrap();
    let body = ElasticSegment::solid_circle(0.2, 0.0007, 54e9, true).unwrap();
    let angles: Vec<f64> = [90.0f64, -30.0, 210.0]
        .iter()
        .map(|a| a.to_radians())
        .collect();
    let tendons = PccTendons::new(&[0.01; 3], &angles).unwrap();
    let robot = PccRobot::new(vec![body, body])
        .unwrap()
        .with_segment_tendons(0, &tendons)
        .unwrap()
        .with_segment_tendons(1, &tendons)
        .unwrap();
    let tensions = vec![4.0, 0.0, 0.0, 0.0, 2.0, 0.0];
    let (force, moment) = [
        ([0.0; 3], [0.0; 3]),
        ([0.0, -0.02, 0.0], [0.0; 3]),
        ([0.0, -0.1, 0.0], [0.0; 3]),
        ([0.01, -0.02, 0.005], [1e-3, 0.0, -5e-4]),
    ][case];
    let loads = PccLoads {
        tensions,
        tip_force: Vector3::from(force),
        tip_moment: Vector3::from(moment),
        ..Default::default()
    };
    let opts = PccSolveOptions::default();
    let mut acc = 0.0;
    for _ in 0..n {
        let s = solve_pcc_statics(&robot, black_box(&loads), &opts).unwrap();
        acc += s.tip_pose[(0, 3)];
    }
    println!("{acc}");
}
