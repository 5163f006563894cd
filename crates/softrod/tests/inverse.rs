//! Inverse statics: round trips through the forward solve, the optimality (KKT) conditions of
//! the minimum-norm program checked with the exact Jacobian, out-of-reach targets, shape
//! targets, loads, and the PCC version (its actuation Jacobian against central differences).

#![allow(clippy::unwrap_used, clippy::too_many_lines)]

mod common;

use std::sync::Arc;

use common::niti_model;
use softrod::nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use softrod::pcc::statics::{solve_pcc_statics, PccLoads, PccRobot, PccSolveOptions};
use softrod::pcc::{pcc_actuation_jacobian, ElasticSegment, PccTendons};
use softrod::{
    actuation_jacobian, inverse_statics, solve_inverse, solve_statics, Actuation, CosseratForward,
    Error, Forward, InverseOptions, InverseWarmStart, Loads, PccForward, Pose, RobotModel,
    SolveOptions, Target,
};

fn niti(loads: Loads, density: Option<f64>) -> Arc<RobotModel> {
    niti_model(loads, density, 0.0)
}

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64) / ((1u64 << 53) as f64)
    }
}

/// Random admissible tensions: each segment pulled by at most two of its tendons (N).
fn random_tensions(g: &mut Lcg, max: f64) -> [f64; 6] {
    let mut t = [0.0; 6];
    for seg in 0..2 {
        let off = (g.next() * 3.0) as usize % 3;
        t[3 * seg + off] = g.next() * max;
        t[3 * seg + (off + 1) % 3] = g.next() * max;
    }
    t
}

/// The KKT conditions of `min ½|a|²` s.t. `J_p a = p`, `a >= 0` at the solution: the
/// multipliers from the free tensions, and the gradient sign at the bounds.
fn check_kkt(model: &Arc<RobotModel>, a: &[f64]) {
    let sol = solve_statics(model, &Actuation::tensions(a), &SolveOptions::default()).unwrap();
    let j = actuation_jacobian(&sol, None).unwrap();
    let jp = j.rows(0, 3).into_owned();
    let free: Vec<usize> = (0..a.len()).filter(|&i| a[i] > 1e-12).collect();
    // a_F = J_Fᵀ λ: least squares for λ.
    let jf = DMatrix::from_fn(3, free.len(), |r, k| jp[(r, free[k])]);
    let af = DVector::from_fn(free.len(), |k, _| a[free[k]]);
    let lambda = (&jf * jf.transpose()).lu().solve(&(&jf * &af)).unwrap();
    let res = &af - jf.transpose() * &lambda;
    let scale = af.amax();
    assert!(res.amax() <= 1e-7 * scale, "stationarity {:e}", res.amax());
    // At a zero tension the gradient of the objective minus Jᵀλ must be >= 0.
    let g = DVector::from_column_slice(a) - jp.transpose() * &lambda;
    for i in 0..a.len() {
        if a[i] <= 1e-12 {
            assert!(
                g[i] >= -1e-7 * scale,
                "bound multiplier of tendon {i}: {}",
                g[i]
            );
        }
    }
}

#[test]
fn niti_round_trip_reaches_every_target_inside_the_bounds() {
    let model = niti(Loads::default(), None);
    let o = SolveOptions::default();
    let mut g = Lcg(3);
    let n = 40;
    let mut reached = 0;
    let mut worst = 0.0f64;
    let mut iterations = 0;
    for k in 0..n {
        let t = random_tensions(&mut g, 4.0);
        let tip = solve_statics(&model, &Actuation::tensions(&t), &o)
            .unwrap()
            .tip_position();
        let target = Target::tip(Vector3::from(tip));
        let opts = InverseOptions {
            throw: false,
            ..Default::default()
        };
        let (inv, sol) = inverse_statics(&model, &target, &opts, &o, None).unwrap();
        let err = (Vector3::from(sol.tip_position()) - target.points[0]).norm();
        assert!(inv.tensions().iter().all(|&x| x >= 0.0));
        worst = worst.max(err);
        iterations += inv.iterations;
        if inv.converged && err <= 1e-9 {
            reached += 1;
        } else {
            println!(
                "target {k} ({t:?}): error {err:e}, converged {}",
                inv.converged
            );
        }
        if k < 8 {
            check_kkt(&model, inv.tensions());
        }
    }
    println!(
        "{reached}/{n} reached, worst {worst:e} m, mean iterations {:.1}",
        iterations as f64 / n as f64
    );
    assert_eq!(reached, n);
}

