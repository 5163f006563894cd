//! Linearisation of a frictional equilibrium: with μ = 0 the actuation Jacobian and the tangent
//! compliance of a frictional solve equal the frictionless ones (the frictionless Jacobian and
//! compliance at the same nodes), and the one-sided finite differences of the nonlinear
//! frictional solve continued from the solution (`previous` = the solution) show that the
//! derivative of a frictional equilibrium is one-sided: pulling on (sliding) and releasing
//! (sticking) a loaded tendon give different slopes. The one-sided actuation Jacobians
//! (pull and release) equal those one-sided differences, and with a vanishing coefficient
//! the frictional linearisation tends to the frictionless one.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use std::sync::Arc;

use softrod::nalgebra::{Matrix3, Vector3, Vector6};
use softrod::{
    actuation_jacobian, directional_actuation_jacobian, frictional_tip_compliance,
    solve_frictional, solve_statics_at, tangent_compliance, Actuation, Direction, FrictionOptions,
    FrictionalSolution, Integrator, LinearElastic, Loads, Profile, RobotModel, Rod, Section,
    StaticsSolution, Tendon, TendonControl,
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

/// A flexible precurved rod (NiTi, 0.2 m, radius 1 mm, rest curvature 5 /m about body y)
/// with two tendons at 4 mm on either side of the curve, under a tip force.
fn precurved(mu: f64) -> Arc<RobotModel> {
    let rod = Rod::new(
        0.2,
        Section::circular(0.001).unwrap(),
        LinearElastic::new(6e10, 0.33).unwrap(),
    )
    .unwrap()
    .with_rest_curvature(Profile::Constant(Vector3::new(0.0, 5.0, 0.0)))
    .unwrap();
    let tendons = [[0.004, 0.0], [-0.004, 0.0]]
        .into_iter()
        .map(|o| {
            Tendon::constant(o, None)
                .unwrap()
                .with_friction(mu)
                .unwrap()
        })
        .collect();
    let loads = Loads::tip_force(Vector3::new(0.0, 0.02, -0.05));
    RobotModel::new(rod, tendons, Vec::new(), loads).unwrap()
}

/// A state to linearise: its name, model, tensions (N) and the equilibrium.
struct State {
    name: &'static str,
    model: Arc<RobotModel>,
    tensions: Vec<f64>,
    solution: FrictionalSolution,
}

/// The states: the NiTi robot loaded from rest at [`TENSIONS`] (unloaded, tip force,
/// gravity: every element sliding toward the base), the unloaded one then released to 2 N
/// on tendon 1 (a slip front: sliding toward the tip near the base, sticking beyond), and the
/// precurved rod with a tip force loaded from rest at [0.8, 0.3] N; μ = 0.2.
fn states(opts: &FrictionOptions) -> Vec<State> {
    let mut out: Vec<State> = cases(0.2)
        .into_iter()
        .map(|(name, model)| {
            let solution =
                solve_frictional(&model, &Actuation::tensions(&TENSIONS), opts, None).unwrap();
            State {
                name,
                model,
                tensions: TENSIONS.to_vec(),
                solution,
            }
        })
        .collect();
    let model = out[0].model.clone();
    let mut released = TENSIONS;
    released[0] = 2.0;
    let act = Actuation::tensions(&released);
    let solution = solve_frictional(&model, &act, opts, Some(&out[0].solution)).unwrap();
    out.push(State {
        name: "unloaded, released",
        model,
        tensions: released.to_vec(),
        solution,
    });
    let model = precurved(0.2);
    let tensions = vec![0.8, 0.3];
    let solution = solve_frictional(&model, &Actuation::tensions(&tensions), opts, None).unwrap();
    out.push(State {
        name: "precurved, tip force",
        model,
        tensions,
        solution,
    });
    out
}

/// The tip pose change `[δp; δθ]` (world; m, rad) from `a` to `b`, `δθ` the axial vector of
/// the skew part of `R_b R_aᵀ`.
fn tip_change(a: &StaticsSolution, b: &StaticsSolution) -> Vector6<f64> {
    let rot = |s: &StaticsSolution| {
        let r = s.rotation.last().unwrap();
        Matrix3::from_fn(|i, j| r[i][j])
    };
    let d = rot(b) * rot(a).transpose();
    let dp =
        Vector3::from(*b.position.last().unwrap()) - Vector3::from(*a.position.last().unwrap());
    Vector6::new(
        dp.x,
        dp.y,
        dp.z,
        0.5 * (d[(2, 1)] - d[(1, 2)]),
        0.5 * (d[(0, 2)] - d[(2, 0)]),
        0.5 * (d[(1, 0)] - d[(0, 1)]),
    )
}

/// The one-sided difference of the tip pose along the base tension of tendon `i` continued
/// from `st` (its history): `(f(τ + h e_i) − f(τ)) / h`, `h` signed.
fn difference(st: &State, i: usize, h: f64, opts: &FrictionOptions) -> Vector6<f64> {
    let mut t = st.tensions.clone();
    t[i] += h;
    let next = solve_frictional(
        &st.model,
        &Actuation::tensions(&t),
        opts,
        Some(&st.solution),
    )
    .unwrap();
    tip_change(&st.solution.statics, &next.statics) / h
}

/// Relative size of the difference of two vectors (to the second).
fn rel6(a: &Vector6<f64>, b: &Vector6<f64>) -> f64 {
    (a - b).norm() / b.norm()
}

/// The pull and release Jacobians at the tip against the one-sided differences continued
/// from the solution, forward for pull and backward for release, with steps `h` and `h / 10`.
/// On one slip branch the difference is smooth in `h` with an O(h) error: the `h / 10` one
/// is ten times closer to the Jacobian, and their Richardson extrapolation
/// `(10 D(h/10) − D(h)) / 9` (error O(h²), about 1e-10 here, plus the solves' round-off
/// divided by `h`) agrees with it to 1e-6 relative per column.
#[test]
fn one_sided_jacobians_are_the_one_sided_differences() {
    let opts = options(50);
    compare_with_differences(&states(&opts), &opts, 1e-4, 1e-6);
}

/// The same with the adaptive integrator (rtol 1e-10, each cell of the friction mesh
/// stepped to its tolerance, the same steps for the columns): the unloaded NiTi robot loaded
/// from rest and released. (With external loads the adaptive solve stops its Newton
/// iteration at 10 rtol, 1e-9, so its differences at these steps are only good to about
/// 1e-4: no oracle at 1e-6 there.)
#[test]
fn one_sided_jacobians_with_the_adaptive_integrator() {
    let mut opts = options(50);
    opts.statics.integrator = Integrator::Adaptive(softrod::AdaptiveOptions {
        rtol: 1e-10,
        atol: 1e-12,
        ..Default::default()
    });
    let mut all = states(&opts);
    all.retain(|s| s.name.starts_with("unloaded"));
    compare_with_differences(&all, &opts, 1e-4, 1e-6);
}

/// Every column of the pull and release Jacobians of every state against the differences
/// with steps `h` and `h / 10` (see above): the extrapolation to `bound` relative, the
/// `h / 10` difference at least 3.3 times closer than the `h` one.
fn compare_with_differences(states: &[State], opts: &FrictionOptions, h: f64, bound: f64) {
    for st in states {
        for direction in [Direction::Pull, Direction::Release] {
            let j = directional_actuation_jacobian(&st.solution.statics, None, direction).unwrap();
            let sign = direction.sign();
            let (mut worst, mut worst_fine) = (0.0f64, 0.0f64);
            for i in 0..st.tensions.len() {
                let col = Vector6::from_fn(|r, _| j[(r, i)]);
                if sign < 0.0 && st.tensions[i] == 0.0 {
                    // A slack tendon cannot be released: its release column is zero.
                    assert_eq!(col.norm(), 0.0, "{}: slack tendon {i}", st.name);
                    continue;
                }
                let coarse = difference(st, i, sign * h, opts);
                let fine = difference(st, i, sign * h / 10.0, opts);
                let extrapolated = (fine * 10.0 - coarse) / 9.0;
                let (e_coarse, e_fine) = (rel6(&coarse, &col), rel6(&fine, &col));
                let e = rel6(&extrapolated, &col);
                eprintln!(
                    "{} {direction:?} tendon {i}: |J| = {:.3e}; difference h {e_coarse:.2e}, \
                     h/10 {e_fine:.2e}, extrapolated {e:.2e} (relative)",
                    st.name,
                    col.norm()
                );
                worst = worst.max(e);
                worst_fine = worst_fine.max(e_fine);
                assert!(e <= bound, "{} {direction:?} {i}: {e:e}", st.name);
                assert!(
                    e_fine < 0.3 * e_coarse,
                    "{} {direction:?} {i}: not O(h): {e_coarse:e} {e_fine:e}",
                    st.name
                );
            }
            eprintln!(
                "{} {direction:?}: worst {worst:.2e} relative to the extrapolated differences \
                 ({worst_fine:.2e} to the h/10 ones)",
                st.name
            );
        }
    }
}

/// As the coefficient vanishes, the frictional linearisation (every element sliding, the
/// tension profile varying with the shape) tends to the frictionless Jacobian of the same
/// equilibrium at O(μ): at μ = 1e-9 they agree to 1e-8 relative.
#[test]
fn vanishing_friction_tends_to_the_frictionless_jacobian() {
    let opts = options(50);
    let act = Actuation::tensions(&TENSIONS);
    for ((name, model), (_, plain_model)) in cases(1e-9).into_iter().zip(cases(0.0)) {
        let fr = solve_frictional(&model, &act, &opts, None).unwrap();
        let plain = solve_statics_at(&plain_model, &act, &opts.statics, &fr.statics.s).unwrap();
        for direction in [Direction::Pull, Direction::Release] {
            let a = directional_actuation_jacobian(&fr.statics, None, direction).unwrap();
            let b = actuation_jacobian(&plain, None).unwrap();
            // The release columns of the slack tendons are zero.
            let cols: Vec<usize> = (0..TENSIONS.len())
                .filter(|&i| direction == Direction::Pull || TENSIONS[i] > 0.0)
                .collect();
            let pick = |m: &softrod::nalgebra::DMatrix<f64>| -> Vec<f64> {
                cols.iter()
                    .flat_map(|&i| m.column(i).iter().copied().collect::<Vec<_>>())
                    .collect()
            };
            let (a, b) = (pick(&a), pick(&b));
            let e = rel(&a, &b);
            eprintln!(
                "μ = 1e-9, {name}, {direction:?}: {e:e} relative to the frictionless Jacobian"
            );
            assert!(e < 1e-8, "{name} {direction:?}: {e:e}");
        }
    }
}

/// The NiTi robot of `case` ([`cases`]) at μ with `extra` (N, N m; world) added to its tip
/// wrench.
fn with_tip_wrench(case: &str, mu: f64, extra: &Vector6<f64>) -> Arc<RobotModel> {
    let (_, model) = cases(mu).into_iter().find(|(n, _)| *n == case).unwrap();
    let mut loads = model.loads().clone();
    loads.tip_force += Vector3::new(extra[0], extra[1], extra[2]);
    loads.tip_moment += Vector3::new(extra[3], extra[4], extra[5]);
    let density = (case == "gravity").then_some(6450.0);
    common::niti_model(loads, density, mu)
}

/// The one-sided tip compliance of a frictional equilibrium (the tension profile following
/// the stick/slip rule) against the one-sided differences of the solve continued from the
/// solution under a small added tip force or moment, for increasing (pull) and decreasing
/// (release) wrench components: the `h / 10` difference to 1e-6 relative per column, steps
/// 1e-6 N and 1e-8 N m. The steps are small because a wrench change moves some elements'
/// `δlo` close to zero, and such an element changes branch at a finite step: releasing the
/// moment about y on the unloaded robot, the difference at 1e-7 N m is 2.9e-5 off (another
/// branch), at 1e-8 N m 1.6e-7 (the derivative's); the forces' differences are O(h)
/// (1.7e-5 at 1e-5 N, 1.7e-6 at 1e-6 N).
#[test]
fn one_sided_tip_compliance_is_the_one_sided_difference() {
    let opts = options(50);
    for st in states(&opts).into_iter().take(3) {
        for direction in [Direction::Pull, Direction::Release] {
            let c = frictional_tip_compliance(&st.solution.statics, direction).unwrap();
            let sign = direction.sign();
            let mut worst = 0.0f64;
            for k in 0..6 {
                let col = Vector6::from_fn(|r, _| c[(r, k)]);
                let h = if k < 3 { 1e-6 } else { 1e-8 };
                let diff = |step: f64| {
                    let model = with_tip_wrench(st.name, 0.2, &(Vector6::ith(k, 1.0) * step));
                    let act = Actuation::tensions(&st.tensions);
                    let next = solve_frictional(&model, &act, &opts, Some(&st.solution)).unwrap();
                    tip_change(&st.solution.statics, &next.statics) / step
                };
                let (coarse, fine) = (diff(sign * h), diff(sign * h / 10.0));
                let extrapolated = (fine * 10.0 - coarse) / 9.0;
                let (e_coarse, e_fine) = (rel6(&coarse, &col), rel6(&fine, &col));
                let e = rel6(&extrapolated, &col);
                eprintln!(
                    "{} {direction:?} tip wrench {k}: |C| = {:.3e}; difference h {e_coarse:.2e}, \
                     h/10 {e_fine:.2e}, extrapolated {e:.2e}",
                    st.name,
                    col.norm()
                );
                worst = worst.max(e_fine);
                assert!(e_fine <= 1e-6, "{} {direction:?} {k}: {e_fine:e}", st.name);
            }
            // Against the compliance with the profile held fixed.
            let fixed = tangent_compliance(&st.solution.statics, TendonControl::Tension, None)
                .unwrap()
                .world;
            eprintln!(
                "{} {direction:?}: worst {worst:.2e}; |C − C_fixed profile| / |C| = {:.2e}",
                st.name,
                (c - fixed).norm() / c.norm()
            );
        }
    }
}

/// A pressure column of a frictional equilibrium: the precurved rod with a chamber (0.5 mm²
/// at 0.5 mm on body y, 200 kPa) beside its two frictional tendons, under its tip force,
/// loaded from rest; the pull and release columns of the pressure against the one-sided
/// differences continued from the solution (steps 50 and 5 Pa, extrapolated), to 1e-6.
#[test]
fn a_pressure_column_is_the_one_sided_difference() {
    use softrod::{Chamber, ChamberArea};
    let opts = options(50);
    let base = precurved(0.2);
    let chamber = Chamber::new(ChamberArea::Constant(5e-7), [0.0, 0.0005], 0.0, None).unwrap();
    let model = RobotModel::new(
        base.rod().clone(),
        base.tendons().to_vec(),
        vec![chamber],
        base.loads().clone(),
    )
    .unwrap();
    let (tensions, p) = ([0.8, 0.3], 2e5);
    let act = |p: f64| Actuation::tensions(&tensions).with_pressures(&[p]);
    let sol = solve_frictional(&model, &act(p), &opts, None).unwrap();
    for direction in [Direction::Pull, Direction::Release] {
        let j = directional_actuation_jacobian(&sol.statics, None, direction).unwrap();
        let col = Vector6::from_fn(|r, _| j[(r, 2)]);
        let diff = |h: f64| {
            let next = solve_frictional(&model, &act(p + h), &opts, Some(&sol)).unwrap();
            tip_change(&sol.statics, &next.statics) / h
        };
        let sign = direction.sign();
        let (coarse, fine) = (diff(sign * 50.0), diff(sign * 5.0));
        let e = rel6(&((fine * 10.0 - coarse) / 9.0), &col);
        let (e_coarse, e_fine) = (rel6(&coarse, &col), rel6(&fine, &col));
        eprintln!(
            "chamber {direction:?}: |J| = {:.3e} m/Pa; difference 50 Pa {e_coarse:.2e}, 5 Pa \
             {e_fine:.2e}, extrapolated {e:.2e}",
            col.norm()
        );
        // Both steps and the extrapolation agree; the truncation error is below the solves'
        // round-off (a few 1e-16 m of tip motion per 5 Pa step) from 50 Pa on, so no O(h)
        // trend is asserted.
        assert!(
            e <= 1e-6 && e_coarse <= 1e-6 && e_fine <= 1e-6,
            "{direction:?}: {e_coarse:e} {e_fine:e} {e:e}"
        );
    }
}
