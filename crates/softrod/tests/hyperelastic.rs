//! Uniaxial material laws and their fitting, against oracles that do not come from the code:
//! closed forms, finite differences, reductions between models, synthetic data with known
//! parameters, and the measured silicone curves (when available).
#![allow(clippy::unwrap_used, clippy::too_many_lines)]

use std::path::PathBuf;

use softrod::{
    fit_stats, fit_uniaxial, Error, FitOptions, Hookean, Linearised, ModelKind, MooneyRivlin,
    NeoHookean, Ogden, Silicone, StrainMeasure, StressMeasure, UniaxialData, UniaxialLaw,
    UniaxialModel, Yeoh,
};

/// Stretches spanning compression and tension, `[0.5, 3]`.
fn stretches() -> Vec<f64> {
    (0..=250).map(|i| 0.5 + 2.5 * i as f64 / 250.0).collect()
}

fn rel_err(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
}

fn invalid_name(err: Error) -> String {
    match err {
        Error::InvalidParameter { name, .. } => name,
        other => panic!("expected InvalidParameter, got {other:?}"),
    }
}

/// A representative set of every law, all stable on `[0.5, 3]`.
fn laws() -> Vec<UniaxialModel> {
    vec![
        Hookean::new(1.2e5).unwrap().into(),
        Linearised::new(9.0e4, 1.0).unwrap().into(),
        NeoHookean::new(4.0e4).unwrap().into(),
        MooneyRivlin::new(3.0e4, 8.0e3).unwrap().into(),
        Yeoh::new(2.0e4, -1.5e3, 1.2e2).unwrap().into(),
        Yeoh::new(2.0e4, 3.0e3, 0.0).unwrap().into(),
        Ogden::new(&[3.0e4, 2.0e3], &[1.8, 6.0]).unwrap().into(),
        Ogden::new(&[2.0e4, 5.0e3, 1.0e3], &[2.5, -2.0, 0.05])
            .unwrap()
            .into(),
    ]
}

// ---------------------------------------------------------------- closed forms and reductions

#[test]
fn neo_hookean_matches_closed_form() {
    let mu = 3.7e4;
    let nh = NeoHookean::new(mu).unwrap();
    for l in stretches() {
        let sigma = mu * (l * l - 1.0 / l);
        assert!((nh.true_stress(l).unwrap() - sigma).abs() <= 1e-12 * mu * (1.0 + l * l));
        let p = mu * (l - 1.0 / (l * l));
        assert!((nh.nominal_stress(l).unwrap() - p).abs() <= 1e-12 * mu * (1.0 + l * l));
    }
    assert!(rel_err(nh.tangent_modulus(0.0).unwrap(), 3.0 * mu) < 1e-15);
    assert!(rel_err(nh.small_strain_modulus(), 3.0 * mu) < 1e-15);
}

#[test]
fn small_strain_modulus_of_invariant_models() {
    let (c10, c01) = (2.1e4, 4.0e3);
    let mr = MooneyRivlin::new(c10, c01).unwrap();
    assert!(rel_err(mr.tangent_modulus(0.0).unwrap(), 6.0 * (c10 + c01)) < 1e-15);
    assert!(rel_err(mr.small_strain_modulus(), 6.0 * (c10 + c01)) < 1e-15);
    let yeoh = Yeoh::new(c10, -300.0, 20.0).unwrap();
    assert!(rel_err(yeoh.tangent_modulus(0.0).unwrap(), 6.0 * c10) < 1e-15);
    let ogden = Ogden::new(&[1.0e4, 3.0e3], &[2.0, -1.5]).unwrap();
    assert!(rel_err(ogden.tangent_modulus(0.0).unwrap(), 3.0 * 1.3e4) < 1e-14);
    // Every law: the analytic small-strain modulus is the tangent at ε = 0.
    for law in laws() {
        let e0 = law.small_strain_modulus();
        assert!(
            rel_err(law.tangent_modulus(0.0).unwrap(), e0) < 1e-14,
            "{law}"
        );
    }
}

