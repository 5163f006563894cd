//! A fixed workload of the statics benches for instruction counts under callgrind: `COUNT`
//! solves of one case, and the marches they took.
//!
//! Cases: `cold` / `warm` (the two-segment NiTi robot with a 0.05 N tip force, cold and
//! warm-started after +2 % tension), `unloaded` (tendons only), `gravity` (the 1 m
//! four-tendon robot under gravity, cold), `cantilever` (the soft cantilever, 0.02 N tip force),
//! `held` (the NiTi robot under the tip force, every tendon held at the displacements of the
//! `cold` tensions, the zero of the displacements given);
//! and, after one tendons-only solve, `COUNT` of `compliance` (along the arm), `tangent` /
//! `tangent_length` (tip, tensions or lengths held) or `workspace` (100 configurations of the
//! compliance bench's workspace map, per count).
//!
//! Run: `valgrind --tool=callgrind target/release/examples/loaded_solve cold 20`.
#![allow(missing_docs, clippy::unwrap_used)]

#[path = "../tests/common/robot.rs"]
mod robot;

use std::sync::Arc;

use softrod::batch::workspace::{workspace_map, DEFAULT_CHUNK};
use softrod::compliance::{compliance, tangent_compliance, TendonControl};
use softrod::nalgebra::Vector3;
use softrod::{
    solve_statics, Actuation, LinearElastic, Loads, RobotModel, Rod, Section, SolveOptions,
};

fn niti(loads: Loads) -> Arc<RobotModel> {
    robot::niti_model(loads, None, 0.0)
}

fn main() {
    let case = std::env::args().nth(1).unwrap_or("cold".into());
    let count: usize = std::env::args()
        .nth(2)
        .map(|a| a.parse().unwrap())
        .unwrap_or(20);
    let opts = SolveOptions::default();
    let act = Actuation::tensions(&[4.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    let changed = Actuation::tensions(&[4.08, 0.0, 0.0, 0.0, 2.04, 0.0]);
    let tip = Loads::tip_force(Vector3::new(0.05, 0.0, 0.0));
    if let Some(done) = after_solve(&case, count, &act, &opts) {
        println!("{case}: {done}");
        return;
    }
    let (model, act, opts) = match case.as_str() {
        "cold" => (niti(tip), act, opts),
        "unloaded" => (niti(Loads::default()), act, opts),
        "warm" => {
            let model = niti(tip);
            let prev = solve_statics(&model, &act, &opts).unwrap();
            let warm = SolveOptions {
                warm_start: Some(prev.warm_start()),
                ..opts
            };
            (model, changed, warm)
        }
        "gravity" => (
            robot::four_tendon_gravity(),
            Actuation::tensions(&[2.0, 0.0, 1.0, 0.0]),
            opts,
        ),
        "held" => {
            let model = niti(tip);
            let forward = solve_statics(&model, &act, &opts).unwrap();
            let zero = softrod::reference_lengths(&model, &opts).unwrap();
            let mut held = act.clone();
            for (i, t) in held.tendons.iter_mut().enumerate() {
                *t = softrod::TendonInput::displacement(zero[i] - forward.tendon_lengths[i]);
            }
            held.reference_lengths = Some(zero);
            (model, held, opts)
        }
        "cantilever" => {
            let soft = Rod::new(
                0.27,
                Section::circular(0.01).unwrap(),
                LinearElastic::new(110e3, 0.5).unwrap(),
            )
            .unwrap();
            let m =
                RobotModel::rod_only(soft, Loads::tip_force(Vector3::new(0.02, 0.0, 0.0))).unwrap();
            (m, Actuation::default(), opts)
        }
        other => panic!("unknown case {other}"),
    };
    let mut last = None;
    for _ in 0..count {
        last = Some(solve_statics(&model, &act, &opts).unwrap());
    }
    let s = last.unwrap();
    println!(
        "{case}: iterations {}, load steps {}, rhs evaluations {}, stable {}, tip {:?}",
        s.stats.iterations,
        s.stats.load_steps,
        s.stats.function_evaluations,
        s.stable,
        s.tip_position()
    );
}

/// The cases that work on the tendons-only robot after a solve (the workspace map makes its
/// own): what the last call returned, or `None` for a solve case.
fn after_solve(case: &str, count: usize, act: &Actuation, opts: &SolveOptions) -> Option<String> {
    let held = match case {
        "workspace" => return Some(workspace(count, opts)),
        "compliance" => None,
        "tangent" => Some(TendonControl::Tension),
        "tangent_length" => Some(TendonControl::Length),
        _ => return None,
    };
    let sol = solve_statics(&niti(Loads::default()), act, opts).unwrap();
    let Some(ctl) = held else {
        let mut c = None;
        for _ in 0..count {
            c = Some(compliance(&sol).unwrap());
        }
        let c = c.unwrap();
        let sum = |m: &[softrod::nalgebra::Matrix6<f64>]| -> f64 {
            m.iter().map(|x| x.abs().sum()).sum()
        };
        return Some(format!(
            "sums of |C| along the arm, world {:e}, body {:e}",
            sum(&c.world),
            sum(&c.body)
        ));
    };
    let mut c = None;
    for _ in 0..count {
        c = Some(tangent_compliance(&sol, ctl, None).unwrap());
    }
    Some(format!("{:?}", c.unwrap().world.diagonal()))
}

/// `100 count` configurations of the compliance bench's workspace map: the first and last
/// tips and the last configuration's translational compliances.
fn workspace(count: usize, opts: &SolveOptions) -> String {
    let tensions: Vec<f64> = (0..100 * count)
        .flat_map(|i| [4.0 * (i % 100) as f64 / 99.0, 0.0, 0.0, 0.0, 1.0, 0.0])
        .collect();
    let model = niti(Loads::default());
    let map = workspace_map(
        &model,
        &Actuation::default(),
        &tensions,
        opts,
        DEFAULT_CHUNK,
        None,
    )
    .unwrap();
    let (first, last) = (&map[0], &map[map.len() - 1]);
    format!(
        "{} configurations, first and last tips {:?} {:?}, last compliances {:e} {:e}",
        map.len(),
        first.tip_position,
        last.tip_position,
        last.max_translational_compliance,
        last.min_translational_compliance
    )
}
