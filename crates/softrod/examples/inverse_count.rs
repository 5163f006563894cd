//! Instruction-count harness (`valgrind --tool=callgrind`): N inverse statics of the
//! two-segment NiTi tendon robot (default RK4 options), cold from zero tensions (mode 0), warm
//! from the solution at a target 1 mm away (mode 1), or N forward evaluations with the
//! actuation Jacobian (mode 2) or N probes (the tip pose alone, mode 5), or N times the ten 1 mm steps of a
//! tracked path (mode 6), a call as Python makes it without and with the check of the answer's
//! mesh (modes 7 and 8 cold, 9 and 10 warm); the PCC inverse of the same robot (two arcs) cold (mode 3)
//! and warm, target moved 1 mm (mode 4). Prints the iterations and evaluations of each case
//! on stderr.
//!
//! Run: `cargo build --release -p softrod --example inverse_count` then
//! `valgrind --tool=callgrind target/release/examples/inverse_count MODE N`.
#![allow(missing_docs, clippy::unwrap_used)]

use std::sync::Arc;

#[path = "../tests/common/robot.rs"]
mod robot;

use softrod::nalgebra::Vector3;
use softrod::pcc::statics::{solve_pcc_statics, PccLoads, PccRobot, PccSolveOptions};
use softrod::pcc::{ElasticSegment, PccTendons};
use softrod::{
    inverse_actuation, pcc_inverse_statics, solve_inverse, CosseratForward, Forward,
    InverseOptions, InverseWarmStart, Loads, RobotModel, SolveOptions, Target,
};

fn niti() -> Arc<RobotModel> {
    robot::niti_model(Loads::default(), None, 0.0)
}

/// The two-segment NiTi robot as two PCC arcs (as in `tests/inverse.rs`).
fn pcc_niti() -> PccRobot {
    let ang = [90.0f64, -30.0, 210.0].map(f64::to_radians);
    let tendons = PccTendons::new(&[0.01; 3], &ang).unwrap();
    let seg = || ElasticSegment::solid_circle(0.2, 0.7e-3, 54e9, true).unwrap();
    PccRobot::new(vec![seg(), seg()])
        .unwrap()
        .with_segment_tendons(0, &tendons)
        .unwrap()
        .with_segment_tendons(1, &tendons)
        .unwrap()
}

/// The ten 1 mm steps of the tracked path of `main` from `w`; the first tension at the end.
fn track(
    fwd: &mut CosseratForward,
    tip: Vector3<f64>,
    io: &InverseOptions,
    w: &InverseWarmStart,
) -> f64 {
    let mut w = w.clone();
    for k in 1..=10 {
        let p = Target::tip(tip + Vector3::new(1e-3 * f64::from(k), 0.0, 0.0));
        w = InverseWarmStart::from(&solve_inverse(fwd, &p, io, Some(&w)).unwrap());
    }
    w.actuation[0]
}

/// A call as Python makes it: a fresh forward model and the inverse alone (mode 7 cold at
/// `targets.0`, 9 warm from `w` at `targets.1`), or `inverse_actuation`, the inverse with the
/// check of the answer's mesh (8 cold, 10 warm).
fn python_call(
    mode: usize,
    model: &Arc<RobotModel>,
    targets: (&Target, &Target),
    io: &InverseOptions,
    o: &SolveOptions,
    w: &InverseWarmStart,
) -> f64 {
    let (t, warm) = if mode <= 8 {
        (targets.0, None)
    } else {
        (targets.1, Some(w))
    };
    if mode == 7 || mode == 9 {
        let mut fresh = CosseratForward::new(model, o, None).unwrap();
        return solve_inverse(&mut fresh, t, io, warm).unwrap().actuation[0];
    }
    inverse_actuation(model, t, io, o, warm).unwrap().actuation[0]
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
    // The PCC inverse (its closed-form iteration) to the PCC tip at the same tensions.
    let pcc = pcc_niti();
    let po = PccSolveOptions::default();
    let pl = PccLoads::default();
    let ptip = solve_pcc_statics(
        &pcc,
        &PccLoads {
            tensions: t.to_vec(),
            ..Default::default()
        },
        &po,
    )
    .unwrap()
    .tip_pose;
    let ptip = Vector3::new(ptip[(0, 3)], ptip[(1, 3)], ptip[(2, 3)]);
    let ptarget = Target::tip(ptip);
    let pmoved = Target::tip(ptip + Vector3::new(1e-3, 0.0, 0.0));
    let pcold = pcc_inverse_statics(&pcc, &pl, &ptarget, &io, &po, None).unwrap();
    let pw = InverseWarmStart::from(&pcold);
    let pwarm = pcc_inverse_statics(&pcc, &pl, &pmoved, &io, &po, Some(&pw)).unwrap();
    eprintln!(
        "pcc: cold iterations {} evaluations {}; warm iterations {} evaluations {} error {:e}",
        pcold.iterations,
        pcold.evaluations,
        pwarm.iterations,
        pwarm.evaluations,
        pwarm.position_error
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
            3 => {
                pcc_inverse_statics(&pcc, &pl, &ptarget, &io, &po, None)
                    .unwrap()
                    .actuation[0]
            }
            4 => {
                pcc_inverse_statics(&pcc, &pl, &pmoved, &io, &po, Some(&pw))
                    .unwrap()
                    .actuation[0]
            }
            5 => fwd.probe(&t).unwrap().positions[0].x,
            6 => track(&mut fwd, tip, &io, &w),
            7..=10 => python_call(mode, &model, (&target, &moved), &io, &o, &w),
            _ => fwd.evaluate(&t, true).unwrap().positions[0].x,
        };
    }
    println!("{acc}");
}