#[test]
fn reductions_between_models() {
    let mu = 5.0e4;
    let nh = NeoHookean::new(mu).unwrap();
    let mr = MooneyRivlin::new(mu / 2.0, 0.0).unwrap();
    let yeoh = Yeoh::new(mu / 2.0, 0.0, 0.0).unwrap();
    let ogden_nh = Ogden::new(&[mu], &[2.0]).unwrap();
    let (c10, c01) = (2.0e4, 6.0e3);
    let mr2 = MooneyRivlin::new(c10, c01).unwrap();
    let ogden_mr = Ogden::new(&[2.0 * c10, 2.0 * c01], &[2.0, -2.0]).unwrap();
    for l in stretches() {
        let s = nh.true_stress(l).unwrap();
        let scale = mu * (1.0 + l * l);
        for other in [
            mr.true_stress(l),
            yeoh.true_stress(l),
            ogden_nh.true_stress(l),
        ] {
            assert!((other.unwrap() - s).abs() <= 1e-13 * scale);
        }
        let e = nh.tangent_modulus(l - 1.0).unwrap();
        for other in [mr.tangent_modulus(l - 1.0), yeoh.tangent_modulus(l - 1.0)] {
            assert!((other.unwrap() - e).abs() <= 1e-13 * scale);
        }
        let a = mr2.true_stress(l).unwrap();
        let b = ogden_mr.true_stress(l).unwrap();
        assert!(
            (a - b).abs() <= 1e-13 * 6.0 * (c10 + c01) * (1.0 + l * l),
            "λ = {l}"
        );
    }
}

#[test]
fn nominal_and_true_stress_are_related_by_the_stretch() {
    for law in laws() {
        for l in stretches() {
            let p = law.nominal_stress(l).unwrap();
            let s = law.true_stress(l).unwrap();
            assert!((s - l * p).abs() <= 1e-13 * (s.abs() + law.small_strain_modulus()));
        }
    }
}

// ---------------------------------------------------------------- tangents vs finite differences

/// Fourth-order central difference `f'(x)` with step `h`.
fn central_difference(f: impl Fn(f64) -> f64, x: f64, h: f64) -> f64 {
    (f(x - 2.0 * h) - 8.0 * f(x - h) + 8.0 * f(x + h) - f(x + 2.0 * h)) / (12.0 * h)
}

/// `|a − b|` relative to `|a|`, or to `1e-3 E0` where the tangent itself vanishes (the
/// Hookean `dσ/dε = E (2λ − 1)` at `λ = 1/2`).
fn tangent_err(exact: f64, fd: f64, e0: f64) -> f64 {
    (exact - fd).abs() / exact.abs().max(1e-3 * e0)
}

#[test]
fn analytic_tangents_match_central_differences() {
    let h = 1e-3;
    for law in laws() {
        let e0 = law.small_strain_modulus();
        for l in stretches() {
            // dσ/dε at ε = λ − 1.
            let fd = central_difference(|x| law.true_stress(x).unwrap(), l, h);
            let exact = law.tangent_modulus(l - 1.0).unwrap();
            let err = tangent_err(exact, fd, e0);
            assert!(err < 1e-8, "{law}: dσ/dε at λ = {l}: {exact} vs {fd}");
            // dP/dλ.
            let fd = central_difference(|x| law.nominal_stress(x).unwrap(), l, h);
            let exact = law.nominal_tangent(l).unwrap();
            let err = tangent_err(exact, fd, e0);
            assert!(err < 1e-8, "{law}: dP/dλ at λ = {l}: {exact} vs {fd}");
            // Axial stiffness is A0 dP/dλ.
            let area = 2.5e-4;
            let k = law.axial_stiffness(area, l).unwrap();
            assert!(rel_err(k, area * exact) < 1e-15);
        }
    }
}

#[test]
fn ogden_is_smooth_through_its_series_switch() {
    // |α ln λ| crosses the series/closed-form switch (0.1) near λ = e^(0.1/α).
    let law = Ogden::new(&[1.0e4], &[0.5]).unwrap();
    let l_switch = (0.1_f64 / 0.5).exp();
    let below = law.true_stress(l_switch * (1.0 - 1e-12)).unwrap();
    let above = law.true_stress(l_switch * (1.0 + 1e-12)).unwrap();
    assert!(rel_err(below, above) < 1e-10);
}

