//! Tendon displacement control: round trips through the tension-controlled solve, slack
//! tendons against the solve without them, tendon stiffness, and the tangent compliance with
//! held tendons against central differences of the displacement-controlled solve.

#![allow(clippy::unwrap_used, clippy::too_many_lines)]

mod common;

use std::sync::Arc;

use common::niti_model;
use softrod::nalgebra::Vector3;
use softrod::{
    reference_lengths, solve_statics, tangent_compliance, Actuation, Integrator, Loads, RobotModel,
    SolveOptions, StaticsSolution, Tendon, TendonControl, TendonInput,
};

fn niti(loads: Loads, density: Option<f64>) -> Arc<RobotModel> {
    niti_model(loads, density, 0.0)
}

fn options() -> SolveOptions {
    SolveOptions::default()
}

fn shape_distance(a: &StaticsSolution, b: &StaticsSolution) -> f64 {
    assert_eq!(a.s.len(), b.s.len());
    a.position
        .iter()
        .zip(&b.position)
        .map(|(p, q)| (Vector3::from(*p) - Vector3::from(*q)).norm())
        .fold(0.0, f64::max)
}

/// Solve with tensions, read the displacements, solve with the displacements: the same
/// tensions and shape.
fn round_trip(model: &Arc<RobotModel>, tensions: &[f64], held: &[usize], what: &str) {
    let o = options();
    let forward = solve_statics(model, &Actuation::tensions(tensions), &o).unwrap();
    let zero = reference_lengths(model, &o).unwrap();
    let mut act = Actuation::tensions(tensions);
    for &i in held {
        act.tendons[i] = TendonInput::displacement(zero[i] - forward.tendon_lengths[i]);
    }
    let back = solve_statics(model, &act, &o).unwrap();
    for &i in held {
        let (a, b) = (tensions[i], back.tendon_tensions[i]);
        let scale = tensions.iter().fold(0.0f64, |m, v| m.max(*v));
        assert!(
            (a - b).abs() <= 1e-8 * scale,
            "{what}: tendon {i}: {b} N vs {a} N"
        );
    }
    let d = shape_distance(&forward, &back);
    println!(
        "{what}: tensions {:?}, shape distance {d:.2e} m, {} iterations",
        back.tendon_tensions, back.stats.iterations
    );
    assert!(d <= 1e-10, "{what}: shape distance {d:e} m");
    assert!(back.stats.converged);
}

#[test]
fn displacement_round_trip_every_tendon_held() {
    let model = niti(Loads::default(), None);
    round_trip(
        &model,
        &[4.0, 0.0, 0.5, 0.0, 2.0, 0.0],
        &[0, 1, 2, 3, 4, 5],
        "unloaded, all held",
    );
}

#[test]
fn displacement_round_trip_mixed_control() {
    let model = niti(Loads::default(), None);
    round_trip(
        &model,
        &[4.0, 0.3, 0.5, 1.0, 2.0, 0.0],
        &[0, 4, 5],
        "unloaded, mixed",
    );
}

#[test]
fn displacement_round_trip_under_tip_load_and_gravity() {
    let loads = Loads {
        tip_force: Vector3::new(0.2, -0.1, -0.3),
        gravity: Vector3::new(0.0, -9.81, 0.0),
        ..Default::default()
    };
    let model = niti(loads, Some(6450.0));
    round_trip(
        &model,
        &[3.0, 0.0, 0.5, 0.0, 2.0, 1.0],
        &[0, 1, 2, 3, 4, 5],
        "tip load and gravity, all held",
    );
}

/// A one-tendon rod under a tip force: length (m), radius (m), E (Pa), offset (m), tension
/// (N), tip force (N), RK4 steps.
type Case = (f64, f64, f64, [f64; 2], f64, [f64; 3], usize);