/// The NiTi robot (density 6450 kg/m³) under gravity along -y and a lateral tip load (an
/// axial 0.2 N would exceed the rod's Euler load, 0.16 N: several equilibria per actuation).
fn niti_under_gravity_and_tip_load() -> Arc<RobotModel> {
    let loads = Loads {
        tip_force: Vector3::new(0.02, 0.0, -0.01),
        gravity: Vector3::new(0.0, -9.81, 0.0),
        ..Default::default()
    };
    niti(loads, Some(6450.0))
}

#[test]
fn niti_under_gravity_and_tip_load_reaches_targets() {
    let model = niti_under_gravity_and_tip_load();
    let o = SolveOptions::default();
    let mut g = Lcg(5);
    for _ in 0..6 {
        let t = random_tensions(&mut g, 3.0);
        let tip = solve_statics(&model, &Actuation::tensions(&t), &o)
            .unwrap()
            .tip_position();
        let target = Target::tip(Vector3::from(tip));
        let (inv, sol) =
            inverse_statics(&model, &target, &InverseOptions::default(), &o, None).unwrap();
        let err = (Vector3::from(sol.tip_position()) - target.points[0]).norm();
        assert!(inv.converged && err <= 1e-9, "{err:e}");
        check_kkt(&model, inv.tensions());
    }
}

#[test]
fn a_target_out_of_reach_is_reported_with_its_distance() {
    let model = niti(Loads::default(), None);
    let o = SolveOptions::default();
    // Straight ahead, 0.1 m beyond the tip of the straight rod.
    let target = Target::tip(Vector3::new(0.0, 0.0, 0.5));
    match inverse_statics(&model, &target, &InverseOptions::default(), &o, None) {
        Err(Error::TargetUnreachable { distance, .. }) => {
            assert!((distance - 0.1).abs() < 1e-6, "{distance}");
        }
        other => panic!("{other:?}"),
    }
    let opts = InverseOptions {
        throw: false,
        ..Default::default()
    };
    let (inv, _) = inverse_statics(&model, &target, &opts, &o, None).unwrap();
    assert!(!inv.converged && !inv.reached);
    assert!((inv.position_error - 0.1).abs() < 1e-6);
    assert!(inv.tensions().iter().all(|&t| t == 0.0));
    // Bounded tensions make a reachable target unreachable.
    let t = [4.0, 0.0, 0.0, 0.0, 2.0, 0.0];
    let tip = solve_statics(&model, &Actuation::tensions(&t), &o)
        .unwrap()
        .tip_position();
    let opts = InverseOptions {
        tension_bounds: (0.0, 1.0),
        throw: false,
        ..Default::default()
    };
    let (inv, _) =
        inverse_statics(&model, &Target::tip(Vector3::from(tip)), &opts, &o, None).unwrap();
    assert!(!inv.converged && inv.position_error > 1e-3);
    assert!(inv.tensions().iter().all(|&t| (0.0..=1.0).contains(&t)));
}

#[test]
fn a_shape_target_is_reached_from_its_backbone_points() {
    let model = niti(Loads::default(), None);
    let o = SolveOptions::default();
    let t = common::NITI_REFERENCE_TENSIONS;
    let sol = solve_statics(&model, &Actuation::tensions(&t), &o).unwrap();
    // Points at mesh nodes and between them.
    let n = sol.s.len();
    let idx = [n / 4, n / 2, n - 1];
    let mut s: Vec<f64> = idx.iter().map(|&i| sol.s[i]).collect();
    let mut points: Vec<Vector3<f64>> = idx
        .iter()
        .map(|&i| Vector3::from(sol.position[i]))
        .collect();
    let target = Target {
        points: points.clone(),
        s: Some(s.clone()),
        rotation: None,
    };
    let (inv, back) =
        inverse_statics(&model, &target, &InverseOptions::default(), &o, None).unwrap();
    assert!(
        inv.converged && inv.position_error <= 1e-9,
        "{}",
        inv.position_error
    );
    for (k, &i) in idx.iter().enumerate() {
        assert!((Vector3::from(back.position[i]) - points[k]).norm() <= 1e-9);
    }
    // Off-mesh arc lengths: the model gets breaks there; a least-squares fit, converged.
    s[0] += 0.0031;
    points[0] += Vector3::new(1e-3, 0.0, 0.0);
    let target = Target {
        points,
        s: Some(s),
        rotation: None,
    };
    let (inv, _) = inverse_statics(&model, &target, &InverseOptions::default(), &o, None).unwrap();
    assert!(inv.converged && inv.position_error > 1e-5);
}