// ---------------------------------------------------------------- inverse map, stability

#[test]
fn force_to_stretch_inverts_the_law() {
    let area = 3.0e-4;
    for law in laws() {
        for l in stretches() {
            let force = law.axial_force(area, l).unwrap();
            let back = law.stretch_from_axial_force(area, force).unwrap();
            assert!(rel_err(back, l) < 1e-10, "{law}: λ = {l}, got {back}");
        }
    }
    // The linear law cannot carry a compressive stress of E or more (it would need λ <= 0).
    let lin = Hookean::new(1.0e5).unwrap();
    assert_eq!(
        invalid_name(lin.stretch_from_nominal_stress(-1.0e5).unwrap_err()),
        "nominal_stress"
    );
    assert_eq!(
        invalid_name(lin.stretch_from_axial_force(1e-4, -20.0).unwrap_err()),
        "force"
    );
    // Neo-Hookean reaches any compressive stress.
    let nh = NeoHookean::new(1.0e4).unwrap();
    let l = nh.stretch_from_nominal_stress(-1.0e6).unwrap();
    assert!(rel_err(nh.nominal_stress(l).unwrap(), -1.0e6) < 1e-10);
}

#[test]
fn check_stable_flags_lost_monotonicity() {
    for law in laws() {
        law.check_stable(0.5, 3.0).unwrap();
    }
    // Yeoh with a negative c20: dP/dλ vanishes where W1 + ... turns; tension side.
    let yeoh = Yeoh::new(1.0e4, -1.0e3, 0.0).unwrap();
    yeoh.check_stable(0.9, 1.5).unwrap();
    let err = yeoh.check_stable(0.5, 4.0).unwrap_err();
    match err {
        Error::InvalidParameter { name, expected, .. } => {
            assert_eq!(name, "Yeoh parameters");
            assert!(expected.contains("stretch"));
        }
        other => panic!("{other:?}"),
    }
    // Mooney–Rivlin with a negative c01 loses stability in compression, where
    // c10 + c01/λ < 0 (λ < 0.8 here).
    let mr = MooneyRivlin::new(1.0e4, -8.0e3).unwrap();
    mr.check_stable(0.95, 3.0).unwrap();
    assert_eq!(
        invalid_name(mr.check_stable(0.5, 3.0).unwrap_err()),
        "MooneyRivlin parameters"
    );
    // The reported failure stretch is where dP/dλ first turns non-positive.
    assert!(mr.nominal_tangent(0.79).unwrap() < 0.0);
}

// ---------------------------------------------------------------- validation, no panics