/// One-tendon rods under a tip force (from a random scan of loaded robots), on 100 or 200 RK4
/// steps: the displacement-controlled solve returns the tensions whose displacements it was
/// given. Its held row resolves the slack to the round-off of a path length, which grows with
/// the steps (up to 55 `ε ℓ` at 200 steps on these robots, above a floor of 16).
#[test]
fn displacement_round_trip_on_fine_meshes_under_a_tip_force() {
    let cases: [Case; 4] = [
        (
            0.290_461_133_727_983_7,
            8.036_425_822_873_156e-4,
            28_712_537.814_615_168,
            [5.154_783_088_027_37e-4, -1.111_961_982_070_262_4e-4],
            0.082_140_848_997_903_37,
            [
                9.245_232_368_372_612e-5,
                -4.032_236_429_738_654e-5,
                4.922_756_306_136_093e-6,
            ],
            100,
        ),
        (
            0.753_407_227_769_765_2,
            1.810_123_779_742_184_7e-3,
            1_848_072_859.516_309_5,
            [1.357_819_368_359_375_2e-3, -3.965_236_030_419_608e-4],
            12.768_370_268_905_455,
            [
                -0.018_357_345_147_867_337,
                0.006_757_292_223_863_014,
                -0.013_213_456_131_952_354,
            ],
            200,
        ),
        (
            0.838_522_038_379_504_5,
            1.376_958_585_316_411_2e-3,
            863_181_175.986_151_5,
            [5.173_193_378_602_569e-4, -5.394_182_513_851_974_4e-5],
            2.965_723_914_842_062,
            [
                7.752_654_778_960_421e-4,
                1.990_521_690_596_541e-3,
                -9.980_902_039_457_334e-4,
            ],
            100,
        ),
        (
            0.579_934_534_922_227_9,
            4.795_898_034_807_645e-3,
            931_106_341.718_693_4,
            [2.102_026_435_130_346e-3, -4.040_647_421_997_539_5e-4],
            120.487_302_870_451_15,
            [
                -0.270_189_714_188_004_6,
                -0.337_154_990_823_631_04,
                -0.510_528_195_414_220_1,
            ],
            100,
        ),
    ];
    for (k, (l, r, e, offset, tension, force, steps)) in cases.into_iter().enumerate() {
        let rod = common::circular_rod(l, r, e, 0.4);
        let tendons = vec![Tendon::constant(offset, None).unwrap()];
        let loads = Loads::tip_force(Vector3::from(force));
        let model = RobotModel::new(rod, tendons, Vec::new(), loads).unwrap();
        let o = SolveOptions {
            integrator: Integrator::Rk4 { steps },
            ..SolveOptions::default()
        };
        let forward = solve_statics(&model, &Actuation::tensions(&[tension]), &o).unwrap();
        let zero = reference_lengths(&model, &o).unwrap();
        let act = Actuation {
            tendons: vec![TendonInput::displacement(
                zero[0] - forward.tendon_lengths[0],
            )],
            ..Actuation::default()
        };
        let back = solve_statics(&model, &act, &o)
            .unwrap_or_else(|err| panic!("case {k} ({steps} steps): {err}"));
        let got = back.tendon_tensions[0];
        assert!(
            (got - tension).abs() <= 1e-8 * tension,
            "case {k}: {got} N vs {tension} N"
        );
        let d = shape_distance(&forward, &back);
        assert!(d <= 1e-10 * l, "case {k}: shape distance {d:e} m");
    }
}

/// A rod of `length` (m), radius 1 mm, E = 54 GPa, with `n` tendons 10 mm from the axis,
/// equally spaced from the angle `phase` (rad), ending at the tip, under a tip force (N).
fn ring_of_tendons(
    n: usize,
    phase: f64,
    tip_force: [f64; 3],
    inextensible: bool,
) -> Arc<RobotModel> {
    let rod = common::circular_rod(0.3, 1e-3, 54e9, 0.3).with_inextensible(inextensible);
    let tendons = (0..n)
        .map(|i| {
            let a = phase + std::f64::consts::TAU * i as f64 / n as f64;
            Tendon::constant([0.01 * a.cos(), 0.01 * a.sin()], None).unwrap()
        })
        .collect();
    let loads = Loads {
        tip_force: Vector3::from(tip_force),
        ..Default::default()
    };
    RobotModel::new(rod, tendons, Vec::new(), loads).unwrap()
}

/// Every tendon of `model` held at the displacements of `tensions`, inextensible or with
/// `stiffness` (N/m): the solve's result.
fn held_at_displacements_of(
    model: &Arc<RobotModel>,
    tensions: &[f64],
    stiffness: f64,
) -> softrod::Result<StaticsSolution> {
    let o = options();
    let forward = solve_statics(model, &Actuation::tensions(tensions), &o).unwrap();
    let zero = reference_lengths(model, &o).unwrap();
    let mut act = Actuation::tensions(tensions);
    for (i, t) in act.tendons.iter_mut().enumerate() {
        // A compliant tendon stretched by its tension: its base end pulled that much further.
        *t = TendonInput::Displacement {
            displacement: zero[i] - forward.tendon_lengths[i] + tensions[i] / stiffness,
            stiffness,
        };
    }
    solve_statics(model, &act, &o)
}