#[test]
fn a_rotation_target_is_reached() {
    let model = niti(Loads::default(), None);
    let o = SolveOptions::default();
    let t = common::NITI_REFERENCE_TENSIONS;
    let sol = solve_statics(&model, &Actuation::tensions(&t), &o).unwrap();
    let r = sol.rotation[sol.s.len() - 1];
    let rot = softrod::nalgebra::Matrix3::new(
        r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1], r[2][2],
    );
    let target = Target {
        points: vec![Vector3::from(sol.tip_position())],
        s: None,
        rotation: Some(rot),
    };
    let (inv, _) = inverse_statics(&model, &target, &InverseOptions::default(), &o, None).unwrap();
    assert!(inv.converged, "{inv:?}");
    assert!(inv.position_error <= 1e-9 && inv.rotation_error <= 1e-8);
    // Six targets, six tendons: the same tensions.
    for (a, b) in inv.tensions().iter().zip(&t) {
        assert!((a - b).abs() <= 1e-6 * 3.0, "{a} vs {b}");
    }
}

#[test]
fn warm_started_tracking_takes_few_iterations() {
    let model = niti(Loads::default(), None);
    let o = SolveOptions::default();
    let tip = common::niti_reference_tip(&model, &o);
    let (first, _) = inverse_statics(
        &model,
        &Target::tip(tip),
        &InverseOptions::default(),
        &o,
        None,
    )
    .unwrap();
    let mut warm = InverseWarmStart::from(&first);
    let mut total = 0;
    let mut probes = 0;
    for k in 1..=10 {
        let p = tip + Vector3::new(1e-3 * k as f64, 0.0, 0.0);
        let (inv, sol) = inverse_statics(
            &model,
            &Target::tip(p),
            &InverseOptions::default(),
            &o,
            Some(&warm),
        )
        .unwrap();
        assert!((Vector3::from(sol.tip_position()) - p).norm() <= 1e-9);
        total += inv.evaluations;
        probes += inv.probes;
        warm = InverseWarmStart::from(&inv);
    }
    println!(
        "per 1 mm step: {:.1} evaluations with the Jacobian, {:.1} probes",
        total as f64 / 10.0,
        probes as f64 / 10.0
    );
    // At most 4 evaluations with the Jacobian per step, and the probes of the curvature (a
    // march of the state alone, about a quarter of one) at most 3 per Newton step.
    assert!(total <= 40, "{total}");
    assert!(probes <= 3 * total, "{probes} probes, {total} evaluations");
}

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

#[test]
fn pcc_actuation_jacobian_matches_central_differences() {
    let robot = pcc_niti();
    for tip_force in [Vector3::zeros(), Vector3::new(0.2, -0.1, 0.3)] {
        let loads = |t: &[f64]| PccLoads {
            tensions: t.to_vec(),
            tip_force,
            ..Default::default()
        };
        let t = [3.0, 0.2, 1.0, 0.1, 2.0, 0.5];
        let o = PccSolveOptions::default();
        let sol = solve_pcc_statics(&robot, &loads(&t), &o).unwrap();
        let j = pcc_actuation_jacobian(&robot, &loads(&t), &sol).unwrap();
        let h = 1e-5;
        for k in 0..6 {
            let (mut up, mut down) = (t, t);
            up[k] += h;
            down[k] -= h;
            let pu = solve_pcc_statics(&robot, &loads(&up), &o).unwrap().tip_pose;
            let pd = solve_pcc_statics(&robot, &loads(&down), &o)
                .unwrap()
                .tip_pose;
            let dp = (pu.fixed_view::<3, 1>(0, 3) - pd.fixed_view::<3, 1>(0, 3)) / (2.0 * h);
            let dr = pu.fixed_view::<3, 3>(0, 0) * pd.fixed_view::<3, 3>(0, 0).transpose();
            let dw = softrod::math::so3::log_so3(&dr.into_owned()) / (2.0 * h);
            let col = j.column(k);
            let scale = col.amax();
            for r in 0..3 {
                assert!((dp[r] - col[r]).abs() <= 1e-6 * scale, "{k} {r}");
                assert!((dw[r] - col[r + 3]).abs() <= 1e-6 * scale, "{k} {r}");
            }
        }
    }
}