#[test]
fn bad_input_is_invalid_parameter_naming_it() {
    assert_eq!(invalid_name(NeoHookean::new(0.0).unwrap_err()), "mu");
    assert_eq!(invalid_name(NeoHookean::new(f64::NAN).unwrap_err()), "mu");
    assert_eq!(
        invalid_name(Hookean::new(-1.0).unwrap_err()),
        "youngs_modulus"
    );
    assert_eq!(
        invalid_name(MooneyRivlin::new(1.0, -2.0).unwrap_err()),
        "c10 + c01"
    );
    assert_eq!(
        invalid_name(MooneyRivlin::new(f64::INFINITY, 0.0).unwrap_err()),
        "c10"
    );
    assert_eq!(invalid_name(Yeoh::new(-1.0, 0.0, 0.0).unwrap_err()), "c10");
    assert_eq!(
        invalid_name(Yeoh::new(1.0, f64::NAN, 0.0).unwrap_err()),
        "c20"
    );
    assert_eq!(
        invalid_name(Yeoh::new(1.0, 0.0, f64::NAN).unwrap_err()),
        "c30"
    );
    assert_eq!(
        invalid_name(Ogden::new(&[1.0], &[0.0]).unwrap_err()),
        "alpha[0]"
    );
    assert_eq!(
        invalid_name(Ogden::new(&[1.0, 2.0], &[1.0]).unwrap_err()),
        "mu"
    );
    assert_eq!(invalid_name(Ogden::new(&[-1.0], &[2.0]).unwrap_err()), "mu");
    assert_eq!(invalid_name(Ogden::new(&[], &[]).unwrap_err()), "mu");
    assert_eq!(
        invalid_name(Linearised::new(1.0, 0.0).unwrap_err()),
        "reference_strain"
    );
    assert_eq!(
        invalid_name(Linearised::from_secant_point(-5.0, 1.0).unwrap_err()),
        "nominal_stress"
    );
    let nh = NeoHookean::new(1.0).unwrap();
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert_eq!(invalid_name(nh.nominal_stress(bad).unwrap_err()), "stretch");
        assert_eq!(invalid_name(nh.true_stress(bad).unwrap_err()), "stretch");
        assert_eq!(
            invalid_name(nh.nominal_tangent(bad).unwrap_err()),
            "stretch"
        );
    }
    for bad in [-1.0, -2.0, f64::NAN] {
        assert_eq!(invalid_name(nh.tangent_modulus(bad).unwrap_err()), "strain");
    }
    assert_eq!(invalid_name(nh.axial_force(0.0, 1.0).unwrap_err()), "area0");
    assert_eq!(
        invalid_name(nh.stretch_from_axial_force(1.0, f64::NAN).unwrap_err()),
        "force"
    );
    assert_eq!(
        invalid_name(nh.check_stable(2.0, 1.0).unwrap_err()),
        "stretch_max"
    );
    assert_eq!(
        invalid_name(nh.check_stable(0.0, 1.0).unwrap_err()),
        "stretch_min"
    );

    let opts = FitOptions::default();
    assert_eq!(
        invalid_name(
            UniaxialData::new(
                &[0.1, 0.2],
                StrainMeasure::Engineering,
                &[1.0],
                StressMeasure::True
            )
            .unwrap_err()
        ),
        "stress"
    );
    assert_eq!(
        invalid_name(
            UniaxialData::new(
                &[0.1, -1.5],
                StrainMeasure::Engineering,
                &[1.0, 2.0],
                StressMeasure::True
            )
            .unwrap_err()
        ),
        "strain[1]"
    );
    assert_eq!(
        invalid_name(
            UniaxialData::new(
                &[1.1, 1.2],
                StrainMeasure::Stretch,
                &[1.0, f64::NAN],
                StressMeasure::True
            )
            .unwrap_err()
        ),
        "stress[1]"
    );
    let data = UniaxialData::new(
        &[1.1],
        StrainMeasure::Stretch,
        &[1.0],
        StressMeasure::Nominal,
    )
    .unwrap();
    assert_eq!(
        invalid_name(fit_uniaxial(&data, ModelKind::MooneyRivlin, &opts).unwrap_err()),
        "data"
    );
    assert_eq!(
        invalid_name(fit_uniaxial(&data, ModelKind::Yeoh { terms: 4 }, &opts).unwrap_err()),
        "terms"
    );
    assert_eq!(
        invalid_name(fit_uniaxial(&data, ModelKind::Ogden { terms: 0 }, &opts).unwrap_err()),
        "terms"
    );
    assert_eq!(
        invalid_name(data.within(2.0, 3.0).unwrap_err()),
        "stretch_max"
    );
}

// ---------------------------------------------------------------- fitting synthetic data

/// Deterministic pseudo-random numbers (SplitMix64), uniform in `[-1, 1]`.
struct Noise(u64);

