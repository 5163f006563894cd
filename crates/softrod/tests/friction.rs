//! Capstan friction along the tendons: the capstan equation on a nearly rigid arc (loading and
//! the unloading slip front, closed forms), the frictionless limit, the capstan law along the
//! returned shape of a flexible robot, global balance with friction, and a load/unload cycle
//! of the two-segment NiTi robot (closure, dissipation, loop width against μ).
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use std::sync::Arc;

use softrod::nalgebra::{Matrix3, Vector3};
use softrod::{
    solve_frictional, solve_path, solve_statics_at, Actuation, FrictionOptions, FrictionalSolution,
    Integrator, LinearElastic, Loads, Profile, RobotModel, Rod, Section, Slip, SolveOptions,
    Tendon,
};

const KAPPA0: f64 = 5.0; // rest curvature (1/m)
const LENGTH: f64 = 0.3; // rod length (m): wrap angle 1.5 rad
const MU: f64 = 0.3;

fn options(steps: usize) -> FrictionOptions {
    let mut o = FrictionOptions::default();
    o.statics.integrator = Integrator::Rk4 { steps };
    o.statics.newton.tolerance = 1e-13;
    o.tolerance = 1e-12;
    o
}

/// A stiff precurved rod (steel, 5 mm radius, rest curvature κ0 about body y) with one tendon
/// on the inside of the curve; tensions of 0.1 mN keep the shape within 1e-9 of the arc.
fn arc_model(mu: f64) -> Arc<RobotModel> {
    arc_model_of(mu, LENGTH)
}