#[test]
fn pcc_inverse_round_trip() {
    let robot = pcc_niti();
    let o = PccSolveOptions::default();
    let mut g = Lcg(9);
    for _ in 0..20 {
        let t = random_tensions(&mut g, 4.0);
        let loads = PccLoads {
            tensions: t.to_vec(),
            ..Default::default()
        };
        let tip = solve_pcc_statics(&robot, &loads, &o).unwrap().tip_pose;
        let target = Target::tip(Vector3::new(tip[(0, 3)], tip[(1, 3)], tip[(2, 3)]));
        let mut fwd = PccForward::new(&robot, &PccLoads::default(), &o);
        let inv = solve_inverse(&mut fwd, &target, &InverseOptions::default(), None).unwrap();
        assert!(inv.converged && inv.position_error <= 1e-9);
    }
}

/// The statics solution returned with the inverse of an unloaded robot (assembled from the
/// inverse's last march) is the forward solve at the tensions found.
#[test]
fn the_returned_solution_is_the_forward_solve_at_the_actuation_found() {
    let model = niti(Loads::default(), None);
    let o = SolveOptions::default();
    let t = [2.0, 0.0, 1.0, 0.0, 1.5, 0.5];
    let tip = Vector3::from(
        solve_statics(&model, &Actuation::tensions(&t), &o)
            .unwrap()
            .tip_position(),
    );
    let (inv, sol) = inverse_statics(
        &model,
        &Target::tip(tip),
        &InverseOptions::default(),
        &o,
        None,
    )
    .unwrap();
    let fwd = solve_statics(&model, &Actuation::tensions(inv.tensions()), &o).unwrap();
    assert_eq!(sol.s, fwd.s);
    assert_eq!(sol.tendon_tensions, fwd.tendon_tensions);
    assert_eq!(sol.base_wrench, fwd.base_wrench);
    assert!(sol.stats.converged && sol.stable == fwd.stable);
    assert_eq!(
        (
            sol.stats.iterations,
            sol.stats.load_steps,
            sol.stats.load_factor
        ),
        (
            fwd.stats.iterations,
            fwd.stats.load_steps,
            fwd.stats.load_factor
        )
    );
    let close = |a: &[[f64; 3]], b: &[[f64; 3]], scale: f64, what: &str| {
        for (x, y) in a.iter().zip(b) {
            for k in 0..3 {
                assert!(
                    (x[k] - y[k]).abs() <= 1e-13 * scale,
                    "{what}: {x:?} vs {y:?}"
                );
            }
        }
    };
    close(&sol.position, &fwd.position, 0.4, "position");
    close(&sol.m_world, &fwd.m_world, 1.0, "moment");
    close(&sol.u, &fwd.u, 1.0 / 0.4, "curvature");
    for (x, y) in sol.tendon_lengths.iter().zip(&fwd.tendon_lengths) {
        assert!((x - y).abs() <= 1e-14, "tendon length {x} vs {y}");
    }
    assert_eq!(sol.jacobian, fwd.jacobian);
    assert!((Vector3::from(sol.tip_position()) - tip).norm() <= 1e-9);
}

