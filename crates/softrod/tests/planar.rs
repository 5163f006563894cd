//! Oracle tests of the planar cable-arm paper's planar model.
#![allow(clippy::unwrap_used)]

use softrod::integrate::AdaptiveOptions;
use softrod::{
    solve_planar, solve_planar_many, uniform_samples, Error, PlanarCableArm, PlanarMethod,
};

const TENSIONS: [f64; 8] = [0.1, 0.25, 0.5, 1.0, 2.0, 3.0, 4.0, 5.0];

fn ode(rtol: f64, atol: f64) -> PlanarMethod {
    PlanarMethod::Ode(AdaptiveOptions {
        rtol,
        atol,
        ..Default::default()
    })
}

/// Independent reference: classical RK4 on (theta, x, y) with the closed-form profile,
/// `n` uniform steps over the loaded part, straight beyond the anchor.
fn rk4_reference(arm: &PlanarCableArm, t: f64, s_out: f64, n: usize) -> (f64, f64, f64) {
    let end = s_out.min(arm.anchor());
    let h = end / n as f64;
    let rhs = |s: f64, th: f64| {
        let (k, q) = arm.closed_form(s, t);
        [(1.0 + q) * k, (1.0 + q) * th.cos(), (1.0 + q) * th.sin()]
    };
    let (mut th, mut x, mut y) = (0.0f64, 0.0f64, 0.0f64);
    for i in 0..n {
        let s = i as f64 * h;
        let k1 = rhs(s, th);
        let k2 = rhs(s + h / 2.0, th + h / 2.0 * k1[0]);
        let k3 = rhs(s + h / 2.0, th + h / 2.0 * k2[0]);
        let k4 = rhs(s + h, th + h * k3[0]);
        th += h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]);
        x += h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]);
        y += h / 6.0 * (k1[2] + 2.0 * k2[2] + 2.0 * k3[2] + k4[2]);
    }
    if s_out > end {
        x += (s_out - end) * th.cos();
        y += (s_out - end) * th.sin();
    }
    (th, x, y)
}

#[test]
fn ode_path_matches_closed_form_to_1e_8() {
    let arm = PlanarCableArm::published_arm();
    let s = uniform_samples(arm.length(), 201).unwrap();
    for t in TENSIONS {
        let cf = solve_planar(&arm, t, &s, PlanarMethod::ClosedForm).unwrap();
        let od = solve_planar(&arm, t, &s, ode(1e-10, 1e-12)).unwrap();
        let kmax = cf.curvature.iter().fold(0.0f64, |m, k| m.max(k.abs()));
        let dk = cf
            .curvature
            .iter()
            .zip(&od.curvature)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(dk / kmax <= 1e-8, "T = {t}: max|dk|/max k = {}", dk / kmax);
        // The strain follows from k; the backbones agree to the same order.
        let dx = (cf.tip[0] - od.tip[0]).hypot(cf.tip[1] - od.tip[1]);
        assert!(dx < 1e-9, "T = {t}: tip difference {dx} m");
    }
}

#[test]
fn published_ode_is_the_derivative_of_the_closed_form() {
    // Central difference of the closed form vs the printed right-hand side.
    let arm = PlanarCableArm::published_arm();
    for t in TENSIONS {
        for i in 1..20 {
            let s = arm.length() * i as f64 / 20.0;
            let h = 1e-6;
            let fd = (arm.closed_form(s + h, t).0 - arm.closed_form(s - h, t).0) / (2.0 * h);
            let k = arm.closed_form(s, t).0;
            let rhs = arm.curvature_rate(s, k, t);
            assert!(
                (fd - rhs).abs() <= 1e-7 * rhs.abs().max(1.0),
                "{fd} vs {rhs}"
            );
        }
        // Corrected final value R(L)^4 equals the closed form at the anchor.
        let kl = arm.closed_form(arm.length(), t).0;
        assert!((arm.final_value(t) - kl).abs() <= 1e-14 * kl);
        // Strain: closed form q = -T/(4D) equals the paper's T(aRk - 1)/(E pi R^2).
        let (k, q) = arm.closed_form(0.1, t);
        assert!((arm.strain(0.1, k, t) - q).abs() <= 1e-14 * q.abs());
    }
}

