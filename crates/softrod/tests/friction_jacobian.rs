//! Linearisation of a frictional equilibrium: with μ = 0 the actuation Jacobian and the tangent
//! compliance of a frictional solve equal the frictionless ones (the frictionless Jacobian and
//! compliance at the same nodes), and the one-sided finite differences of the nonlinear
//! frictional solve continued from the solution (`previous` = the solution) show that the
//! derivative of a frictional equilibrium is one-sided: pulling on (sliding) and releasing
//! (sticking) a loaded tendon give different slopes.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use std::sync::Arc;

use softrod::nalgebra::Vector3;
use softrod::{
    actuation_jacobian, solve_frictional, solve_statics_at, tangent_compliance, Actuation,
    FrictionOptions, FrictionalSolution, Integrator, Loads, RobotModel, StaticsSolution,
    TendonControl,
};

fn options(steps: usize) -> FrictionOptions {
    let mut o = FrictionOptions::default();
    o.statics.integrator = Integrator::Rk4 { steps };
    o.statics.newton.tolerance = 1e-14;
    o.tolerance = 1e-14;
    o
}

const TENSIONS: [f64; 6] = [3.0, 0.0, 0.0, 0.0, 1.0, 0.0];

/// The load cases of the must-show list: unloaded, a tip force, gravity.
fn cases(mu: f64) -> Vec<(&'static str, Arc<RobotModel>)> {
    vec![
        ("unloaded", common::niti_model(Loads::default(), None, mu)),
        (
            "tip force",
            common::niti_model(Loads::tip_force(Vector3::new(0.05, -0.02, 0.01)), None, mu),
        ),
        (
            "gravity",
            common::niti_model(
                Loads {
                    gravity: Vector3::new(0.0, -9.81, 0.0),
                    ..Loads::default()
                },
                Some(6450.0),
                mu,
            ),
        ),
    ]
}

/// Largest entry of `a - b` relative to the largest entry of `b` (entries of two matrices of
/// the same shape, in storage order).
fn rel(a: &[f64], b: &[f64]) -> f64 {
    let diff = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    diff / b.iter().fold(0.0f64, |m, y| m.max(y.abs()))
}

/// For every load case with μ = 0: the frictional solve at [`TENSIONS`] and the
/// frictionless solve on its nodes.
fn zero_friction_pairs() -> Vec<(&'static str, FrictionalSolution, StaticsSolution)> {
    let act = Actuation::tensions(&TENSIONS);
    let opts = options(50);
    cases(0.0)
        .into_iter()
        .map(|(name, model)| {
            let fr = solve_frictional(&model, &act, &opts, None).unwrap();
            let plain = solve_statics_at(&model, &act, &opts.statics, &fr.statics.s).unwrap();
            (name, fr, plain)
        })
        .collect()
}

#[test]
fn zero_friction_actuation_jacobian_is_the_frictionless_one() {
    for (name, fr, plain) in zero_friction_pairs() {
        let a = actuation_jacobian(&fr.statics, None).unwrap();
        let b = actuation_jacobian(&plain, None).unwrap();
        let e = rel(a.as_slice(), b.as_slice());
        eprintln!("μ = 0, {name}: actuation Jacobian {e:e} relative to the frictionless one");
        assert!(e < 1e-12, "{name}: {e:e}");
    }
}

#[test]
fn zero_friction_tangent_compliance_is_the_frictionless_one() {
    for (name, fr, plain) in zero_friction_pairs() {
        let a = tangent_compliance(&fr.statics, TendonControl::Tension, None).unwrap();
        let b = tangent_compliance(&plain, TendonControl::Tension, None).unwrap();
        let e = rel(a.world.as_slice(), b.world.as_slice());
        eprintln!("μ = 0, {name}: tangent compliance {e:e} relative to the frictionless one");
        assert!(e < 1e-12, "{name}: {e:e}");
    }
}

/// One-sided finite difference of the tip pose with respect to the base tension of tendon
/// `i`, continued from `sol` (its history), step `h` (N, signed).
fn one_sided(
    model: &Arc<RobotModel>,
    sol: &FrictionalSolution,
    i: usize,
    h: f64,
    opts: &FrictionOptions,
) -> Vector3<f64> {
    let mut t = TENSIONS;
    t[i] += h;
    let next = solve_frictional(model, &Actuation::tensions(&t), opts, Some(sol)).unwrap();
    let (a, b) = (
        next.statics.position.last().unwrap(),
        sol.statics.position.last().unwrap(),
    );
    (Vector3::from(*a) - Vector3::from(*b)) / h
}

/// The derivative of a frictional equilibrium is one-sided: at a state loaded from rest
/// (every element sliding toward the base) pulling the tendon further slides, releasing it
/// sticks, and the two one-sided slopes differ at O(1); each converges as O(h) (the two steps
/// `h` and `h / 10` agree to far better than the two sides).
#[test]
fn the_derivative_of_a_frictional_equilibrium_is_one_sided() {
    for (name, model) in cases(0.2) {
        let opts = options(50);
        let sol = solve_frictional(&model, &Actuation::tensions(&TENSIONS), &opts, None).unwrap();
        let h = 1e-4 * TENSIONS[0];
        let up = one_sided(&model, &sol, 0, h, &opts);
        let up10 = one_sided(&model, &sol, 0, h / 10.0, &opts);
        let down = one_sided(&model, &sol, 0, -h, &opts);
        let down10 = one_sided(&model, &sol, 0, -h / 10.0, &opts);
        let side = (up - down).norm() / up.norm();
        let (cu, cd) = (
            (up - up10).norm() / up.norm(),
            (down - down10).norm() / down.norm(),
        );
        eprintln!(
            "μ = 0.2, {name}: |pull − release| / |pull| = {side:.3e}; h → h/10 changes the \
             pull slope by {cu:.2e}, the release slope by {cd:.2e} (relative)"
        );
        assert!(side > 1e-2, "{name}: the two sides agree ({side:e})");
        assert!(
            cu < 1e-2 * side && cd < 1e-2 * side,
            "{name}: {cu:e} {cd:e}"
        );
    }
}