/// [`arc_model`] of another `length` (m).
fn arc_model_of(mu: f64, length: f64) -> Arc<RobotModel> {
    let rod = Rod::new(
        length,
        Section::circular(0.005).unwrap(),
        LinearElastic::new(2e11, 0.3).unwrap(),
    )
    .unwrap()
    .with_inextensible(true)
    .with_rest_curvature(Profile::Constant(Vector3::new(0.0, KAPPA0, 0.0)))
    .unwrap();
    let tendon = Tendon::constant([0.004, 0.0], None)
        .unwrap()
        .with_friction(mu)
        .unwrap();
    RobotModel::new(rod, vec![tendon], Vec::new(), Loads::default()).unwrap()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn capstan_on_a_rigid_arc() {
    let model = arc_model(MU);
    let tau0 = 1e-4;
    let sol = solve_frictional(&model, &Actuation::tensions(&[tau0]), &options(200), None).unwrap();
    // The shape is the arc.
    let tip = sol.tip_position();
    let th = KAPPA0 * LENGTH;
    let arc = [(1.0 - th.cos()) / KAPPA0, 0.0, th.sin() / KAPPA0];
    let off = (0..3).map(|k| (tip[k] - arc[k]).abs()).fold(0.0, f64::max);
    assert!(off < 1e-9, "tip off the arc by {off:e} m");
    let mut worst: f64 = 0.0;
    for (j, &s) in sol.statics.s.iter().enumerate() {
        let exact = tau0 * (-MU * KAPPA0 * s).exp();
        worst = worst.max(rel(sol.tension[j][0], exact));
        assert_eq!(sol.slip[j][0], Slip::Loading);
    }
    eprintln!(
        "capstan: worst relative error {worst:e}, tip off the arc {off:e} m, {} rod solves",
        sol.iterations
    );
    assert!(worst < 1e-8, "capstan: worst relative error {worst:e}");
    // The rod is loaded with the local tension: at the tip, its own force is -τ(L) t(L).
    let n = sol.statics.s.len() - 1;
    let t = sol.tangent[n][0];
    let f = sol.statics.n_world[n];
    for k in 0..3 {
        let e = -sol.tension[n][0] * t[k];
        assert!((f[k] - e).abs() < 1e-10 * tau0, "tip force {f:?} vs {e}");
    }
}

#[test]
fn unloading_moves_a_slip_front() {
    let model = arc_model(MU);
    let (tau0, taur) = (1e-4, 0.6e-4);
    let path = [Actuation::tensions(&[tau0]), Actuation::tensions(&[taur])];
    let sols = solve_path(&model, &path, &options(200)).unwrap();
    let sol = &sols[1];
    let front = (tau0 / taur).ln() / (2.0 * MU * KAPPA0);
    assert!(front < LENGTH);
    let mut worst: f64 = 0.0;
    for (j, &s) in sol.statics.s.iter().enumerate() {
        let exact = if s <= front {
            taur * (MU * KAPPA0 * s).exp()
        } else {
            tau0 * (-MU * KAPPA0 * s).exp()
        };
        worst = worst.max(rel(sol.tension[j][0], exact));
        let h = LENGTH / 200.0;
        if s < front - h && j > 0 {
            assert_eq!(sol.slip[j][0], Slip::Unloading, "s = {s}");
        } else if s > front + h {
            assert_eq!(sol.slip[j][0], Slip::Stick, "s = {s}");
        }
    }
    eprintln!("unloading: worst relative error {worst:e} (front at {front} m)");
    assert!(worst < 1e-8, "unloading: worst relative error {worst:e}");
    // Reloading to the first tension restores the loading profile (the front sweeps back).
    let again = solve_frictional(&model, &path[0], &options(200), Some(sol)).unwrap();
    for (j, &s) in again.statics.s.iter().enumerate() {
        let exact = tau0 * (-MU * KAPPA0 * s).exp();
        assert!(rel(again.tension[j][0], exact) < 1e-8);
    }
}

/// The NiTi robot with friction `mu` on every tendon and a lateral tip force.
fn niti(mu: f64, tip: Vector3<f64>) -> Arc<RobotModel> {
    common::niti_model(Loads::tip_force(tip), None, mu)
}

/// With and without a tip force (the fixed point and the one march).
#[test]
fn zero_friction_is_the_frictionless_solver() {
    for tip in [Vector3::new(0.05, -0.02, 0.0), Vector3::zeros()] {
        let model = niti(0.0, tip);
        let act = Actuation::tensions(&[4.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
        let opts = options(50);
        let fr = solve_frictional(&model, &act, &opts, None).unwrap();
        let plain = solve_statics_at(&model, &act, &opts.statics, &fr.statics.s).unwrap();
        let mut worst: f64 = 0.0;
        for (a, b) in fr.statics.position.iter().zip(&plain.position) {
            for k in 0..3 {
                worst = worst.max((a[k] - b[k]).abs());
            }
        }
        eprintln!("μ = 0, tip force {tip:?}: {worst:e} m from the frictionless solve");
        assert!(
            worst < 1e-12,
            "μ = 0 differs from the frictionless solve by {worst:e} m"
        );
        for row in &fr.tension {
            for (i, &t) in row.iter().enumerate() {
                assert!(t == act.tension_values(6)[i] || t == 0.0);
            }
        }
    }
}

/// The path tangent of tendon `i` at node `j`, from the returned pose and strains.
fn path_tangent(model: &RobotModel, sol: &FrictionalSolution, j: usize, i: usize) -> Vector3<f64> {
    let st = &sol.statics;
    let r = Matrix3::from_fn(|a, b| st.rotation[j][a][b]);
    let props = model.rod().section_at(st.s[j]);
    let (o, op) = model.tendons()[i].routing().offset(st.s[j], &props);
    let w = Vector3::from(st.v[j])
        + Vector3::from(st.u[j]).cross(&Vector3::new(o[0], o[1], 0.0))
        + Vector3::new(op[0], op[1], 0.0);
    (r * w).normalize()
}

#[test]
fn capstan_law_holds_along_the_returned_shape() {
    let mu = 0.2;
    let model = niti(mu, Vector3::new(0.03, 0.0, 0.0));
    let act = Actuation::tensions(&[3.0, 0.0, 1.0, 0.0, 2.0, 0.0]);
    let up = solve_frictional(&model, &act, &options(80), None).unwrap();
    let down = Actuation::tensions(&[2.0, 0.0, 1.0, 0.0, 1.5, 0.0]);
    let back = solve_frictional(&model, &down, &options(80), Some(&up)).unwrap();
    let mut stuck = 0;
    for sol in [&up, &back] {
        let s = &sol.statics.s;
        for i in [0, 2, 4] {
            for j in 1..s.len() {
                if sol.slip[j][i] == Slip::Absent {
                    break;
                }
                let (ta, tb) = (
                    path_tangent(&model, sol, j - 1, i),
                    path_tangent(&model, sol, j, i),
                );
                let dtheta = ta.cross(&tb).norm().atan2(ta.dot(&tb));
                let dlog = (sol.tension[j][i] / sol.tension[j - 1][i]).ln();
                match sol.slip[j][i] {
                    Slip::Loading => {
                        assert!((dlog + mu * dtheta).abs() <= 1e-6 * mu * dtheta.max(1e-12) + 1e-15)
                    }
                    Slip::Unloading => {
                        assert!((dlog - mu * dtheta).abs() <= 1e-6 * mu * dtheta.max(1e-12) + 1e-15)
                    }
                    Slip::Stick => {
                        stuck += 1;
                        assert!(dlog.abs() <= mu * dtheta * (1.0 + 1e-6) + 1e-15);
                    }
                    Slip::Absent => unreachable!(),
                }
            }
        }
    }
    assert!(stuck > 0, "the partial unloading sticks somewhere");
}

#[test]
fn global_balance_with_friction() {
    let f_tip = Vector3::new(0.04, -0.03, 0.01);
    let model = niti(0.25, f_tip);
    let act = Actuation::tensions(&[3.0, 0.0, 0.0, 0.0, 2.0, 1.0]);
    let sol = solve_frictional(&model, &act, &options(80), None).unwrap();
    let st = &sol.statics;
    let n = st.s.len() - 1;
    let (p0, pl) = (Vector3::from(st.position[0]), Vector3::from(st.position[n]));
    // Rod + tendons at the base: the rod's own wrench plus each tendon's pull at its base.
    let props = model.rod().section_at(0.0);
    let r0 = Matrix3::from_fn(|a, b| st.rotation[0][a][b]);
    let mut force = Vector3::from(st.n_world[0]);
    let mut moment = Vector3::from(st.m_world[0]);
    for (i, t) in model.tendons().iter().enumerate() {
        let (o, _) = t.routing().offset(0.0, &props);
        let pull = Vector3::from(sol.tangent[0][i]) * sol.tension[0][i];
        force += pull;
        moment += (r0 * Vector3::new(o[0], o[1], 0.0)).cross(&pull);
    }
    // ... balances the tip force (no other external load).
    let ef = (force - f_tip).amax() / f_tip.norm();
    let em = (moment - (pl - p0).cross(&f_tip)).amax() / (f_tip.norm() * 0.4);
    eprintln!("balance: base force {ef:e}, base moment {em:e} (relative)");
    assert!(
        ef < 1e-10 && em < 1e-10,
        "base balance: force {ef:e}, moment {em:e}"
    );
    // At the tip, rod + tendons (with their local tensions) carry the tip force.
    let rl = Matrix3::from_fn(|a, b| st.rotation[n][a][b]);
    let mut tip = Vector3::from(st.n_world[n]);
    let mut tip_m = Vector3::from(st.m_world[n]);
    let props = model.rod().section_at(0.4);
    for (i, t) in model.tendons().iter().enumerate().skip(3) {
        let (o, _) = t.routing().offset(0.4, &props);
        let pull = Vector3::from(sol.tangent[n][i]) * sol.tension[n][i];
        tip += pull;
        tip_m += (rl * Vector3::new(o[0], o[1], 0.0)).cross(&pull);
    }
    assert!(
        (tip - f_tip).amax() / f_tip.norm() < 1e-10,
        "tip force {tip} vs {f_tip}"
    );
    assert!(
        tip_m.amax() / (f_tip.norm() * 0.4) < 1e-10,
        "tip moment {tip_m}"
    );
    // Friction took tension off: the distal tensions are below the base ones.
    assert!(sol.tension[n][4] < 2.0 * 0.99);
}

/// `cycles` load/unload cycles of tendon 0 between 0.5 and 4 N (tendon 4 at 1 N) on the NiTi
/// robot with friction `mu`, `k` steps each way and `steps` RK4 steps: the tensions of
/// tendon 0 and the solutions.
fn cycles_of(
    mu: f64,
    cycles: usize,
    k: usize,
    steps: usize,
) -> (Vec<f64>, Vec<FrictionalSolution>) {
    let model = niti(mu, Vector3::zeros());
    let (lo, hi) = (0.5, 4.0);
    let mut taus = vec![lo];
    for _ in 0..cycles {
        taus.extend((1..=k).map(|j| lo + (hi - lo) * j as f64 / k as f64));
        taus.extend((0..k).rev().map(|j| lo + (hi - lo) * j as f64 / k as f64));
    }
    let path: Vec<Actuation> = taus
        .iter()
        .map(|&t| Actuation::tensions(&[t, 0.0, 0.0, 0.0, 1.0, 0.0]))
        .collect();
    let sols = solve_path(&model, &path, &options(steps)).unwrap();
    (taus, sols)
}

/// A load/unload cycle of tendon 0 between `lo` and `hi` N (tendon 4 at 1 N), `k` steps each
/// way: tip x and the tendon-0 path length at every step.
fn cycle(mu: f64, cycles: usize) -> (Vec<f64>, Vec<[f64; 3]>, Vec<f64>) {
    let (taus, sols) = cycles_of(mu, cycles, 14, 50);
    let tips = sols.iter().map(FrictionalSolution::tip_position).collect();
    let lengths = sols.iter().map(|s| s.statics.tendon_lengths[0]).collect();
    (taus, tips, lengths)
}

#[test]
fn load_unload_cycle_of_the_niti_robot() {
    let mut widths = Vec::new();
    for mu in [0.0, 0.05, 0.1, 0.2] {
        let (taus, tips, lengths) = cycle(mu, 3);
        let n = taus.len();
        let per = (n - 1) / 3;
        // The loop closes: after the first loading from rest, every cycle repeats the second.
        for j in per..=2 * per {
            let (a, b) = (tips[j], tips[j + per]);
            let d = (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max);
            assert!(
                d < 1e-9,
                "μ = {mu}: cycle 3 differs from cycle 2 by {d:e} m at step {j}"
            );
        }
        // Work done by the actuator on the tendon over one cycle (the pull-in is the path
        // shortening): positive with friction.
        let work: f64 = (per..n - 1)
            .map(|j| -0.5 * (taus[j] + taus[j + 1]) * (lengths[j + 1] - lengths[j]))
            .sum();
        // Loop width: the largest tip distance between loading and unloading at equal tension.
        let half = per / 2;
        let width = (1..half)
            .map(|j| {
                let (a, b) = (tips[per + j], tips[per + per - j]);
                (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
            })
            .fold(0.0, f64::max);
        if mu == 0.0 {
            assert!(width < 1e-12, "frictionless loop width {width:e}");
            assert!(work.abs() < 1e-9, "frictionless cycle work {work:e}");
        } else {
            assert!(work > 0.0, "μ = {mu}: dissipated work {work:e} J");
        }
        eprintln!("μ = {mu}: loop width {width:e} m, cycle work {work:e} J");
        widths.push(width);
    }
    for w in widths.windows(2) {
        assert!(w[1] > w[0], "loop width grows with μ: {widths:?}");
    }
}

#[test]
fn bad_friction_is_a_named_error() {
    for mu in [-0.1, f64::NAN, f64::INFINITY] {
        let e = Tendon::constant([0.01, 0.0], None)
            .unwrap()
            .with_friction(mu)
            .unwrap_err();
        assert!(e.to_string().contains("friction"), "{e}");
    }
    // A previous state of another robot (shorter, or with another tendon) is refused by name.
    let a = solve_frictional(
        &arc_model(0.1),
        &Actuation::tensions(&[1e-4]),
        &options(50),
        None,
    )
    .unwrap();
    let shorter = arc_model_of(0.1, 0.8 * LENGTH);
    let two = {
        let m = arc_model(0.1);
        let mut tendons = m.tendons().to_vec();
        tendons.push(Tendon::constant([-0.004, 0.0], None).unwrap());
        RobotModel::new(m.rod().clone(), tendons, Vec::new(), Loads::default()).unwrap()
    };
    for (other, t) in [(shorter, vec![1e-4]), (two, vec![1e-4, 0.0])] {
        let e =
            solve_frictional(&other, &Actuation::tensions(&t), &options(50), Some(&a)).unwrap_err();
        assert!(e.to_string().contains("previous"), "{e}");
    }
    let _ = SolveOptions::default();
}

#[test]
fn the_frictionless_solver_refuses_a_tendon_with_friction() {
    // A uniform tension would be the frictionless answer: the plain solve names the
    // coefficient instead of returning it; with mu = 0 it solves.
    let e = solve_statics_at(
        &arc_model(MU),
        &Actuation::tensions(&[1e-4]),
        &SolveOptions::default(),
        &[],
    )
    .unwrap_err();
    match e {
        softrod::Error::InvalidParameter { name, .. } => assert_eq!(name, "tendons[0].friction"),
        other => panic!("expected a named error, got {other:?}"),
    }
    assert!(solve_statics_at(
        &arc_model(0.0),
        &Actuation::tensions(&[1e-4]),
        &SolveOptions::default(),
        &[]
    )
    .is_ok());
}

/// The one march of an unloaded model (the tension a state of the march) against the fixed
/// point on the profile (rod solves alternating with the capstan rule): the same discrete
/// equations solved two independent ways, from rest and along an unloading/reloading path.
#[test]
fn one_march_equals_the_fixed_point() {
    for mu in [0.05, 0.2, 0.5] {
        let model = niti(mu, Vector3::zeros());
        let path: Vec<Actuation> = [[4.0, 2.0], [2.5, 2.0], [3.0, 1.0], [0.5, 1.5]]
            .iter()
            .map(|t| Actuation::tensions(&[t[0], 0.0, 1.0, 0.0, t[1], 0.0]))
            .collect();
        let mut adaptive = options(50);
        adaptive.statics.integrator = Integrator::Adaptive(softrod::AdaptiveOptions {
            rtol: 1e-10,
            atol: 1e-12,
            ..Default::default()
        });
        for opts in [options(50), adaptive] {
            let mut fixed_point = opts;
            fixed_point.single_march = false;
            let a = solve_path(&model, &path, &opts).unwrap();
            let b = solve_path(&model, &path, &fixed_point).unwrap();
            let (mut dp, mut dt): (f64, f64) = (0.0, 0.0);
            for (x, y) in a.iter().zip(&b) {
                assert_eq!(x.iterations, 1);
                assert!(y.iterations > 1);
                assert_eq!(x.slip.len(), y.slip.len());
                for (p, q) in x.statics.position.iter().zip(&y.statics.position) {
                    for k in 0..3 {
                        dp = dp.max((p[k] - q[k]).abs());
                    }
                }
                for (p, q) in x.tension.iter().zip(&y.tension) {
                    for (s, t) in p.iter().zip(q) {
                        dt = dt.max((s - t).abs() / 4.0);
                    }
                }
                assert_eq!(x.slip, y.slip, "μ = {mu}: slip states differ");
            }
            eprintln!("μ = {mu}: one march vs fixed point: {dp:e} m, {dt:e} relative tension");
            assert!(dp < 1e-10 && dt < 1e-10, "μ = {mu}: {dp:e} m, {dt:e}");
        }
    }
}

/// Work `W` of the base tensions and friction work `D` (force times slip) over the second
/// load/unload cycle of tendon 0 (0.5 → 4 → 0.5 N, tendon 4 at 1 N) in `k` steps each way,
/// with `steps` RK4 steps along the rod; time quadrature by trapezoids.
fn cycle_energy(mu: f64, steps: usize, k: usize) -> (f64, f64) {
    let (_, sols) = cycles_of(mu, 2, k, steps);
    let (mut work, mut friction) = (0.0, 0.0);
    for w in sols[2 * k..].windows(2) {
        let (a, b) = (&w[0], &w[1]);
        for i in 0..6 {
            let (la, lb) = (a.statics.tendon_lengths[i], b.statics.tendon_lengths[i]);
            // The base pulls the tendon in by −δℓ.
            work -= 0.5 * (a.tension[0][i] + b.tension[0][i]) * (lb - la);
            // Slip toward the base at node j: −δ(ℓ − λ_j), λ_j the path length to node j.
            let slip = |j: usize| -((lb - b.path_length[j][i]) - (la - a.path_length[j][i]));
            for j in 0..a.tension.len() - 1 {
                if a.slip[j + 1][i] == Slip::Absent {
                    break;
                }
                let drop = 0.5
                    * ((a.tension[j][i] - a.tension[j + 1][i])
                        + (b.tension[j][i] - b.tension[j + 1][i]));
                friction += drop * 0.5 * (slip(j) + slip(j + 1));
            }
        }
    }
    (work, friction)
}

/// The work the base tensions do over a closed load/unload cycle (the elastic energy
/// returns) is the work friction dissipates, the integral of the friction force times the
/// tendon's slip along its path (the slip from the returned path lengths, the tendon being
/// inextensible): equal to 1e-6 relative at 50 RK4 steps (the difference falls as h³ with the
/// rod's steps: 3.4e-7, 4.9e-8, 6.4e-9 at 40, 80, 160 steps for μ = 0.2), positive, growing
/// with μ; zero without friction.
#[test]
fn cycle_dissipation_is_friction_force_times_slip() {
    let (w0, d0) = cycle_energy(0.0, 50, 25);
    assert!(
        w0.abs() < 1e-12 && d0 == 0.0,
        "frictionless cycle: W {w0:e}, D {d0:e}"
    );
    let mut last = 0.0;
    for mu in [0.05, 0.1, 0.2] {
        let (w, d) = cycle_energy(mu, 50, 25);
        let rel = (w - d).abs() / w;
        eprintln!("μ = {mu}: W = {w:e} J, ∫ friction × slip = {d:e} J, relative {rel:e}");
        assert!(w > last, "μ = {mu}: dissipated work {w:e} J");
        assert!(
            rel < 1e-6,
            "μ = {mu}: W {w:e} J vs friction work {d:e} J ({rel:e})"
        );
        last = w;
    }
}

/// The actuation Jacobian of a frictional equilibrium is the one-sided pull one
/// (`friction_jacobian.rs` checks both directions against one-sided differences), at every
/// node `actuation_jacobians` asks for.
#[test]
fn the_actuation_jacobian_of_a_frictional_equilibrium_is_the_pull_one() {
    use softrod::{actuation_jacobians, Direction, Linearisation};
    let model = niti(0.2, Vector3::zeros());
    let act = Actuation::tensions(&[3.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    let sol = solve_frictional(&model, &act, &options(50), None).unwrap();
    let pull = softrod::actuation_jacobian(&sol.statics, None).unwrap();
    let same =
        softrod::directional_actuation_jacobian(&sol.statics, None, Direction::Pull).unwrap();
    let release =
        softrod::directional_actuation_jacobian(&sol.statics, None, Direction::Release).unwrap();
    assert_eq!(pull, same);
    assert!((&pull - &release).amax() > 1e-2 * pull.amax());
    let last = sol.statics.s.len() - 1;
    let both = actuation_jacobians(&sol.statics, &[10, last], Linearisation::Tension).unwrap();
    assert_eq!(both[1], pull);
    let mid = softrod::directional_actuation_jacobian(&sol.statics, Some(10), Direction::Pull);
    assert_eq!(both[0], mid.unwrap());
}

/// The NiTi robot with friction `mu` on every tendon under `loads`.
fn niti_loaded(mu: f64, loads: Loads, density: Option<f64>) -> Arc<RobotModel> {
    common::niti_model(loads, density, mu)
}

/// Loaded models (tip force, gravity, both): the one march per Newton iterate of the base
/// wrench against the fixed point on the profile (a full rod solve per profile), the same
/// discrete equations solved two independent ways, from rest and along an
/// unloading/reloading path.
#[test]
fn loaded_one_march_equals_the_fixed_point() {
    let tip = Vector3::new(0.05, -0.02, 0.01);
    let g = Vector3::new(0.0, -9.81, 0.0);
    let cases = [
        ("tip force", Loads::tip_force(tip), None),
        (
            "gravity",
            Loads {
                gravity: g,
                ..Loads::default()
            },
            Some(6450.0),
        ),
        // Far from the unloaded rod: the start there may be refused (then the frictionless
        // solve's base wrench).
        (
            "large tip force",
            Loads::tip_force(Vector3::new(0.3, -0.2, 0.05)),
            None,
        ),
        (
            "tip force and gravity",
            Loads {
                gravity: g,
                ..Loads::tip_force(tip)
            },
            Some(6450.0),
        ),
    ];
    let path: Vec<Actuation> = [[4.0, 2.0], [2.5, 2.0], [3.0, 1.0], [0.5, 1.5]]
        .iter()
        .map(|t| Actuation::tensions(&[t[0], 0.0, 1.0, 0.0, t[1], 0.0]))
        .collect();
    for (name, loads, density) in cases {
        for mu in [0.05, 0.2, 0.5] {
            let model = niti_loaded(mu, loads.clone(), density);
            let mut adaptive = options(50);
            adaptive.statics.integrator = Integrator::Adaptive(softrod::AdaptiveOptions {
                // The Newton tolerance of the adaptive integrator is 10 rtol (1 + |x|): tight
                // enough for both solves to resolve the equations below 1e-10 m.
                rtol: 1e-12,
                atol: 1e-14,
                ..Default::default()
            });
            for mut opts in [options(50), adaptive] {
                let mut fixed_point = opts;
                fixed_point.single_march = false;
                // One fixed-point iteration at most: a fall back to the fixed point fails.
                opts.max_iterations = 1;
                let a = solve_path(&model, &path, &opts).unwrap();
                let b = solve_path(&model, &path, &fixed_point).unwrap();
                let (mut dp, mut dt): (f64, f64) = (0.0, 0.0);
                let mut marches = Vec::new();
                for (x, y) in a.iter().zip(&b) {
                    marches.push(x.iterations);
                    // The one-march solve (cell steps of its marches only, no rod solve of
                    // the fixed point).
                    for (p, q) in x.statics.position.iter().zip(&y.statics.position) {
                        for k in 0..3 {
                            dp = dp.max((p[k] - q[k]).abs());
                        }
                    }
                    for (p, q) in x.tension.iter().zip(&y.tension) {
                        for (s, t) in p.iter().zip(q) {
                            dt = dt.max((s - t).abs() / 4.0);
                        }
                    }
                    assert_eq!(x.slip, y.slip, "{name}, μ = {mu}: slip states differ");
                }
                eprintln!(
                    "{name}, μ = {mu}: one march vs fixed point: {dp:e} m, {dt:e} relative \
                     tension; marches {marches:?}, fixed point {:?}",
                    b.iter().map(|s| s.iterations).collect::<Vec<_>>()
                );
                assert!(
                    dp < 1e-10 && dt < 1e-10,
                    "{name}, μ = {mu}: {dp:e} m, {dt:e}"
                );
            }
        }
    }
}

/// Displacement control with friction: the shortenings a tension-controlled path produces,
/// held on the same history, give back its tensions and shapes; with μ = 0 it is the
/// frictionless displacement solve.
#[test]
fn displacement_round_trip_with_friction() {
    use softrod::{reference_lengths, TendonInput};
    let opts = options(50);
    for tip in [Vector3::zeros(), Vector3::new(0.03, -0.02, 0.0)] {
        let model = niti(0.2, tip);
        let reference = reference_lengths(&model, &opts.statics).unwrap();
        let up = Actuation::tensions(&[3.0, 0.0, 0.0, 0.0, 1.5, 0.0]);
        let down = Actuation::tensions(&[1.8, 0.0, 0.0, 0.0, 1.2, 0.0]);
        let first = solve_frictional(&model, &up, &opts, None).unwrap();
        let second = solve_frictional(&model, &down, &opts, Some(&first)).unwrap();
        for (target, prev) in [(&first, None), (&second, Some(&first))] {
            let mut act = Actuation::tensions(&[0.0; 6]);
            for i in [0, 4] {
                act.tendons[i] =
                    TendonInput::displacement(reference[i] - target.statics.tendon_lengths[i]);
            }
            let held = solve_frictional(&model, &act, &opts, prev).unwrap();
            let (mut dt, mut dp): (f64, f64) = (0.0, 0.0);
            for (a, b) in held
                .tension
                .iter()
                .flatten()
                .zip(target.tension.iter().flatten())
            {
                dt = dt.max((a - b).abs() / 3.0);
            }
            for (a, b) in held.statics.position.iter().zip(&target.statics.position) {
                for k in 0..3 {
                    dp = dp.max((a[k] - b[k]).abs());
                }
            }
            eprintln!(
                "displacement round trip (tip {tip:?}, {}): tensions {dt:e} relative, shape \
                 {dp:e} m",
                if prev.is_some() {
                    "unloading"
                } else {
                    "loading"
                }
            );
            assert!(dt < 1e-8 && dp < 1e-10, "round trip: {dt:e}, {dp:e} m");
            assert_eq!(held.slip, target.slip);
        }
    }
    // μ = 0: the frictionless displacement solve.
    let model = niti(0.0, Vector3::new(0.03, -0.02, 0.0));
    let mut act = Actuation::tensions(&[0.0; 6]);
    act.tendons[0] = TendonInput::displacement(0.004);
    act.tendons[4] = TendonInput::displacement(0.002);
    let fr = solve_frictional(&model, &act, &opts, None).unwrap();
    let plain = solve_statics_at(&model, &act, &opts.statics, &fr.statics.s).unwrap();
    let mut worst: f64 = 0.0;
    for (a, b) in fr.statics.position.iter().zip(&plain.position) {
        for k in 0..3 {
            worst = worst.max((a[k] - b[k]).abs());
        }
    }
    let dt = (fr.tension[0][0] - plain.tendon_tensions[0]).abs() / plain.tendon_tensions[0];
    eprintln!("μ = 0 displacement control: {worst:e} m, tension {dt:e} relative");
    assert!(worst < 1e-10 && dt < 1e-8, "{worst:e} m, {dt:e}");
}