impl Noise {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

/// Synthetic test: 200 stretches in `[0.7, 3]`, stress of `law` in `measure` plus uniform noise
/// of amplitude `noise` (Pa).
fn synthetic(law: &dyn UniaxialLaw, measure: StressMeasure, noise: f64, seed: u64) -> UniaxialData {
    synthetic_scaled(law, measure, noise, seed).0
}

/// [`synthetic`] with the noise amplitude given as a fraction of the largest stress (at
/// `λ = 3`, in the data's measure); returns the data and the amplitude (Pa).
fn synthetic_relative(
    law: &dyn UniaxialLaw,
    measure: StressMeasure,
    fraction: f64,
    seed: u64,
) -> (UniaxialData, f64) {
    let peak = match measure {
        StressMeasure::Nominal => law.nominal_stress(3.0).unwrap(),
        StressMeasure::True => law.true_stress(3.0).unwrap(),
    };
    synthetic_scaled(law, measure, fraction * peak, seed)
}

fn synthetic_scaled(
    law: &dyn UniaxialLaw,
    measure: StressMeasure,
    noise: f64,
    seed: u64,
) -> (UniaxialData, f64) {
    let mut rng = Noise(seed);
    let stretch: Vec<f64> = (0..200).map(|i| 0.7 + 2.3 * i as f64 / 199.0).collect();
    let stress: Vec<f64> = stretch
        .iter()
        .map(|&l| {
            let s = match measure {
                StressMeasure::Nominal => law.nominal_stress(l).unwrap(),
                StressMeasure::True => law.true_stress(l).unwrap(),
            };
            s + noise * rng.next()
        })
        .collect();
    (
        UniaxialData::new(&stretch, StrainMeasure::Stretch, &stress, measure).unwrap(),
        noise,
    )
}

/// Noise of 0.5 % of the largest stress; parameters recovered within the stated tolerances
/// (a few times the parameter standard error of this design).
#[test]
fn fits_recover_known_parameters_from_noisy_data() {
    let opts = FitOptions::default();
    for measure in [StressMeasure::Nominal, StressMeasure::True] {
        // Neo-Hookean: mu within 0.1 %.
        let truth = NeoHookean::new(4.0e4).unwrap();
        let (data, noise) = synthetic_relative(&truth, measure, 0.005, 1);
        let fit = fit_uniaxial(&data, ModelKind::NeoHookean, &opts).unwrap();
        let UniaxialModel::NeoHookean(nh) = fit.model else {
            panic!()
        };
        assert!(rel_err(nh.mu(), 4.0e4) < 1e-3, "{nh}");
        // Residuals are the noise: RMS ≈ amplitude / √3, max ≤ amplitude (+ fit error).
        assert!(fit.stats.rms < 0.7 * noise && fit.stats.rms > 0.45 * noise);
        assert!(fit.stats.max_abs_residual < 1.1 * noise);
        assert!(fit.stats.r_squared > 0.999);

        // Mooney–Rivlin: c10 within 2 %, c01 within 5 % (they are strongly correlated).
        let truth = MooneyRivlin::new(3.0e4, 8.0e3).unwrap();
        let (data, noise) = synthetic_relative(&truth, measure, 0.005, 2);
        let fit = fit_uniaxial(&data, ModelKind::MooneyRivlin, &opts).unwrap();
        let UniaxialModel::MooneyRivlin(mr) = fit.model else {
            panic!()
        };
        assert!(rel_err(mr.c10(), 3.0e4) < 0.02, "{mr}");
        assert!(rel_err(mr.c01(), 8.0e3) < 0.05, "{mr}");
        assert!(fit.stats.rms < 0.7 * noise);

        // Yeoh (3 terms): c10 within 2 %, c20 within 10 %, c30 within 20 %.
        let truth = Yeoh::new(2.0e4, 1.5e3, 60.0).unwrap();
        let (data, noise) = synthetic_relative(&truth, measure, 0.005, 3);
        let fit = fit_uniaxial(&data, ModelKind::Yeoh { terms: 3 }, &opts).unwrap();
        let UniaxialModel::Yeoh(y) = fit.model else {
            panic!()
        };
        assert!(rel_err(y.c10(), 2.0e4) < 0.02, "{y}");
        assert!(rel_err(y.c20(), 1.5e3) < 0.10, "{y}");
        assert!(rel_err(y.c30(), 60.0) < 0.20, "{y}");
        assert!(fit.stats.rms < 0.7 * noise);

        // Ogden (2 terms): the curve is recovered within the noise; the parameters are strongly
        // correlated (the second modulus with its exponent): the first term within 3 %, the
        // second exponent within 5 %, its modulus within 20 %.
        let truth = Ogden::new(&[2.0e4, 2.0e3], &[1.5, 4.0]).unwrap();
        let (data, noise) = synthetic_relative(&truth, measure, 0.005, 4);
        let fit = fit_uniaxial(&data, ModelKind::Ogden { terms: 2 }, &opts).unwrap();
        let UniaxialModel::Ogden(o) = fit.model else {
            panic!()
        };
        // At least as good as the true parameters on these data (a least-squares minimum),
        // and the same curve over the data to within a third of the noise amplitude.
        assert!(fit.stats.rms <= fit_stats(&truth, &data).rms * (1.0 + 1e-12));
        for &l in data.stretch() {
            let d = match measure {
                StressMeasure::Nominal => {
                    o.nominal_stress(l).unwrap() - truth.nominal_stress(l).unwrap()
                }
                StressMeasure::True => o.true_stress(l).unwrap() - truth.true_stress(l).unwrap(),
            };
            assert!(d.abs() < noise / 3.0, "λ = {l}: {d} Pa");
        }
        let (mut mu, mut alpha) = (o.mu().to_vec(), o.alpha().to_vec());
        if alpha[0] > alpha[1] {
            mu.swap(0, 1);
            alpha.swap(0, 1);
        }
        assert!(
            rel_err(mu[0], 2.0e4) < 0.03 && rel_err(mu[1], 2.0e3) < 0.20,
            "{o}"
        );
        assert!(
            rel_err(alpha[0], 1.5) < 0.03 && rel_err(alpha[1], 4.0) < 0.05,
            "{o}"
        );
        assert!(fit.stats.rms < 0.7 * noise);
    }
}

#[test]
fn noise_free_fits_are_exact() {
    let opts = FitOptions::default();
    let truth = Yeoh::new(2.0e4, -4.0e2, 25.0).unwrap();
    let data = synthetic(&truth, StressMeasure::Nominal, 0.0, 0);
    let fit = fit_uniaxial(&data, ModelKind::Yeoh { terms: 3 }, &opts).unwrap();
    let UniaxialModel::Yeoh(y) = fit.model else {
        panic!()
    };
    assert!(
        rel_err(y.c10(), 2.0e4) < 1e-10 && rel_err(y.c20(), -4.0e2) < 1e-9,
        "{y}"
    );
    assert!(rel_err(y.c30(), 25.0) < 1e-8, "{y}");

    let truth = Ogden::new(&[2.0e4, -1.0e3], &[2.5, -3.0]).unwrap();
    let data = synthetic(&truth, StressMeasure::True, 0.0, 0);
    let fit = fit_uniaxial(&data, ModelKind::Ogden { terms: 2 }, &opts).unwrap();
    assert!(
        fit.stats.rms < 1e-6 * 2.0e4,
        "{} {:?}",
        fit.model,
        fit.stats
    );
}

#[test]
fn strain_measures_are_converted() {
    // The same Neo-Hookean curve given as stretch, engineering strain and log strain.
    let law = NeoHookean::new(1.0e4).unwrap();
    let stretch: Vec<f64> = (1..50).map(|i| 1.0 + 0.05 * i as f64).collect();
    let stress: Vec<f64> = stretch
        .iter()
        .map(|&l| law.true_stress(l).unwrap())
        .collect();
    let eng: Vec<f64> = stretch.iter().map(|l| l - 1.0).collect();
    let log: Vec<f64> = stretch.iter().map(|l| l.ln()).collect();
    for (strain, measure) in [
        (&stretch, StrainMeasure::Stretch),
        (&eng, StrainMeasure::Engineering),
        (&log, StrainMeasure::Logarithmic),
    ] {
        let data = UniaxialData::new(strain, measure, &stress, StressMeasure::True).unwrap();
        let fit = fit_uniaxial(&data, ModelKind::NeoHookean, &FitOptions::default()).unwrap();
        let UniaxialModel::NeoHookean(nh) = fit.model else {
            panic!()
        };
        assert!(rel_err(nh.mu(), 1.0e4) < 1e-12, "{measure:?}: {nh}");
    }
}

#[test]
fn nonnegative_fits_respect_the_bounds() {
    // Strain-softening data: the unconstrained Yeoh fit has c20 < 0.
    let truth = MooneyRivlin::new(1.0e4, 6.0e3).unwrap();
    let data = synthetic(&truth, StressMeasure::Nominal, 0.0, 0);
    let free = fit_uniaxial(&data, ModelKind::Yeoh { terms: 2 }, &FitOptions::default()).unwrap();
    let UniaxialModel::Yeoh(y) = free.model else {
        panic!()
    };
    assert!(y.c20() < 0.0);
    let opts = FitOptions {
        nonnegative: true,
        ..FitOptions::default()
    };
    let bounded = fit_uniaxial(&data, ModelKind::Yeoh { terms: 2 }, &opts).unwrap();
    let UniaxialModel::Yeoh(yb) = bounded.model else {
        panic!()
    };
    assert!(yb.c10() > 0.0 && yb.c20() == 0.0, "{yb}");
    // The bounded optimum is the one-term (Neo-Hookean) fit, and no better than the free one.
    let nh = fit_uniaxial(&data, ModelKind::NeoHookean, &FitOptions::default()).unwrap();
    let UniaxialModel::NeoHookean(n) = nh.model else {
        panic!()
    };
    assert!(rel_err(2.0 * yb.c10(), n.mu()) < 1e-12);
    assert!(bounded.stats.rms >= free.stats.rms);
    // Ogden with μ >= 0.
    let fit = fit_uniaxial(&data, ModelKind::Ogden { terms: 2 }, &opts).unwrap();
    let UniaxialModel::Ogden(o) = fit.model else {
        panic!()
    };
    assert!(o.mu().iter().all(|&m| m >= 0.0), "{o}");
}

#[test]
fn linearised_secants() {
    let nh = NeoHookean::new(2.0e4).unwrap();
    let lin = Linearised::secant_of(&nh, 1.0).unwrap();
    // The secant passes through the curve at the reference strain.
    assert!(
        rel_err(
            lin.nominal_stress(2.0).unwrap(),
            nh.nominal_stress(2.0).unwrap()
        ) < 1e-15
    );
    assert!(rel_err(lin.secant_modulus(), 2.0e4 * (2.0 - 0.25)) < 1e-15);
    // A datasheet "100 % modulus" of 0.069 MPa.
    let ds = Linearised::from_secant_point(0.069e6, 1.0).unwrap();
    assert!(rel_err(ds.as_hookean().youngs_modulus(), 0.069e6) < 1e-15);
    // A line fitted to a line through the origin.
    let data = UniaxialData::new(
        &[0.1, 0.2, 0.4],
        StrainMeasure::Engineering,
        &[1.0e4, 2.0e4, 4.0e4],
        StressMeasure::Nominal,
    )
    .unwrap();
    let fit = fit_uniaxial(&data, ModelKind::Linearised, &FitOptions::default()).unwrap();
    let UniaxialModel::Linearised(l) = fit.model else {
        panic!()
    };
    assert!(rel_err(l.secant_modulus(), 1.0e5) < 1e-12);
    assert!(rel_err(l.reference_strain(), 0.4) < 1e-12);
}

// ---------------------------------------------------------------- silicone library

#[test]
fn silicone_library_is_valid_and_named() {
    for s in Silicone::ALL {
        assert_eq!(Silicone::from_name(s.name()).unwrap(), s);
        assert!(!s.source().is_empty());
        let nh = s.neo_hookean();
        let yeoh = s.yeoh();
        // Rebuilding through the validating constructors accepts the stored constants.
        NeoHookean::new(nh.mu()).unwrap();
        Yeoh::new(yeoh.c10(), yeoh.c20(), yeoh.c30()).unwrap();
        // Stable on the fitted range (or, without one, on [0.5, 3]).
        let (lo, hi) = s.fit_stretch_range().unwrap_or((0.5, 3.0));
        nh.check_stable(0.5, hi).unwrap();
        yeoh.check_stable(0.5, hi).unwrap();
        if let Some(mr) = s.mooney_rivlin() {
            MooneyRivlin::new(mr.c10(), mr.c01()).unwrap();
            mr.check_stable(lo, hi).unwrap();
        }
    }
    assert_eq!(
        Silicone::from_name("dragonskin-10").unwrap(),
        Silicone::DragonSkin10
    );
    assert_eq!(
        Silicone::from_name("ECOFLEX 00 30").unwrap(),
        Silicone::Ecoflex0030
    );
    assert_eq!(
        invalid_name(Silicone::from_name("Sylgard 184").unwrap_err()),
        "name"
    );
    // Ordering of stiffness within a family (Shore hardness): 00-30 < 00-50, 10 < 20 < 30.
    let mu = |s: Silicone| s.neo_hookean().mu();
    assert!(mu(Silicone::Ecoflex0030) < mu(Silicone::Ecoflex0050));
    assert!(mu(Silicone::DragonSkin10) < mu(Silicone::DragonSkin20));
    assert!(mu(Silicone::DragonSkin20) < mu(Silicone::DragonSkin30));
}

/// Directory of the measured curves vendored with the repository (`data/silicone-tensile`).
///
/// # Panics
/// If the folder is missing: the check below must not pass without its data.
fn silicone_data_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/silicone-tensile");
    assert!(
        dir.is_dir(),
        "vendored tensile data not found at {}",
        dir.display()
    );
    dir
}

