//! Why the inverse statics with a sphere misses some round-trip targets: the NiTi robot driven
//! into a sphere by random admissible tensions, each missed target analysed (printed).
//!
//! Run: `SPHERE=0 SAMPLES=1000 [ANALYSE=0] cargo run --release -p softrod --example contact_inverse_misses`.
#![allow(missing_docs, clippy::unwrap_used)]

#[path = "../tests/common/robot.rs"]
mod common;

use common::Rng;
use softrod::nalgebra::Vector3;
use softrod::{
    contact_inverse_statics, solve_constrained, Actuation, InverseOptions, Loads, Obstacle,
    SolveOptions, Target,
};

/// Diagnosis of the misses on a sphere (`SPHERE=0` the
/// 40 mm sphere, `1` the 60 mm one; `SAMPLES` tension vectors, 100 by default). Per target
/// not reached it prints the generating and the returned tensions with their contacts, the
/// least distance of the contact-free shape at the answer to the sphere's centre, the
/// gradient of the distance projected on the bounds, the forward solve along the
/// Gauss–Newton step against its linearisation, cold and warm-started solves at tiny
/// fractions of that step, and the distance along the segment to the generating tensions
/// (not for a target reached without the least norm certified, nor with `ANALYSE=0`); per
/// converged answer on an unstable equilibrium its margin; then the counts. docs/command.md "With obstacles" quotes its output.
fn main() {
    let which: usize = std::env::var("SPHERE")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0);
    let samples: usize = std::env::var("SAMPLES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(100);
    let sphere = [
        Obstacle::sphere([0.06, 0.0, 0.3], 0.04).unwrap(),
        Obstacle::sphere([0.0, 0.07, 0.25], 0.06).unwrap(),
    ][which]
        .clone();
    let rod = common::niti_rod();
    let tendons = common::niti_tendons(&[0.0; 6]);
    let (model, _) = common::split(&rod, &tendons, &[], &Loads::default()).unwrap();
    let options = common::rk4_options(50);
    let obstacles = [sphere.clone()];
    let mut rng = Rng(0x5eed);
    let (mut touching, mut missed, mut reached, mut unstable) = (0, 0, 0, 0);
    let analyse = std::env::var("ANALYSE").map_or(true, |v| v != "0");
    for k in 0..samples {
        let t = rng.admissible();
        let Ok(f) = solve_constrained(&model, &Actuation::tensions(&t), &options, None, &obstacles)
        else {
            continue;
        };
        if f.contacts.is_empty() || !f.solution.stats.converged {
            continue;
        }
        let target = Target::tip(Vector3::from(f.solution.tip_position()));
        let inv = InverseOptions {
            throw: false,
            ..InverseOptions::default()
        };
        touching += 1;
        let (out, sol) =
            contact_inverse_statics(&model, &obstacles, &target, &inv, &options, None).unwrap();
        if out.converged {
            if !sol.solution.stable {
                unstable += 1;
                println!(
                    "#{k} converged on an unstable equilibrium: margin {:.3e} (target's {:.3e})",
                    sol.solution.stability_margin(),
                    f.solution.stability_margin()
                );
            }
            continue;
        }
        missed += 1;
        let cs = |s: &softrod::ContactSolution| {
            s.contacts
                .iter()
                .map(|c| format!("s {:.4} f {:.2e} n {:.2?}", c.s, c.normal_force, c.normal))
                .collect::<Vec<_>>()
                .join("; ")
                + &format!(
                    " stable {} margin {:.2e}",
                    s.solution.stable,
                    s.solution.stability_margin()
                )
        };
        println!(
            "#{k} gen {t:?} |t| {:.3} contacts [{}]",
            t.iter().map(|v| v * v).sum::<f64>().sqrt(),
            cs(&f)
        );
        println!(
            "   got {:.3?} |a| {:.3} err {:.3e} it {} contacts [{}]",
            out.actuation,
            out.actuation.iter().map(|v| v * v).sum::<f64>().sqrt(),
            out.position_error,
            out.iterations,
            cs(&sol)
        );
        if out.reached {
            reached += 1;
            println!("   reached (the minimum norm not certified)");
        } else if analyse {
            analyse_miss(&model, &options, &obstacles, &target, &t, &out);
        }
    }
    println!(
        "missed {missed} of {touching} ({reached} of them reached, not certified); \
         {unstable} converged on an unstable equilibrium"
    );
}

