//! End constraints through the shooting problem, against closed-form beam theory: the
//! clamped–clamped and clamped–pinned beams under a midspan force, and Greenhill's torque
//! buckling of a clamped–clamped rod.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use std::sync::Arc;

use softrod::nalgebra::{Matrix3, Vector3};
use softrod::{
    solve_constrained, Actuation, ContactSolution, Loads, PointLoad, Pose, RobotModel,
    TipConstraint,
};

use common::{beam as rod, rk4_options as options, BEAM_E as E, BEAM_LENGTH as L, BEAM_NU as NU};

fn straight_tip() -> Pose {
    Pose::new(Vector3::new(0.0, 0.0, L), Matrix3::identity()).unwrap()
}

fn midspan(sol: &ContactSolution) -> [f64; 3] {
    let j = sol.solution.s.iter().rposition(|s| *s == 0.5 * L).unwrap();
    sol.solution.position[j]
}

/// Global balance: the base wrench equals the applied loads plus the tip reaction (about
/// the base), to 1e-10 of the load scale.
fn assert_balanced(sol: &ContactSolution, loads: &[(Vector3<f64>, Vector3<f64>)], scale: f64) {
    let r = sol.tip_reaction.unwrap();
    let tip = Vector3::from(sol.solution.tip_position());
    let (mut f, mut m) = (
        Vector3::new(r[0], r[1], r[2]),
        Vector3::new(r[3], r[4], r[5]),
    );
    m += tip.cross(&f);
    for (p, force) in loads {
        f += force;
        m += p.cross(force);
    }
    let b = sol.solution.base_wrench;
    for k in 0..3 {
        assert!(
            (b[k] - f[k]).abs() <= 1e-10 * scale,
            "force {k}: {} vs {}",
            b[k],
            f[k]
        );
        assert!(
            (b[3 + k] - m[k]).abs() <= 1e-10 * scale * L,
            "moment {k}: {} vs {}",
            b[3 + k],
            m[k]
        );
    }
}

fn solve_midspan(radius: f64, p: f64, tip: &TipConstraint) -> (ContactSolution, f64) {
    let loads = Loads {
        point_loads: vec![PointLoad::force(0.5 * L, Vector3::new(p, 0.0, 0.0))],
        ..Loads::default()
    };
    let model = RobotModel::rod_only(rod(radius), loads).unwrap();
    let sol =
        solve_constrained(&model, &Actuation::default(), &options(200), Some(tip), &[]).unwrap();
    (sol, model.force_scale())
}

#[test]
fn clamped_clamped_midspan_deflection_is_timoshenko() {
    let radius = 0.02;
    let r = rod(radius);
    let (ei, _, _, gas) = common::circular_constants(E, NU, radius, r.shear_coefficient());
    let p = 1e-4 * 192.0 * ei / L.powi(3) * (radius / L);
    let (sol, _) = solve_midspan(radius, p, &TipConstraint::clamp(straight_tip()));
    assert!(sol.solution.stats.converged && sol.solution.stable);
    let exact = p * L.powi(3) / (192.0 * ei) + p * L / (4.0 * gas);
    let got = midspan(&sol)[0];
    let err = (got / exact - 1.0).abs();
    assert!(err < 1e-3, "midspan {got:e} vs {exact:e} ({err:e})");
    // Symmetry: each end carries half the force and the same moment P L / 8.
    let rt = sol.tip_reaction.unwrap();
    assert!(
        (rt[0] / (-0.5 * p) - 1.0).abs() < 1e-3,
        "tip reaction {rt:?}"
    );
    assert!(
        (rt[4].abs() / (p * L / 8.0) - 1.0).abs() < 1e-3,
        "tip moment {rt:?}"
    );
    let mid = Vector3::new(0.0, 0.0, 0.5 * L);
    assert_balanced(&sol, &[(mid, Vector3::new(p, 0.0, 0.0))], p);
    println!("clamped-clamped: midspan {got:e}, closed form {exact:e}, rel. error {err:e}");
}

#[test]
fn clamped_pinned_midspan_deflection_is_euler_bernoulli() {
    let radius = 1e-3;
    let (ei, _, _, _) = common::circular_constants(E, NU, radius, 1.0);
    let p = 1e-4 * 768.0 / 7.0 * ei / L.powi(3) * (radius / L);
    let pin = TipConstraint::pin([0.0, 0.0, L]).unwrap();
    let (sol, fs) = solve_midspan(radius, p, &pin);
    assert!(sol.solution.stats.converged && sol.solution.stable);
    let exact = 7.0 * p * L.powi(3) / (768.0 * ei);
    let got = midspan(&sol)[0];
    let err = (got / exact - 1.0).abs();
    assert!(err < 1e-3, "midspan {got:e} vs {exact:e} ({err:e})");
    // The pin carries no moment; its force is 5 P / 16.
    let rt = sol.tip_reaction.unwrap();
    assert!(
        rt[3..].iter().all(|m| m.abs() < 1e-9 * fs * L),
        "pin moment {rt:?}"
    );
    assert!(
        (rt[0] / (-5.0 * p / 16.0) - 1.0).abs() < 1e-3,
        "pin force {rt:?}"
    );
    let mid = Vector3::new(0.0, 0.0, 0.5 * L);
    assert_balanced(&sol, &[(mid, Vector3::new(p, 0.0, 0.0))], p);
    println!("clamped-pinned: midspan {got:e}, closed form {exact:e}, rel. error {err:e}");
}

/// Greenhill: a rod clamped at both ends (the tip free to slide along and twist about its
/// axis) under an axial twisting moment buckles at `M L / (E I) = 8.98682` (twice the first
/// root of `tan x = x`).
#[test]
fn clamped_clamped_rod_under_torque_loses_stability_at_greenhill() {
    let radius = 1e-3;
    let (ei, _, _, _) = common::circular_constants(E, NU, radius, 1.0);
    // 2 x the first positive root of tan x = x.
    let mut x: f64 = 4.5;
    for _ in 0..50 {
        x -= (x.tan() - x) / (1.0 / x.cos().powi(2) - 1.0);
    }
    let critical = 2.0 * x * ei / L;
    assert!((2.0 * x - 8.98682).abs() < 1e-5);
    let held = [true, true, false, true, true, false];
    let tip = TipConstraint::new(straight_tip(), held).unwrap();
    let stable_at = |factor: f64| {
        let loads = Loads::tip_moment(Vector3::new(0.0, 0.0, factor * critical));
        let model: Arc<RobotModel> = RobotModel::rod_only(rod(radius), loads).unwrap();
        let sol = solve_constrained(
            &model,
            &Actuation::default(),
            &options(400),
            Some(&tip),
            &[],
        )
        .unwrap();
        assert!(sol.solution.stats.converged);
        (sol.solution.stable, sol.conjugate_points.unwrap())
    };
    assert_eq!(stable_at(0.5), (true, 0));
    assert_eq!(stable_at(0.999), (true, 0));
    let (stable, count) = stable_at(1.001);
    assert!(
        !stable && count >= 1,
        "above Greenhill: {count} conjugate points"
    );
    println!("Greenhill: stable at 0.999 Mc, unstable at 1.001 Mc ({count} conjugate points)");
}