/// Engineering strain and stress (Pa) of one database file (header columns checked by name).
fn read_curve(path: &std::path::Path) -> (Vec<f64>, Vec<f64>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .by_ref()
        .find(|l| l.starts_with("Time (s);"))
        .unwrap()
        .split(';')
        .collect();
    let col = |n: &str| header.iter().position(|h| h.trim() == n).unwrap();
    let (ie, is) = (col("Engineering Strain"), col("Engineering Stress (MPa)"));
    lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let f: Vec<&str> = l.split(';').collect();
            (
                f[ie].trim().parse::<f64>().unwrap(),
                1e6 * f[is].trim().parse::<f64>().unwrap(),
            )
        })
        .unzip()
}

/// The library constants are the fits to the measured curves (to their six stored digits).
#[test]
fn silicone_library_reproduces_the_measured_fits() {
    let dir = silicone_data_dir();
    let files = [
        (Silicone::Ecoflex0030, "Ecoflex 00-30.csv"),
        (Silicone::Ecoflex0050, "Ecoflex 00-50.csv"),
        (Silicone::DragonSkin10, "Dragon Skin 10 MEDIUM.csv"),
        (Silicone::DragonSkin20, "Dragon Skin 20.csv"),
        (Silicone::DragonSkin30, "Dragon Skin 30.csv"),
    ];
    // Every library entry is backed by a measured curve.
    assert_eq!(files.len(), Silicone::ALL.len());
    let opts = FitOptions::default();
    for (silicone, file) in files {
        let (strain, stress) = read_curve(&dir.join(file));
        let (_, hi) = silicone.fit_stretch_range().unwrap();
        let data = UniaxialData::new(
            &strain,
            StrainMeasure::Engineering,
            &stress,
            StressMeasure::Nominal,
        )
        .unwrap()
        .within(1e-3, hi)
        .unwrap();
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-5 * b.abs();

        let fit = fit_uniaxial(&data, ModelKind::NeoHookean, &opts).unwrap();
        let UniaxialModel::NeoHookean(nh) = fit.model else {
            panic!()
        };
        assert!(
            close(silicone.neo_hookean().mu(), nh.mu()),
            "{silicone}: {nh}"
        );

        let fit = fit_uniaxial(&data, ModelKind::MooneyRivlin, &opts).unwrap();
        let UniaxialModel::MooneyRivlin(mr) = fit.model else {
            panic!()
        };
        let lib = silicone.mooney_rivlin().unwrap();
        assert!(
            close(lib.c10(), mr.c10()) && close(lib.c01(), mr.c01()),
            "{silicone}: {mr}"
        );

        let fit = fit_uniaxial(&data, ModelKind::Yeoh { terms: 3 }, &opts).unwrap();
        let UniaxialModel::Yeoh(y) = fit.model else {
            panic!()
        };
        let lib = silicone.yeoh();
        assert!(
            close(lib.c10(), y.c10()) && close(lib.c20(), y.c20()) && close(lib.c30(), y.c30()),
            "{silicone}: {y}"
        );
        // Yeoh fits these curves to within 2 % of the largest stress (RMS).
        let s = fit_stats(&lib, &data);
        let peak = data.stress().iter().copied().fold(0.0, f64::max);
        assert!(
            s.rms < 0.02 * peak && s.r_squared > 0.999,
            "{silicone}: {s:?}"
        );
    }
}