/// The forward model of an unloaded robot with uniform intervals (the NiTi robot, at the
/// origin and on a moved, tilted base) evaluates the RK4 march in closed form: its tip pose
/// is the forward solve's to round-off, and its actuation Jacobian the one integrated with the
/// march (the variational columns of `actuation_jacobian`), taut and slack tendons alike.
#[test]
fn the_closed_form_march_of_uniform_intervals_is_the_march() {
    let o = SolveOptions::default();
    let (c, s) = (0.3f64.cos(), 0.3f64.sin());
    let tilted = Pose::new(
        Vector3::new(0.05, -0.02, 0.1),
        Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c),
    )
    .unwrap();
    let tendons = || {
        common::niti_tendons(&[0.0; 6])
            .into_iter()
            .map(|t| t.tendon)
            .collect::<Vec<_>>()
    };
    let models = [
        niti(Loads::default(), None),
        RobotModel::new(
            common::niti_rod().with_base_pose(tilted),
            tendons(),
            Vec::new(),
            Loads::default(),
        )
        .unwrap(),
    ];
    let mut g = Lcg(11);
    let mut sets = vec![
        [0.0; 6],
        [3.0, 0.0, 1.0, 0.0, 2.0, 0.5],
        [1.0; 6],
        [0.0, 0.0, 0.0, 2.0, 0.0, 0.5],
    ];
    sets.extend((0..4).map(|_| random_tensions(&mut g, 4.0)));
    let (mut worst_p, mut worst_j) = (0.0f64, 0.0f64);
    for model in &models {
        let mut fwd = CosseratForward::new(model, &o, None).unwrap();
        for t in &sets {
            let ev = fwd.evaluate(t, true).unwrap();
            let probe = fwd.probe(t).unwrap();
            let sol = solve_statics(model, &Actuation::tensions(t), &o).unwrap();
            let tip = Vector3::from(sol.tip_position());
            let r = sol.rotation[sol.s.len() - 1];
            let rot = Matrix3::from_fn(|i, j| r[i][j]);
            let dp = (ev.positions[0] - tip).norm();
            let dr = (ev.rotation - rot).amax();
            assert!(
                dp <= 1e-14 && dr <= 1e-13,
                "{t:?}: tip {dp:e} m, rotation {dr:e}"
            );
            assert!((probe.positions[0] - ev.positions[0]).norm() <= 1e-15);
            let marched = actuation_jacobian(&sol, None).unwrap();
            let closed = &ev.jacobian.as_ref().unwrap()[0];
            for rows in [0, 3] {
                let m = marched.rows(rows, 3);
                let scale = m.amax();
                let err = (closed.rows(rows, 3) - m).amax() / scale;
                worst_j = worst_j.max(err);
                assert!(
                    err <= 1e-12,
                    "{t:?}: rows {rows}.. differ by {err:e} relative"
                );
            }
            worst_p = worst_p.max(dp);
        }
    }
    println!("worst tip difference {worst_p:e} m, worst Jacobian difference {worst_j:e} relative");
}

/// The closed-form march with a tendon along the axis (offset 0): pulled alone on the straight
/// rod it only shortens it (its column changes the step's translation, not its rotation),
/// and its Jacobian column is still the marched one.
#[test]
fn the_closed_form_march_holds_a_tendon_along_the_axis() {
    let o = SolveOptions::default();
    let mut tendons: Vec<_> = common::niti_tendons(&[0.0; 6])
        .into_iter()
        .map(|t| t.tendon)
        .collect();
    tendons.push(common::tendon([0.0, 0.0], 0.0, None).unwrap().tendon);
    let model = RobotModel::new(common::niti_rod(), tendons, Vec::new(), Loads::default()).unwrap();
    let mut fwd = CosseratForward::new(&model, &o, None).unwrap();
    for t in [
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0],
        [1.0, 0.0, 0.0, 0.0, 0.5, 0.0, 2.0],
    ] {
        let ev = fwd.evaluate(&t, true).unwrap();
        let sol = solve_statics(&model, &Actuation::tensions(&t), &o).unwrap();
        assert!((ev.positions[0] - Vector3::from(sol.tip_position())).norm() <= 1e-14);
        let marched = actuation_jacobian(&sol, None).unwrap();
        let closed = &ev.jacobian.as_ref().unwrap()[0];
        let scale = marched.amax();
        let err = (closed - &marched).amax() / scale;
        assert!(err <= 1e-12, "{t:?}: Jacobians differ by {err:e} relative");
        assert!(
            marched[(2, 6)].abs() > 1e-9 * scale,
            "the axial tendon shortens the rod"
        );
    }
}