#[test]
fn zero_tension_is_straight_with_length_l() {
    let arm = PlanarCableArm::published_arm();
    let s = uniform_samples(arm.length(), 11).unwrap();
    for m in [PlanarMethod::ClosedForm, ode(1e-8, 1e-10)] {
        let sol = solve_planar(&arm, 0.0, &s, m).unwrap();
        for i in 0..s.len() {
            assert_eq!(sol.curvature[i], 0.0);
            assert_eq!(sol.strain[i], 0.0);
            assert!((sol.x[i] - s[i]).abs() < 1e-15 && sol.y[i] == 0.0);
        }
        assert!((sol.tip[0] - arm.length()).abs() < 1e-15 && sol.tip[1] == 0.0);
    }
}

#[test]
fn untapered_arm_is_an_exact_circular_arc() {
    for anchor in [None, Some(0.2)] {
        let arm = PlanarCableArm::new(0.3, 0.01, 0.01, 0.4, 200e3, anchor).unwrap();
        let s = uniform_samples(arm.length(), 7).unwrap();
        for t in [0.3, 2.0, 8.0] {
            let (k, q) = arm.closed_form(0.0, t);
            let kap = (1.0 + q) * k; // curvature per undeformed length
            let sa = arm.anchor();
            let th = kap * sa;
            let (ax, ay) = (
                (1.0 + q) * th.sin() / kap,
                (1.0 + q) * (1.0 - th.cos()) / kap,
            );
            let rest = arm.length() - sa;
            let tip = (ax + rest * th.cos(), ay + rest * th.sin());
            for m in [PlanarMethod::ClosedForm, ode(1e-12, 1e-14)] {
                let sol = solve_planar(&arm, t, &s, m).unwrap();
                let tol = if m == PlanarMethod::ClosedForm {
                    1e-12
                } else {
                    1e-9
                };
                assert!(
                    (sol.tip[0] - tip.0).abs() < tol && (sol.tip[1] - tip.1).abs() < tol,
                    "T = {t}, anchor {anchor:?}: {:?} vs {tip:?}",
                    sol.tip
                );
                assert!((sol.tip_angle - th).abs() < tol * 10.0);
                // Every sample on the arc (or on the straight continuation).
                for (i, &si) in s.iter().enumerate() {
                    let (ex, ey) = if si <= sa {
                        (
                            (1.0 + q) * (kap * si).sin() / kap,
                            (1.0 + q) * (1.0 - (kap * si).cos()) / kap,
                        )
                    } else {
                        (ax + (si - sa) * th.cos(), ay + (si - sa) * th.sin())
                    };
                    assert!((sol.x[i] - ex).abs() < tol && (sol.y[i] - ey).abs() < tol);
                }
            }
        }
    }
}

#[test]
fn backbone_is_accurate_to_1e_9_m_at_201_samples() {
    let arm = PlanarCableArm::published_arm();
    let s = uniform_samples(arm.length(), 201).unwrap();
    for t in TENSIONS {
        let sol = solve_planar(&arm, t, &s, PlanarMethod::ClosedForm).unwrap();
        // The RK4 reference is itself converged: halving its step changes it by < 1e-13 m.
        let r1 = rk4_reference(&arm, t, arm.length(), 1 << 14);
        let r2 = rk4_reference(&arm, t, arm.length(), 1 << 15);
        assert!((r1.1 - r2.1).abs() < 1e-13 && (r1.2 - r2.2).abs() < 1e-13);
        let err = (sol.tip[0] - r2.1).hypot(sol.tip[1] - r2.2);
        assert!(err < 1e-9, "T = {t}: tip error {err:e} m");
        assert!((sol.tip_angle - r2.0).abs() < 1e-10);
        // Interior samples too.
        for i in [50, 100, 150] {
            let r = rk4_reference(&arm, t, s[i], 1 << 13);
            assert!((sol.x[i] - r.1).hypot(sol.y[i] - r.2) < 1e-9);
        }
    }
}

#[test]
fn coarse_sampling_does_not_lose_accuracy() {
    // The panels are set by the curvature and the taper, not by the output spacing: with 2,
    // 3 or 11 samples the tip is as accurate as with 201, at low tension (slowly turning,
    // strongly tapered) as at high tension, for both evaluation paths.
    let arm = PlanarCableArm::published_arm();
    for t in [0.001, 0.01, 0.05, 0.1, 0.5, 1.0, 5.0, 20.0] {
        let r = rk4_reference(&arm, t, arm.length(), 1 << 15);
        for n in [2, 3, 11] {
            let s = uniform_samples(arm.length(), n).unwrap();
            let cf = solve_planar(&arm, t, &s, PlanarMethod::ClosedForm).unwrap();
            let err = (cf.tip[0] - r.1).hypot(cf.tip[1] - r.2);
            assert!(
                err < 1e-10,
                "T = {t}, {n} samples: closed-form tip error {err:e} m"
            );
            let od = solve_planar(&arm, t, &s, ode(1e-11, 1e-13)).unwrap();
            let err = (od.tip[0] - r.1).hypot(od.tip[1] - r.2);
            assert!(err < 1e-9, "T = {t}, {n} samples: ODE tip error {err:e} m");
        }
    }
}