/// Held inextensible tendons whose displacements do not determine their tensions are named,
/// with the tensions that pull against each other: four tendons 90° apart (the pattern
/// `[1, -1, 1, -1]` moves neither the rod nor the tendons' lengths), six 60° apart, and three
/// on a rod that cannot stretch (equal tensions only compress it). They were answered with
/// one of the many tensions silently, or with a `ConvergenceError` at a residual of 1e-11.
/// The same tendons with a stiffness (or fewer of them held) determine the tensions: the ones
/// the displacements came from (the oracle).
#[test]
fn held_tendons_pulling_against_each_other_without_moving_the_rod_are_named() {
    let four = ring_of_tendons(4, 0.3, [0.02, 0.01, 0.0], false);
    let six = ring_of_tendons(6, 0.3, [0.02, 0.01, 0.0], false);
    let stiff = ring_of_tendons(3, 0.3, [0.02, 0.01, 0.0], true);
    let symmetric = ring_of_tendons(4, 0.0, [0.02, 0.0, 0.0], false);
    let cases: [(&Arc<RobotModel>, &[f64], &str); 4] = [
        (&four, &[3.0, 1.5, 1.0, 0.5], "four tendons"),
        (&symmetric, &[3.0, 1.0, 1.0, 1.0], "four tendons, planar"),
        (&six, &[3.0, 2.0, 1.5, 1.0, 0.7, 0.5], "six tendons"),
        (&stiff, &[3.0, 1.0, 0.5], "three tendons, inextensible rod"),
    ];
    for (model, tensions, what) in cases {
        match held_at_displacements_of(model, tensions, f64::INFINITY) {
            Err(softrod::Error::InvalidParameter { name, expected, .. }) => {
                println!("{what}: {expected}");
                assert_eq!(name, "displacements", "{what}");
                assert!(expected.contains("tendon_stiffness"), "{what}: {expected}");
            }
            other => panic!("{what}: {other:?}"),
        }
        let back = held_at_displacements_of(model, tensions, 1e4).unwrap();
        for (a, b) in tensions.iter().zip(&back.tendon_tensions) {
            assert!(
                (a - b).abs() <= 1e-8 * 3.0,
                "{what}, compliant: {b} N vs {a} N"
            );
        }
    }
    // Three of the four held: determined (the rod's axial stiffness separates them).
    round_trip(
        &four,
        &[3.0, 1.5, 1.0, 0.5],
        &[0, 1, 2],
        "four tendons, three held",
    );
}

#[test]
fn a_paid_out_tendon_goes_slack_and_changes_nothing() {
    let model = niti(Loads::default(), None);
    let o = options();
    let tensions = [4.0, 0.0, 0.5, 0.0, 2.0, 0.0];
    let without = solve_statics(&model, &Actuation::tensions(&tensions), &o).unwrap();
    let zero = reference_lengths(&model, &o).unwrap();
    // Tendons 1, 3 and 5 paid out beyond the lengthening of their paths the others cause (by
    // 1 mm, 1 µm and 0.1 mm); the others tension-controlled.
    let natural = |i: usize| zero[i] - without.tendon_lengths[i];
    let paid = [
        (1, natural(1).min(0.0) - 1e-3),
        (3, natural(3).min(0.0) - 1e-6),
        (5, natural(5).min(0.0) - 1e-4),
    ];
    let mut act = Actuation::tensions(&tensions);
    for &(i, d) in &paid {
        assert!(d < 0.0);
        act.tendons[i] = TendonInput::displacement(d);
    }
    let with = solve_statics(&model, &act, &o).unwrap();
    for &(i, d) in &paid {
        assert_eq!(with.tendon_tensions[i], 0.0, "tendon {i}");
        let slack = (zero[i] - with.tendon_lengths[i]) - d;
        assert!(slack > 0.0, "tendon {i} slack {slack}");
    }
    let d = shape_distance(&with, &without);
    assert!(d <= 1e-12, "shape distance {d:e}");
}

