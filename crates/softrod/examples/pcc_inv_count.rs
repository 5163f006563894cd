//! Instruction-count harness (`valgrind --tool=callgrind`): N PCC inverse statics of the
//! two-segment NiTi robot, cold (mode 0) or warm after a 1 mm move (mode 1).
#![allow(missing_docs, clippy::unwrap_used)]
use softrod::nalgebra::Vector3;
use softrod::pcc::statics::{solve_pcc_statics, PccLoads, PccRobot, PccSolveOptions};
use softrod::pcc::{ElasticSegment, PccTendons};
use softrod::{
    pcc_inverse_statics, solve_inverse, InverseOptions, InverseWarmStart, PccForward, Target,
};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mode: usize = args[1].parse().unwrap();
    let n: usize = args[2].parse().unwrap();
    let ang = [90.0f64, -30.0, 210.0].map(f64::to_radians);
    let tendons = PccTendons::new(&[0.01; 3], &ang).unwrap();
    let seg = || ElasticSegment::solid_circle(0.2, 0.7e-3, 54e9, true).unwrap();
    let robot = PccRobot::new(vec![seg(), seg()])
        .unwrap()
        .with_segment_tendons(0, &tendons)
        .unwrap()
        .with_segment_tendons(1, &tendons)
        .unwrap();
    let o = PccSolveOptions::default();
    let t = [0.0, 1.7, 0.9, 2.2, 0.0, 0.4];
    let loads = PccLoads {
        tensions: t.to_vec(),
        ..Default::default()
    };
    let tip = solve_pcc_statics(&robot, &loads, &o).unwrap().tip_pose;
    let p = Vector3::new(tip[(0, 3)], tip[(1, 3)], tip[(2, 3)]);
    let target = Target::tip(p);
    let moved = Target::tip(p + Vector3::new(1e-3, 0.0, 0.0));
    let io = InverseOptions::default();
    let mut fwd = PccForward::new(&robot, &PccLoads::default(), &o);
    let cold = solve_inverse(&mut fwd, &target, &io, None).unwrap();
    let w = InverseWarmStart::from(&cold);
    eprintln!(
        "cold: it {} ev {} a {:?}",
        cold.iterations, cold.evaluations, cold.actuation
    );
    let warm = solve_inverse(&mut fwd, &moved, &io, Some(&w)).unwrap();
    eprintln!(
        "warm: it {} ev {} a {:?}",
        warm.iterations, warm.evaluations, warm.actuation
    );
    let fast = pcc_inverse_statics(&robot, &PccLoads::default(), &target, &io, &o, None).unwrap();
    eprintln!(
        "fast cold: it {} ev {} a {:?}",
        fast.iterations, fast.evaluations, fast.actuation
    );
    let wf = InverseWarmStart::from(&fast);
    let fw = pcc_inverse_statics(&robot, &PccLoads::default(), &moved, &io, &o, Some(&wf)).unwrap();
    eprintln!(
        "fast warm: it {} ev {} a {:?}",
        fw.iterations, fw.evaluations, fw.actuation
    );
    let mut acc = 0.0;
    for _ in 0..n {
        let r = if mode == 0 {
            pcc_inverse_statics(&robot, &PccLoads::default(), &target, &io, &o, None).unwrap()
        } else {
            pcc_inverse_statics(&robot, &PccLoads::default(), &moved, &io, &o, Some(&wf)).unwrap()
        };
        acc += r.actuation[0];
    }
    println!("{acc}");
}
