//! Exact parameter sensitivities of the planar arm against central differences of the same
//! discrete march, and the solution against `solve_planar`.
#![allow(clippy::unwrap_used)]

use softrod::{
    planar_sensitivities, solve_planar, uniform_samples, PlanarCableArm, PlanarMethod,
    PlanarParameter,
};

fn arm_with(base: &PlanarCableArm, p: PlanarParameter, v: f64) -> PlanarCableArm {
    let (mut l, mut r0, mut rl, mut a, mut e) = (
        base.length(),
        base.base_radius(),
        base.tip_radius(),
        base.offset_ratio(),
        base.youngs_modulus(),
    );
    match p {
        PlanarParameter::YoungsModulus => e = v,
        PlanarParameter::OffsetRatio => a = v,
        PlanarParameter::BaseRadius => r0 = v,
        PlanarParameter::TipRadius => rl = v,
        PlanarParameter::Tension => {}
    }
    let anchor = (base.anchor() < base.length()).then_some(base.anchor());
    l = l.max(anchor.unwrap_or(0.0));
    PlanarCableArm::new(l, r0, rl, a, e, anchor).unwrap()
}

fn value(base: &PlanarCableArm, t: f64, p: PlanarParameter) -> f64 {
    match p {
        PlanarParameter::YoungsModulus => base.youngs_modulus(),
        PlanarParameter::OffsetRatio => base.offset_ratio(),
        PlanarParameter::BaseRadius => base.base_radius(),
        PlanarParameter::TipRadius => base.tip_radius(),
        PlanarParameter::Tension => t,
    }
}

fn check(arm: &PlanarCableArm, t: f64) {
    let s = uniform_samples(arm.length(), 41).unwrap();
    let sens = planar_sensitivities(arm, t, &s).unwrap();
    // The solution is the planar solver's (both ~1e-10 L from the exact backbone).
    let sol = solve_planar(arm, t, &s, PlanarMethod::ClosedForm).unwrap();
    for i in 0..s.len() {
        assert!((sens.x[i] - sol.x[i]).abs() < 1e-10 * arm.length());
        assert!((sens.y[i] - sol.y[i]).abs() < 1e-10 * arm.length());
        assert!((sens.angle[i] - sol.angle[i]).abs() < 1e-9);
    }
    for (j, &p) in PlanarParameter::ALL.iter().enumerate() {
        let v = value(arm, t, p);
        let h = 1e-5 * v;
        let eval = |dv: f64| {
            let (a2, t2) = if p == PlanarParameter::Tension {
                (*arm, t + dv)
            } else {
                (arm_with(arm, p, v + dv), t)
            };
            planar_sensitivities(&a2, t2, &s).unwrap()
        };
        let (plus, minus) = (eval(h), eval(-h));
        let n = s.len();
        type Field<'a> = (&'a [f64], &'a [f64], &'a [f64]);
        let fields: [Field<'_>; 4] = [
            (&sens.d_x, &plus.x, &minus.x),
            (&sens.d_y, &plus.y, &minus.y),
            (&sens.d_angle, &plus.angle, &minus.angle),
            (&sens.d_arc, &plus.arc, &minus.arc),
        ];
        for (field, (d, pl, mi)) in fields.iter().enumerate() {
            // Relative to the largest column entry (the shape's scale of that sensitivity).
            let scale = (0..n).map(|i| d[i * 5 + j].abs()).fold(0.0, f64::max);
            if scale == 0.0 {
                continue;
            }
            for i in 0..n {
                let fd = (pl[i] - mi[i]) / (2.0 * h);
                let err = (d[i * 5 + j] - fd).abs() / scale;
                assert!(
                    err < 1e-6,
                    "{:?} field {field} sample {i}: exact {} vs central {fd} (rel {err:e})",
                    p,
                    d[i * 5 + j]
                );
            }
        }
    }
}

#[test]
fn sensitivities_match_central_differences_on_the_published_arm() {
    let arm = PlanarCableArm::published_arm();
    for t in [0.2, 1.0, 3.0] {
        check(&arm, t);
    }
}

#[test]
fn sensitivities_with_an_inner_anchor_and_reverse_taper() {
    let arm = PlanarCableArm::new(0.2, 0.006, 0.01, 0.4, 2e5, Some(0.13)).unwrap();
    check(&arm, 0.8);
}

#[test]
fn modulus_and_tension_scale_together_leave_the_shape_unchanged() {
    // k and q depend on E and T only through T / E: E dk/dE + T dk/dT = 0 exactly, so
    // E d/dE + T d/dT of every backbone quantity vanishes (the identity calibration relies on
    // to flag E together with a tension scale as not identifiable).
    let arm = PlanarCableArm::published_arm();
    let s = uniform_samples(arm.length(), 21).unwrap();
    let t = 1.5;
    let sens = planar_sensitivities(&arm, t, &s).unwrap();
    let e = arm.youngs_modulus();
    for i in 0..s.len() {
        for d in [&sens.d_x, &sens.d_y, &sens.d_angle] {
            let comb = e * d[i * 5] + t * d[i * 5 + 2];
            assert!(comb.abs() < 1e-12, "{comb}");
        }
    }
}