#[test]
fn held_tendons_meet_the_complementarity_exactly() {
    let model = niti(Loads::default(), None);
    let o = options();
    let zero = reference_lengths(&model, &o).unwrap();
    // Every tendon held: segment 1's first tendon pulled 1 mm, its antagonists paid out by
    // 2 mm (they go slack), segment 2's at zero (held rigid: they resist the bending of
    // segment 1, taut or slack as the complementarity decides).
    let disp = [1e-3, -2e-3, -2e-3, 0.0, 0.0, 0.0];
    let act = Actuation::mixed(&[0.0; 6], &disp);
    let sol = solve_statics(&model, &act, &o).unwrap();
    for i in 0..6 {
        let tau = sol.tendon_tensions[i];
        let slack = (zero[i] - sol.tendon_lengths[i]) - disp[i];
        assert!(
            tau >= 0.0 && slack >= -1e-12,
            "tendon {i}: {tau} N, slack {slack}"
        );
        assert!(
            tau == 0.0 || slack.abs() <= 1e-12,
            "tendon {i}: {tau} N, slack {slack}"
        );
    }
    assert!(sol.tendon_tensions[0] > 1.0);
    assert_eq!(sol.tendon_tensions[1], 0.0);
    assert_eq!(sol.tendon_tensions[2], 0.0);
    println!("tensions {:?}", sol.tendon_tensions);
    // The same shape as the tension-controlled solve at the tensions found.
    let forward = solve_statics(&model, &Actuation::tensions(&sol.tendon_tensions), &o).unwrap();
    assert!(shape_distance(&sol, &forward) <= 1e-10);
}

#[test]
fn a_compliant_tendon_stretches_by_its_tension_over_its_stiffness() {
    let model = niti(Loads::default(), None);
    let o = options();
    let zero = reference_lengths(&model, &o).unwrap();
    let k = 2e3; // N/m
    let mut act = Actuation::tensions(&[0.0; 6]);
    act.tendons[0] = TendonInput::Displacement {
        displacement: 2e-3,
        stiffness: k,
    };
    let sol = solve_statics(&model, &act, &o).unwrap();
    let tau = sol.tendon_tensions[0];
    let shortening = zero[0] - sol.tendon_lengths[0];
    assert!(
        (2e-3 - shortening - tau / k).abs() <= 1e-13,
        "{tau} {shortening}"
    );
    // The same shape as the tension-controlled solve at that tension.
    let mut t = [0.0; 6];
    t[0] = tau;
    let forward = solve_statics(&model, &Actuation::tensions(&t), &o).unwrap();
    assert!(shape_distance(&sol, &forward) <= 1e-12);
    // A rigid tendon needs a larger tension for the same pull.
    let mut rigid = act.clone();
    rigid.tendons[0] = TendonInput::displacement(2e-3);
    let r = solve_statics(&model, &rigid, &o).unwrap();
    assert!(r.tendon_tensions[0] > tau);
}