/// A uniform rod (0.4 m, radius 3 mm, E 1 MPa) with two antagonistic tendons at 2 mm, at
/// tensions that curl it.
fn curled_uniform() -> Arc<RobotModel> {
    let rod = softrod::Rod::new(
        0.4,
        softrod::Section::circular(0.003).unwrap(),
        softrod::LinearElastic::new(1e6, 0.5).unwrap(),
    )
    .unwrap();
    let tendons = vec![
        softrod::Tendon::constant([0.002, 0.0], None).unwrap(),
        softrod::Tendon::constant([-0.002, 0.0], None).unwrap(),
    ];
    RobotModel::new(rod, tendons, vec![], Loads::default()).unwrap()
}

/// The closed-form estimate of a uniform unloaded robot's mesh error (per interval, the
/// constant strains of its stages) is the sum `Σ θ⁵/120 (L - s)/L` over the nodes of the
/// forward solve at the same actuation, on the NiTi robot and a curled uniform rod.
#[test]
fn the_closed_form_mesh_error_is_the_sum_over_the_solved_nodes() {
    let o = SolveOptions::default();
    let cases: [(Arc<RobotModel>, Vec<f64>); 3] = [
        (
            niti(Loads::default(), None),
            vec![2.0, 0.0, 1.0, 0.0, 1.5, 0.5],
        ),
        (curled_uniform(), vec![0.02, 0.005]),
        (curled_uniform(), vec![1.9, 0.3]),
    ];
    for (model, a) in cases {
        let mut fwd = CosseratForward::new(&model, &o, None).unwrap();
        let closed = fwd.mesh_error(&a);
        let sol = solve_statics(&model, &Actuation::tensions(&a), &o).unwrap();
        let summed = softrod::compliance::rk4_position_error(&sol);
        println!("{a:?}: closed form {closed:e}, over the nodes {summed:e}");
        assert!(summed > 0.0);
        assert!(
            (closed - summed).abs() <= 1e-10 * summed,
            "{closed:e} vs {summed:e}"
        );
    }
}

/// On the uniform rod curled 1.9 turns the default mesh errs by 5.5e-3 L at the answer: the
/// inverse ran on it alone (as on 41 chosen steps, which are kept) and found tensions off by
/// 0.5 % and 3 %, the tip of their adaptive solve 0.16 mm from the target. It runs again on a
/// finer mesh (1,120 steps); 8 chosen steps are refused, naming them (they were reported out
/// of reach by 17 mm). Oracle: the target is the adaptive integrator's tip at known tensions,
/// which are found again.
#[test]
fn an_inverse_on_a_curl_the_default_mesh_cannot_resolve_is_solved_on_a_finer_one() {
    let model = curled_uniform();
    let truth = [1.9, 0.3];
    let adaptive = SolveOptions {
        integrator: softrod::Integrator::Adaptive(softrod::AdaptiveOptions {
            rtol: 1e-10,
            atol: 1e-12,
            ..Default::default()
        }),
        ..SolveOptions::default()
    };
    let tip = |a: &[f64]| {
        Vector3::from(
            solve_statics(&model, &Actuation::tensions(a), &adaptive)
                .unwrap()
                .tip_position(),
        )
    };
    let target = Target::tip(tip(&truth));
    let o = SolveOptions::default();
    let io = InverseOptions::default();
    // (A curl of 1.9 turns is reached by other tensions too: the inverse starts near these.)
    let near = InverseWarmStart::actuation(truth.iter().map(|t| 1.02 * t).collect());
    let inv = softrod::inverse_actuation(&model, &target, &io, &o, Some(&near)).unwrap();
    let (with, sol) = inverse_statics(&model, &target, &io, &o, Some(&near)).unwrap();
    println!(
        "found {:?}, solved on {:?}",
        inv.actuation, sol.options.integrator
    );
    assert!(inv.reached && with.reached);
    assert_eq!(inv.actuation, with.actuation);
    for (got, want) in inv.actuation.iter().zip(truth) {
        assert!((got - want).abs() <= 1e-6 * want, "{got} vs {want}");
    }
    assert!((tip(&inv.actuation) - tip(&truth)).norm() <= 1e-8);
    // A chosen mesh that turns by radians a step is refused, naming it.
    let coarse = SolveOptions {
        integrator: softrod::Integrator::Rk4 { steps: 8 },
        ..o
    };
    match softrod::inverse_actuation(&model, &target, &io, &coarse, Some(&near)) {
        Err(Error::InvalidParameter { name, .. }) => assert_eq!(name, "steps"),
        other => panic!("8 steps: {other:?}"),
    }
}