/// The measurements of one miss of `main` (printed): the contact-free
/// shape, the distance's gradient, the Gauss–Newton step and the segment to the generating
/// tensions `t`.
fn analyse_miss(
    model: &std::sync::Arc<softrod::RobotModel>,
    options: &SolveOptions,
    obstacles: &[Obstacle],
    target: &Target,
    t: &[f64; 6],
    out: &softrod::InverseSolution,
) {
    use softrod::{ContactForward, Forward};
    let sphere = obstacles[0].clone();
    let options = *options;
    // The contact-free shape at the answer: its least distance to the sphere's centre.
    if let Obstacle::Sphere { center, radius } = sphere {
        let free = solve_constrained(
            model,
            &Actuation::tensions(&out.actuation),
            &options,
            None,
            &[],
        )
        .unwrap();
        let dmin = free
            .solution
            .position
            .iter()
            .map(|p| (Vector3::from(*p) - center).norm())
            .fold(f64::INFINITY, f64::min);
        println!(
            "   free shape at the answer: least distance to the centre {dmin:.4} (radius {radius})"
        );
    }
    // Gradient of ½|e|² projected on the bounds.
    let mut fwd = ContactForward::new(model, &options, obstacles).unwrap();
    let ev = fwd.evaluate(&out.actuation, true).unwrap();
    let j = ev.jacobian.unwrap()[0].rows(0, 3).into_owned();
    let e = target.points[0] - ev.positions[0];
    let g = -(j.transpose() * e);
    let pg: Vec<f64> = (0..6)
        .map(|i| {
            if out.actuation[i] <= 0.0 {
                g[i].min(0.0)
            } else {
                g[i]
            }
        })
        .collect();
    let sv = j.clone().svd(false, false).singular_values;
    println!(
        "   |e| {:.3e} proj grad {:.3e} (|J^T e|/(|J||e|) {:.3e}) sv {:.3e} {:.3e}",
        e.norm(),
        pg.iter().map(|v| v * v).sum::<f64>().sqrt(),
        pg.iter().map(|v| v * v).sum::<f64>().sqrt() / (sv[0] * e.norm()),
        sv[2],
        sv[0]
    );
    // The forward map along the Gauss-Newton step against its linearisation.
    let d = j.clone().pseudo_inverse(1e-12).unwrap() * e;
    let p0 = ev.positions[0];
    let mut lin = String::new();
    for alpha in [1e-6, 1e-4, 1e-2, 0.1, 1.0] {
        let a: Vec<f64> = (0..6)
            .map(|m| (out.actuation[m] + alpha * d[m]).max(0.0))
            .collect();
        let da: Vec<f64> = (0..6).map(|m| a[m] - out.actuation[m]).collect();
        let pred = &j * softrod::nalgebra::DVector::from_column_slice(&da);
        match fwd.solve(&a) {
            Ok(s) => {
                let dp = Vector3::from(s.solution.tip_position()) - p0;
                lin += &format!(
                    " a={alpha:.0e}: rel {:.1e} err {:.1e} nc {}",
                    (dp - &pred).norm() / pred.norm(),
                    (Vector3::from(s.solution.tip_position()) - target.points[0]).norm(),
                    s.contacts.len()
                );
            }
            Err(_) => lin += " fail",
        }
    }
    println!("   GN step |d| {:.2e}:{lin}", d.norm());
    // Cold and warm-started solves at tiny perturbations of the answer.
    let base = fwd.solve(&out.actuation).unwrap();
    let mut warm_opts = options;
    warm_opts.warm_start = Some(base.solution.warm_start());
    let mut cw = String::new();
    for ex in [-12, -10, -8, -7, -6, -5, -4, -3] {
        let alpha = 10f64.powi(ex);
        let a: Vec<f64> = (0..6)
            .map(|m| (out.actuation[m] + alpha * d[m]).max(0.0))
            .collect();
        let err = |o: &SolveOptions| match solve_constrained(
            model,
            &Actuation::tensions(&a),
            o,
            None,
            obstacles,
        ) {
            Ok(s) => format!(
                "{:.1e} n {:.2?}",
                (Vector3::from(s.solution.tip_position()) - target.points[0]).norm(),
                s.contacts.first().map(|c| c.normal)
            ),
            Err(_) => "fail".into(),
        };
        cw += &format!(" 1e{ex}: {}/{}", err(&options), err(&warm_opts));
    }
    println!("   cold/warm:{cw}");
    segment_to_generating(&fwd, &target.points[0], t, &out.actuation);
}

/// The distance of the tip to `target` along the segment from the answer `a` to the
/// generating tensions `t` (printed, with the number of contacts).
fn segment_to_generating(
    fwd: &softrod::ContactForward,
    target: &Vector3<f64>,
    t: &[f64; 6],
    a: &[f64],
) {
    // The distance along the segment from the answer to the generating tensions.
    let mut line = String::new();
    for i in 0..=10 {
        let th = f64::from(i) / 10.0;
        let a: Vec<f64> = (0..6).map(|m| a[m] + th * (t[m] - a[m])).collect();
        match fwd.solve(&a) {
            Ok(s) => {
                line += &format!(
                    " {:.1e}/{}",
                    (Vector3::from(s.solution.tip_position()) - *target).norm(),
                    s.contacts.len()
                )
            }
            Err(_) => line += " fail",
        }
    }
    println!("   segment answer->gen:{line}");
}