/// The tangent compliance with the taut held tendons at fixed displacement (compliant
/// tendons) against central differences of the displacement-controlled nonlinear solve under a
/// small tip wrench.
#[test]
fn held_tangent_compliance_matches_central_differences() {
    let o = options();
    let base = niti(Loads::default(), None);
    let zero = reference_lengths(&base, &o).unwrap();
    let mut act = Actuation::mixed(
        &[0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        &[1e-3, 0.0, 0.0, f64::NAN, f64::NAN, 2e-4],
    );
    act.tendons[5] = TendonInput::Displacement {
        displacement: 2e-4,
        stiffness: 5e3,
    };
    act.reference_lengths = Some(zero);
    let sol = solve_statics(&base, &act, &o).unwrap();
    assert!(sol.tendon_tensions[0] > 0.0 && sol.tendon_tensions[5] > 0.0);
    let t = tangent_compliance(&sol, TendonControl::Actuated, None).unwrap();
    let h = [1e-4, 1e-4, 1e-4, 1e-5, 1e-5, 1e-5];
    for k in 0..6 {
        let solve = |sign: f64| {
            let mut f = Vector3::zeros();
            let mut m = Vector3::zeros();
            if k < 3 {
                f[k] = sign * h[k];
            } else {
                m[k - 3] = sign * h[k];
            }
            let loads = Loads {
                tip_force: f,
                tip_moment: m,
                ..Default::default()
            };
            let model = base.with_loads(loads).unwrap();
            let mut opts = o;
            opts.newton.tolerance = 1e-12;
            solve_statics(&model, &act, &opts).unwrap()
        };
        let (up, down) = (solve(1.0), solve(-1.0));
        let n = up.s.len() - 1;
        let dp = Vector3::from(up.position[n]) - Vector3::from(down.position[n]);
        let col = t.world.column(k);
        let scale = col.amax();
        for r in 0..3 {
            let fd = dp[r] / (2.0 * h[k]);
            assert!(
                (fd - col[r]).abs() <= 1e-6 * scale,
                "column {k} row {r}: {fd:e} vs {:e}",
                col[r]
            );
        }
        for i in [0, 5] {
            let rate = (up.tendon_tensions[i] - down.tendon_tensions[i]) / (2.0 * h[k]);
            let exact = t.tension_rate[i][k];
            // Per tendon, relative to its largest rate per unit force (N/N) or moment.
            let scale = (0..6)
                .map(|c| t.tension_rate[i][c].abs() * if c < 3 { 1.0 } else { 1e-1 })
                .fold(0.0, f64::max)
                * if k < 3 { 1.0 } else { 10.0 };
            assert!(
                (rate - exact).abs() <= 1e-6 * scale,
                "tension rate of tendon {i} per wrench component {k}: {rate:e} vs {exact:e}"
            );
        }
    }
}

/// The sensitivities of a displacement-controlled equilibrium (held tendons respond) against
/// central differences: per displacement, per tension of a tension-controlled tendon, per
/// stiffness factor.
#[test]
fn held_sensitivities_match_central_differences() {
    use softrod::{sensitivities, Linearisation, Parameter};
    let o = SolveOptions {
        newton: softrod::NewtonOptions {
            tolerance: 1e-12,
            ..options().newton
        },
        ..options()
    };
    let model = niti(
        Loads {
            gravity: Vector3::new(0.0, -9.81, 0.0),
            ..Default::default()
        },
        Some(6450.0),
    );
    let zero = reference_lengths(&model, &o).unwrap();
    let act = |d0: f64, t4: f64| {
        let mut a = Actuation::mixed(
            &[0.0, 0.0, 0.0, 0.3, t4, 0.0],
            &[d0, -5e-3, 2e-4, f64::NAN, f64::NAN, 1e-4],
        );
        a.reference_lengths = Some(zero.clone());
        a
    };
    let sol = solve_statics(&model, &act(1e-3, 1.0), &o).unwrap();
    println!("{:?}", sol.tendon_tensions);
    assert!(sol.tendon_tensions[0] > 0.0 && sol.tendon_tensions[1] == 0.0);
    let params = [
        Parameter::Displacement(0),
        Parameter::Tension(4),
        Parameter::Displacement(1),
    ];
    let n = sol.s.len() - 1;
    let sens = sensitivities(&sol, &params, &[n], Linearisation::Actuated).unwrap();
    // A slack tendon's displacement changes nothing.
    assert!(sens.pose[0].column(2).amax() == 0.0);
    for (j, h) in [(0, 1e-6), (1, 1e-4)] {
        let (up, down) = if j == 0 {
            (act(1e-3 + h, 1.0), act(1e-3 - h, 1.0))
        } else {
            (act(1e-3, 1.0 + h), act(1e-3, 1.0 - h))
        };
        let (up, down) = (
            solve_statics(&model, &up, &o).unwrap(),
            solve_statics(&model, &down, &o).unwrap(),
        );
        let dp = Vector3::from(up.position[n]) - Vector3::from(down.position[n]);
        let col = sens.pose[0].column(j);
        for r in 0..3 {
            let fd = dp[r] / (2.0 * h);
            assert!(
                (fd - col[r]).abs() <= 1e-6 * col.amax(),
                "{:?} row {r}: {fd:e} vs {:e}",
                params[j],
                col[r]
            );
        }
        let fd = (up.tendon_tensions[0] - down.tendon_tensions[0]) / (2.0 * h);
        let exact = sens.tendon_tensions[(0, j)];
        assert!((fd - exact).abs() <= 1e-6 * exact.abs(), "{fd} vs {exact}");
    }
}