/// A soft tapered arm (0.39 m, radius 8.0 to 7.6 mm, 0.17 MPa) with two antagonistic tendons,
/// curled by 5.65 N on the second: from rest the iteration stops beyond a fold of the tip's
/// map (the target reported out of reach); from 16 spread starts the known tensions are found
/// (the least norm of the answers), from given starts too, and the answer's start is named.
#[test]
fn several_starts_reach_a_target_beyond_a_fold() {
    let rod = softrod::Rod::new(
        0.393_793_428_715_491_7,
        softrod::Section::tapered_circular(0.007_978_000_145_928_25, 0.007_598_580_664_849_234)
            .unwrap(),
        softrod::LinearElastic::new(169_771.687_920_789_85, 0.5).unwrap(),
    )
    .unwrap()
    .with_shear_coefficient(0.9)
    .unwrap();
    let (x, y) = (0.005_457_709_104_149_448, -0.002_676_939_545_717_354);
    let tendons = vec![
        softrod::Tendon::constant([x, y], None).unwrap(),
        softrod::Tendon::constant([-x, -y], None).unwrap(),
    ];
    let model = Arc::new(RobotModel::new(rod, tendons, vec![], Loads::default()).unwrap());
    let truth = [0.0, 5.650_332_047_526_689];
    let so = SolveOptions::default();
    // (Under the mesh control, as the forward solve in Python: 4.4 turns need a finer mesh.)
    let tip =
        softrod::cosserat::mesh::solve_at_output(&model, &Actuation::tensions(&truth), &so, &[])
            .unwrap()
            .tip_position();
    let target = Target::tip(Vector3::from(tip));
    let one = inverse_statics(&model, &target, &InverseOptions::default(), &so, None);
    assert!(
        matches!(one, Err(Error::TargetUnreachable { .. })),
        "{one:?}"
    );
    for starts in [
        softrod::Starts::Spread(16),
        softrod::Starts::Given(vec![vec![1.0, 1.0], vec![0.0, 6.0]]),
    ] {
        let opts = InverseOptions {
            starts: starts.clone(),
            ..InverseOptions::default()
        };
        let (inv, sol) = inverse_statics(&model, &target, &opts, &so, None).unwrap();
        assert!(inv.converged && inv.start > 0, "{starts:?}: {}", inv.start);
        for (a, b) in inv.tensions().iter().zip(truth) {
            assert!((a - b).abs() <= 1e-6 * b.max(1.0), "{starts:?}: {a} vs {b}");
        }
        let back = Vector3::from(sol.tip_position());
        assert!((back - Vector3::from(tip)).norm() <= 1e-9);
    }
}

/// A forward model that forgets ([`Forward::forget`], as before each start of a path's first
/// target) evaluates as a new one, bit for bit: a loaded robot's forward solves are
/// warm-started from the last, so an earlier start would otherwise leave its equilibrium to
/// the next.
#[test]
fn a_forward_model_that_forgets_evaluates_as_a_new_one() {
    let model = niti_under_gravity_and_tip_load();
    let o = SolveOptions::default();
    let (far, near) = (
        [0.0, 2.5, 0.0, 3.0, 0.0, 2.0],
        [1.4, 0.0, 0.5, 0.0, 0.7, 0.0],
    );
    let mut fresh = CosseratForward::new(&model, &o, None).unwrap();
    let want = fresh.evaluate(&near, true).unwrap();
    let mut used = CosseratForward::new(&model, &o, None).unwrap();
    used.evaluate(&far, true).unwrap();
    let warm = used.evaluate(&near, true).unwrap();
    used.evaluate(&far, true).unwrap();
    used.forget();
    let got = used.evaluate(&near, true).unwrap();
    println!(
        "tip from the far equilibrium: {:e} m from a new model's",
        (warm.positions[0] - want.positions[0]).norm()
    );
    assert_eq!(got.positions, want.positions);
    assert_eq!(got.jacobian, want.jacobian);
}
