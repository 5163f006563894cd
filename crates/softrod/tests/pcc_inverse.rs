//! The closed-form PCC inverse statics (`pcc_inverse_statics`, unloaded robot, tip target)
//! against two independent oracles: the generic SQP of `solve_inverse` on the PCC forward model
//! (directional differences of the Newton-solved equilibrium's Jacobian for the curvature) and
//! the first-order optimality (KKT) conditions with the actuation Jacobian of
//! `pcc/sensitivity.rs`; every target reached is checked by an independent forward solve.
#![allow(clippy::unwrap_used)]

use softrod::nalgebra::{DMatrix, DVector, Vector3};
use softrod::pcc::statics::{solve_pcc_statics, PccLoads, PccRobot, PccSolveOptions};
use softrod::pcc::{pcc_actuation_jacobian, ElasticSegment, PccChambers, PccTendons};
use softrod::{
    pcc_inverse_statics, solve_inverse, InverseOptions, InverseSolution, InverseWarmStart,
    PccForward, Target,
};

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

/// The two-segment NiTi robot as two constant-curvature segments, three tendons each.
fn niti(extensible: bool) -> PccRobot {
    let ang = [90.0f64, -30.0, 210.0].map(f64::to_radians);
    let tendons = PccTendons::new(&[0.01; 3], &ang).unwrap();
    let seg = || ElasticSegment::solid_circle(0.2, 0.7e-3, 54e9, extensible).unwrap();
    PccRobot::new(vec![seg(), seg()])
        .unwrap()
        .with_segment_tendons(0, &tendons)
        .unwrap()
        .with_segment_tendons(1, &tendons)
        .unwrap()
}

/// Each segment pulled by at most two of its tendons (N).
fn admissible(g: &mut Lcg, max: f64) -> Vec<f64> {
    let mut t = vec![0.0; 6];
    for seg in 0..2 {
        let off = (g.next() * 3.0) as usize % 3;
        t[3 * seg + off] = g.next() * max;
        t[3 * seg + (off + 1) % 3] = g.next() * max;
    }
    t
}

fn tip_of(robot: &PccRobot, tensions: &[f64], pressures: &[f64]) -> Vector3<f64> {
    let loads = PccLoads {
        tensions: tensions.to_vec(),
        pressures: pressures.to_vec(),
        ..Default::default()
    };
    let t = solve_pcc_statics(robot, &loads, &PccSolveOptions::default())
        .unwrap()
        .tip_pose;
    Vector3::new(t[(0, 3)], t[(1, 3)], t[(2, 3)])
}

/// KKT of `min ½ |a - c|²_W` s.t. `p(a) = target`, `lo <= a <= hi` with the Jacobian of
/// `pcc_actuation_jacobian`: `W (a - c) = Jᵀ λ` on the free actuators (λ by least squares),
/// and the gradient pointing out of the box at the bounds.
fn check_kkt(robot: &PccRobot, inv: &InverseSolution, w: &[f64], hi: f64) {
    let nt = robot.n_tendons();
    let loads = PccLoads {
        tensions: inv.actuation[..nt].to_vec(),
        pressures: inv.actuation[nt..].to_vec(),
        ..Default::default()
    };
    let sol = solve_pcc_statics(robot, &loads, &PccSolveOptions::default()).unwrap();
    let j = pcc_actuation_jacobian(robot, &loads, &sol).unwrap();
    let jp = j.rows(0, 3).into_owned();
    let a = &inv.actuation;
    let n = a.len();
    let free: Vec<usize> = (0..n)
        .filter(|&i| a[i] > 1e-12 && a[i] < hi - 1e-12)
        .collect();
    let jf = DMatrix::from_fn(3, free.len(), |r, c| jp[(r, free[c])]);
    let gf = DVector::from_fn(free.len(), |r, _| w[free[r]] * a[free[r]]);
    let lambda = (&jf * jf.transpose()).lu().solve(&(&jf * &gf)).unwrap();
    let scale = 1.0 + gf.amax();
    for i in 0..n {
        let r = w[i] * a[i] - jp.column(i).dot(&lambda);
        if free.contains(&i) {
            assert!(r.abs() <= 1e-7 * scale, "stationarity {i}: {r:e}");
        } else if a[i] <= 1e-12 {
            assert!(r >= -1e-7 * scale, "lower bound {i}: {r:e}");
        } else {
            assert!(r <= 1e-7 * scale, "upper bound {i}: {r:e}");
        }
    }
}

fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
    a.iter()
        .zip(b)
        .all(|(x, y)| (x - y).abs() <= tol * (1.0 + x.abs().max(y.abs())))
}