#[test]
fn anchor_before_tip_leaves_a_straight_distal_part() {
    let arm = PlanarCableArm::new(0.27, 0.015, 0.0074, 1.0 / 3.0, 110e3, Some(0.18)).unwrap();
    let s = uniform_samples(arm.length(), 28).unwrap();
    let sol = solve_planar(&arm, 2.0, &s, PlanarMethod::ClosedForm).unwrap();
    let r = rk4_reference(&arm, 2.0, arm.length(), 1 << 15);
    assert!((sol.tip[0] - r.1).hypot(sol.tip[1] - r.2) < 1e-9);
    for (i, &si) in s.iter().enumerate() {
        if si > 0.18 {
            assert_eq!(sol.curvature[i], 0.0);
            assert_eq!(sol.angle[i], sol.tip_angle);
        }
    }
    let od = solve_planar(&arm, 2.0, &s, ode(1e-11, 1e-13)).unwrap();
    assert!((od.tip[0] - r.1).hypot(od.tip[1] - r.2) < 1e-9);
}

#[test]
fn scaling_lengths_by_lambda_and_tension_by_lambda_squared_gives_a_similar_shape() {
    let base = PlanarCableArm::published_arm();
    let s = uniform_samples(base.length(), 101).unwrap();
    let a = solve_planar(&base, 1.5, &s, PlanarMethod::ClosedForm).unwrap();
    for lam in [0.1, 3.0] {
        let arm = PlanarCableArm::new(
            lam * base.length(),
            lam * base.base_radius(),
            lam * base.tip_radius(),
            base.offset_ratio(),
            base.youngs_modulus(),
            None,
        )
        .unwrap();
        let ss: Vec<f64> = s.iter().map(|v| v * lam).collect();
        let b = solve_planar(&arm, 1.5 * lam * lam, &ss, PlanarMethod::ClosedForm).unwrap();
        for i in 0..s.len() {
            assert!((b.x[i] - lam * a.x[i]).abs() < 1e-12 * lam);
            assert!((b.y[i] - lam * a.y[i]).abs() < 1e-12 * lam);
            assert!((b.angle[i] - a.angle[i]).abs() < 1e-12);
            assert!((b.strain[i] - a.strain[i]).abs() < 1e-14);
        }
    }
}

#[test]
fn tip_angle_grows_monotonically_with_tension() {
    let arm = PlanarCableArm::published_arm();
    let s = uniform_samples(arm.length(), 2).unwrap();
    let tensions: Vec<f64> = (0..=100).map(|i| 5.0 * i as f64 / 100.0).collect();
    let b = solve_planar_many(&arm, &tensions, &s, PlanarMethod::ClosedForm).unwrap();
    for w in b.tip_angle.windows(2) {
        assert!(w[1] > w[0]);
    }
    // The arm curls toward the cable (+y) and more at the thinner tip.
    let sol = solve_planar(
        &arm,
        2.0,
        &uniform_samples(0.27, 11).unwrap(),
        PlanarMethod::ClosedForm,
    )
    .unwrap();
    assert!(sol.tip[1] > 0.0);
    assert!(sol.curvature.windows(2).all(|w| w[1] > w[0]));
}

#[test]
fn batch_equals_individual_solves() {
    let arm = PlanarCableArm::published_arm();
    let s = uniform_samples(arm.length(), 33).unwrap();
    let tensions: Vec<f64> = (0..300).map(|i| 0.01 * i as f64).collect();
    for m in [PlanarMethod::ClosedForm, ode(1e-8, 1e-10)] {
        let b = solve_planar_many(&arm, &tensions, &s, m).unwrap();
        for (r, &t) in tensions.iter().enumerate().step_by(37) {
            let one = solve_planar(&arm, t, &s, m).unwrap();
            assert_eq!(&b.x[r * 33..(r + 1) * 33], &one.x[..]);
            assert_eq!(&b.curvature[r * 33..(r + 1) * 33], &one.curvature[..]);
            assert_eq!(b.tip[r], one.tip);
        }
    }
}

fn name_of(e: Error) -> String {
    match e {
        Error::InvalidParameter { name, .. } => name,
        other => panic!("expected InvalidParameter, got {other:?}"),
    }
}