#[test]
fn closed_form_inverse_is_the_generic_one_and_meets_the_kkt_conditions() {
    for extensible in [true, false] {
        let robot = niti(extensible);
        let o = PccSolveOptions::default();
        let io = InverseOptions::default();
        let mut g = Lcg(21);
        let mut warm: Option<InverseWarmStart> = None;
        for k in 0..60 {
            let target = Target::tip(tip_of(&robot, &admissible(&mut g, 3.0), &[]));
            let fast =
                pcc_inverse_statics(&robot, &PccLoads::default(), &target, &io, &o, None).unwrap();
            let mut fwd = PccForward::new(&robot, &PccLoads::default(), &o);
            let slow = solve_inverse(&mut fwd, &target, &io, None).unwrap();
            assert!(fast.converged && slow.converged);
            assert!(
                close(&fast.actuation, &slow.actuation, 1e-8),
                "{k}: {fast:?} {slow:?}"
            );
            let p = tip_of(&robot, &fast.actuation, &[]);
            assert!((p - target.points[0]).norm() <= 1e-9);
            assert!(fast.actuation.iter().all(|&v| v >= 0.0));
            check_kkt(&robot, &fast, &[1.0; 6], f64::INFINITY);
            // Warm-started along a path of 1 mm moves.
            let moved = Target::tip(target.points[0] + Vector3::new(1e-3, 0.0, 0.0));
            let w = warm.take().unwrap_or_else(|| InverseWarmStart::from(&fast));
            let wf = pcc_inverse_statics(&robot, &PccLoads::default(), &moved, &io, &o, Some(&w));
            let mut fwd = PccForward::new(&robot, &PccLoads::default(), &o);
            let ws = solve_inverse(&mut fwd, &moved, &io, Some(&w));
            match (wf, ws) {
                (Ok(a), Ok(b)) => {
                    assert!(close(&a.actuation, &b.actuation, 1e-8), "warm {k}");
                    let p = tip_of(&robot, &a.actuation, &[]);
                    assert!((p - moved.points[0]).norm() <= 1e-9);
                    warm = Some(InverseWarmStart::from(&a));
                }
                (Err(_), Err(_)) => {}
                (a, b) => panic!("warm {k}: {a:?} vs {b:?}"),
            }
        }
    }
}

#[test]
fn bounds_weights_and_reference_match_the_generic_inverse_and_chambers_take_it() {
    let robot = niti(true);
    let o = PccSolveOptions::default();
    let mut g = Lcg(5);
    for k in 0..20 {
        let target = Target::tip(tip_of(&robot, &admissible(&mut g, 2.0), &[]));
        let w: Vec<f64> = (0..6).map(|_| 0.5 + g.next()).collect();
        let io = InverseOptions {
            weights: Some(w.clone()),
            tension_bounds: (0.0, 2.5),
            reference: (k % 2 == 1).then(|| vec![0.1; 6]),
            throw: false,
            ..Default::default()
        };
        let fast =
            pcc_inverse_statics(&robot, &PccLoads::default(), &target, &io, &o, None).unwrap();
        let mut fwd = PccForward::new(&robot, &PccLoads::default(), &o);
        let slow = solve_inverse(&mut fwd, &target, &io, None).unwrap();
        assert_eq!(fast.converged, slow.converged, "{k}");
        assert!(
            close(&fast.actuation, &slow.actuation, 1e-8),
            "{k}: {fast:?} {slow:?}"
        );
        assert!(fast.actuation.iter().all(|&v| (0.0..=2.5).contains(&v)));
        if fast.converged && io.reference.is_none() {
            check_kkt(&robot, &fast, &w, 2.5);
        }
    }
    // A pneumatic segment under a tendon segment.
    let body = ElasticSegment::solid_circle(0.15, 4e-3, 2e6, true).unwrap();
    let chambers = PccChambers::equally_spaced(3, 2e-5, 2.5e-3, 0.0).unwrap();
    let tendons = PccTendons::equally_spaced(3, 3e-3, 0.3).unwrap();
    let robot = PccRobot::new(vec![body, body])
        .unwrap()
        .with_chambers(0, chambers)
        .unwrap()
        .with_segment_tendons(1, &tendons)
        .unwrap();
    for _ in 0..10 {
        let p = [g.next() * 2e4, g.next() * 2e4, 0.0];
        let t = [g.next() * 0.3, 0.0, g.next() * 0.3];
        let target = Target::tip(tip_of(&robot, &t, &p));
        let io = InverseOptions::default();
        let fast =
            pcc_inverse_statics(&robot, &PccLoads::default(), &target, &io, &o, None).unwrap();
        let mut fwd = PccForward::new(&robot, &PccLoads::default(), &o);
        let slow = solve_inverse(&mut fwd, &target, &io, None).unwrap();
        // With chambers the generic iteration answers.
        assert_eq!(fast, slow);
        assert!(fast.converged);
        let (tf, pf) = fast.actuation.split_at(3);
        assert!((tip_of(&robot, tf, pf) - target.points[0]).norm() <= 1e-9);
    }
}

#[test]
fn unreachable_and_loaded_targets_take_the_generic_path() {
    let robot = niti(true);
    let o = PccSolveOptions::default();
    let io = InverseOptions {
        throw: false,
        ..Default::default()
    };
    let far = Target::tip(Vector3::new(0.5, 0.5, 0.0));
    let inv = pcc_inverse_statics(&robot, &PccLoads::default(), &far, &io, &o, None).unwrap();
    assert!(!inv.converged && inv.position_error > 0.1);
    let thrown = pcc_inverse_statics(
        &robot,
        &PccLoads::default(),
        &far,
        &InverseOptions::default(),
        &o,
        None,
    );
    assert!(matches!(
        thrown,
        Err(softrod::Error::TargetUnreachable { .. })
    ));
    let loads = PccLoads {
        tip_force: Vector3::new(0.0, 0.05, -0.1),
        ..Default::default()
    };
    let t = [1.0, 0.5, 0.0, 0.0, 0.3, 0.0];
    let tip = solve_pcc_statics(
        &robot,
        &PccLoads {
            tensions: t.to_vec(),
            ..loads.clone()
        },
        &o,
    )
    .unwrap()
    .tip_pose;
    let target = Target::tip(Vector3::new(tip[(0, 3)], tip[(1, 3)], tip[(2, 3)]));
    let fast = pcc_inverse_statics(&robot, &loads, &target, &io, &o, None).unwrap();
    let mut fwd = PccForward::new(&robot, &loads, &o);
    let slow = solve_inverse(&mut fwd, &target, &io, None).unwrap();
    assert_eq!(fast, slow);
}