#[test]
fn bad_input_names_the_parameter() {
    let ok = (0.27, 0.015, 0.0074, 1.0 / 3.0, 110e3);
    let cases: [(&str, [f64; 6]); 12] = [
        ("length", [0.0, ok.1, ok.2, ok.3, ok.4, f64::NAN]),
        ("length", [f64::NAN, ok.1, ok.2, ok.3, ok.4, f64::NAN]),
        ("base_radius", [ok.0, -1.0, ok.2, ok.3, ok.4, f64::NAN]),
        ("tip_radius", [ok.0, ok.1, 0.0, ok.3, ok.4, f64::NAN]),
        (
            "tip_radius",
            [ok.0, ok.1, f64::INFINITY, ok.3, ok.4, f64::NAN],
        ),
        ("offset_ratio", [ok.0, ok.1, ok.2, 1.0, ok.4, f64::NAN]),
        ("offset_ratio", [ok.0, ok.1, ok.2, -0.1, ok.4, f64::NAN]),
        ("youngs_modulus", [ok.0, ok.1, ok.2, ok.3, 0.0, f64::NAN]),
        ("anchor", [ok.0, ok.1, ok.2, ok.3, ok.4, 0.0]),
        ("anchor", [ok.0, ok.1, ok.2, ok.3, ok.4, 0.3]),
        ("anchor", [ok.0, ok.1, ok.2, ok.3, ok.4, f64::INFINITY]),
        ("youngs_modulus", [ok.0, ok.1, ok.2, ok.3, -5.0, f64::NAN]),
    ];
    for (name, p) in cases {
        let anchor = if p[5].is_nan() { None } else { Some(p[5]) };
        let e = PlanarCableArm::new(p[0], p[1], p[2], p[3], p[4], anchor).unwrap_err();
        assert_eq!(name_of(e), name);
    }
    let arm = PlanarCableArm::published_arm();
    let s = uniform_samples(arm.length(), 5).unwrap();
    for t in [-1.0, f64::NAN, f64::INFINITY, 1e6] {
        let e = solve_planar(&arm, t, &s, PlanarMethod::ClosedForm).unwrap_err();
        assert_eq!(name_of(e), "tension");
    }
    assert_eq!(name_of(uniform_samples(1.0, 1).unwrap_err()), "n_points");
    let e = solve_planar(&arm, 1.0, &[0.0, 0.5], PlanarMethod::ClosedForm).unwrap_err();
    assert_eq!(name_of(e), "s[1]");
    let e = solve_planar_many(&arm, &[1.0, -2.0], &s, PlanarMethod::ClosedForm).unwrap_err();
    assert_eq!(name_of(e), "tensions[1]");
    let e = solve_planar(&arm, 1.0, &s, ode(-1.0, 1e-9)).unwrap_err();
    assert_eq!(name_of(e), "rtol");
}

/// An absolute tolerance of the ODE's curvature whose integral `atol L` would turn the tip by
/// more than 1e-3 rad is refused, naming `atol` (1 1/m moved the tip 18 mm at 2 N); at the
/// bound the tip is within `atol L²` of the closed form.
#[test]
fn an_ode_absolute_tolerance_that_turns_the_tip_is_refused() {
    let arm = PlanarCableArm::published_arm();
    let s = uniform_samples(arm.length(), 5).unwrap();
    for atol in [1.0, 1e308] {
        let e = solve_planar(&arm, 2.0, &s, ode(1e-10, atol)).unwrap_err();
        assert_eq!(name_of(e), "atol");
    }
    let bound = softrod::planar::ODE_STRAIN_ERROR / arm.length();
    let at = solve_planar(&arm, 2.0, &s, ode(1e-10, bound)).unwrap();
    let exact = solve_planar(&arm, 2.0, &s, PlanarMethod::ClosedForm).unwrap();
    let d = ((at.tip[0] - exact.tip[0]).powi(2) + (at.tip[1] - exact.tip[1]).powi(2)).sqrt();
    println!("at the bound {bound:e} 1/m: tip {d:e} m from the closed form");
    assert!(d <= bound * arm.length().powi(2), "{d:e}");
}

#[test]
fn ode_non_convergence_reports_iterations() {
    let arm = PlanarCableArm::published_arm();
    let s = uniform_samples(arm.length(), 5).unwrap();
    let m = PlanarMethod::Ode(AdaptiveOptions {
        rtol: 1e-10,
        atol: 1e-12,
        max_steps: 10,
    });
    match solve_planar(&arm, 1.0, &s, m) {
        Err(Error::NotConverged { iterations, .. }) => assert_eq!(iterations, 10),
        other => panic!("{other:?}"),
    }
}
