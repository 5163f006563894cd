//! Bad input to the statics API returns `Error::InvalidParameter` naming the field; nothing
//! panics on user input.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use std::sync::Arc;

use softrod::nalgebra::{Matrix3, Vector3};
use softrod::{
    Error, Integrator, LinearElastic, Loads, PointLoad, Pose, Profile, Rod, Routing, Section,
    SectionProperties, SolveOptions, WarmStart,
};

fn name_of<T: std::fmt::Debug>(r: softrod::Result<T>) -> String {
    match r {
        Err(Error::InvalidParameter { name, .. }) => name,
        other => panic!("expected InvalidParameter, got {other:?}"),
    }
}

fn rod() -> Rod {
    Rod::new(
        0.3,
        Section::circular(0.002).unwrap(),
        LinearElastic::new(1e7, 0.3).unwrap(),
    )
    .unwrap()
}

#[test]
fn bad_geometry_and_moduli_are_named() {
    for r in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert_eq!(name_of(Section::circular(r)), "radius");
        assert_eq!(name_of(Section::tapered_circular(r, 0.01)), "base_radius");
        assert_eq!(name_of(Section::tapered_circular(0.01, r)), "tip_radius");
        assert_eq!(name_of(Section::tube(r, 0.0)), "outer_radius");
        assert_eq!(name_of(LinearElastic::new(r, 0.3)), "youngs_modulus");
        assert_eq!(
            name_of(Rod::new(
                r,
                Section::circular(0.01).unwrap(),
                LinearElastic::new(1.0, 0.3).unwrap()
            )),
            "length"
        );
        assert_eq!(name_of(rod().with_density(r)), "density");
        assert_eq!(
            name_of(rod().with_shear_coefficient(r)),
            "shear_coefficient"
        );
    }
    // A tube whose inner radius reaches (or passes) the outer one.
    for ri in [0.01, 0.02, -0.001, f64::NAN] {
        assert_eq!(name_of(Section::tube(0.01, ri)), "inner_radius");
    }
    for nu in [0.6, -1.0, f64::NAN] {
        assert_eq!(name_of(LinearElastic::new(1e6, nu)), "poisson_ratio");
    }
    assert_eq!(
        name_of(LinearElastic::with_shear_modulus(1e6, 1e5)),
        "shear_modulus"
    );
    assert_eq!(
        name_of(Section::table(
            &[0.0, 0.1],
            &[1e-6, -1e-6],
            &[1e-12; 2],
            &[1e-12; 2],
            &[2e-12; 2]
        )),
        "area[1]"
    );
    assert_eq!(
        name_of(Section::table(
            &[0.0, 0.0],
            &[1e-6; 2],
            &[1e-12; 2],
            &[1e-12; 2],
            &[2e-12; 2]
        )),
        "s[1]"
    );
    // A table that does not cover the rod.
    let short = Section::table(
        &[0.0, 0.1],
        &[1e-6; 2],
        &[1e-12; 2],
        &[1e-12; 2],
        &[2e-12; 2],
    )
    .unwrap();
    assert_eq!(
        name_of(Rod::new(0.3, short, LinearElastic::new(1e6, 0.3).unwrap())),
        "section.s"
    );
    // A user section that becomes negative.
    let f = Section::function(Arc::new(|s: f64| {
        let mut p = SectionProperties::circle(0.001, 0.0);
        p.area = 1e-6 - s * 1e-5;
        p
    }));
    assert!(name_of(Rod::new(0.3, f, LinearElastic::new(1e6, 0.3).unwrap())).ends_with(".area"));
    // NaN in a rest strain, a non-rotation base pose.
    assert_eq!(
        name_of(rod().with_rest_curvature(Profile::Constant(Vector3::new(0.0, f64::NAN, 0.0)))),
        "rest_curvature[1]"
    );
    assert_eq!(
        name_of(Pose::new(Vector3::zeros(), Matrix3::identity() * 2.0)),
        "base_pose.rotation"
    );
    assert_eq!(
        name_of(Pose::new(
            Vector3::new(f64::NAN, 0.0, 0.0),
            Matrix3::identity()
        )),
        "base_pose.position[0]"
    );
}

#[test]
fn bad_tendons_are_named() {
    // A tension is an actuation input, checked when solving with the tendon's index.
    for tension in [-1.0, f64::NAN] {
        let t = common::tendon([0.001, 0.0], tension, None).unwrap();
        assert_eq!(
            name_of(common::solve(
                &rod(),
                &[t],
                &Loads::default(),
                &SolveOptions::default()
            )),
            "tensions[0]"
        );
    }
    assert_eq!(
        name_of(common::tendon([0.001, f64::NAN], 1.0, None)),
        "offset[1]"
    );
    for end in [0.0, -0.1, f64::NAN] {
        assert_eq!(name_of(common::tendon([0.001, 0.0], 1.0, Some(end))), "end");
    }
    let helix = |pitch| {
        common::tendon_with(
            Routing::Helical {
                radius: 0.001,
                pitch,
                phase: 0.0,
            },
            1.0,
            None,
        )
    };
    assert_eq!(name_of(helix(0.0)), "pitch");
    assert_eq!(name_of(helix(f64::INFINITY)), "pitch");
    // A termination beyond the tip is caught when solving, with the tendon's index.
    let t = common::tendon([0.001, 0.0], 1.0, Some(0.31)).unwrap();
    let ok = common::tendon([0.001, 0.0], 1.0, None).unwrap();
    assert_eq!(
        name_of(common::solve(
            &rod(),
            &[ok, t],
            &Loads::default(),
            &SolveOptions::default()
        )),
        "tendons[1].end"
    );
    // A user routing that returns NaN.
    let bad = common::tendon_with(
        Routing::Function {
            offset: Arc::new(|s| [0.001, if s > 0.2 { f64::NAN } else { 0.0 }]),
            derivative: Arc::new(|_| [0.0, 0.0]),
        },
        1.0,
        None,
    )
    .unwrap();
    assert!(name_of(common::solve(
        &rod(),
        &[bad],
        &Loads::default(),
        &SolveOptions::default()
    ))
    .starts_with("tendons[0].offset"));
    // A constant offset is checked once, at s = 0: too far from the backbone, or beyond the
    // centre of a constant rest curvature (the tendon would run backwards).
    let far = common::tendon([0.31, 0.0], 1.0, Some(0.2)).unwrap();
    let solve = |r: &Rod, t| common::solve(r, &[t], &Loads::default(), &SolveOptions::default());
    assert_eq!(name_of(solve(&rod(), far)), "tendons[0].offset(0)");
    let curved = rod()
        .with_rest_curvature(Profile::Constant(Vector3::new(0.0, 10.0, 0.0)))
        .unwrap();
    let inside = common::tendon([0.11, 0.0], 1.0, None).unwrap();
    assert_eq!(name_of(solve(&curved, inside)), "tendons[0].offset(0)");
    let outside = common::tendon([-0.11, 0.0], 1.0, None).unwrap();
    assert!(
        softrod::RobotModel::new(curved, vec![outside.tendon], vec![], Loads::default()).is_ok()
    );
}

#[test]
fn bad_loads_and_options_are_named() {
    let solve = |loads: &Loads, opts: &SolveOptions| common::solve(&rod(), &[], loads, opts);
    let d = SolveOptions::default();
    let mut l = Loads::tip_force(Vector3::new(0.0, f64::NAN, 0.0));
    assert_eq!(name_of(solve(&l, &d)), "loads.tip_force[1]");
    l = Loads::tip_moment(Vector3::new(f64::INFINITY, 0.0, 0.0));
    assert_eq!(name_of(solve(&l, &d)), "loads.tip_moment[0]");
    l = Loads::default();
    l.point_loads.push(PointLoad::force(0.5, Vector3::x()));
    assert_eq!(name_of(solve(&l, &d)), "loads.point_loads[0].s");
    l = Loads::default();
    l.point_loads.push(PointLoad::force(0.0, Vector3::x()));
    assert_eq!(name_of(solve(&l, &d)), "loads.point_loads[0].s");
    l = Loads {
        gravity: Vector3::new(0.0, 0.0, -9.81),
        ..Default::default()
    };
    assert_eq!(name_of(solve(&l, &d)), "density");
    l = Loads {
        distributed_force: Some(Profile::Function(Arc::new(|s| {
            Vector3::new(0.0, if s > 0.1 { f64::NAN } else { 0.0 }, 0.0)
        }))),
        ..Default::default()
    };
    assert!(name_of(solve(&l, &d)).starts_with("loads.distributed_force("));
    let l = Loads::default();
    let o = SolveOptions {
        integrator: Integrator::Rk4 { steps: 0 },
        ..d
    };
    assert_eq!(name_of(solve(&l, &o)), "integrator.steps");
    let o = SolveOptions {
        integrator: Integrator::Rk4 { steps: usize::MAX },
        ..d
    };
    assert_eq!(name_of(solve(&l, &o)), "integrator.steps");
    let o = SolveOptions {
        newton: softrod::NewtonOptions {
            tolerance: f64::NAN,
            ..d.newton
        },
        ..d
    };
    assert_eq!(name_of(solve(&l, &o)), "tolerance");
    let o = SolveOptions {
        newton: softrod::NewtonOptions {
            max_iterations: 0,
            ..d.newton
        },
        ..d
    };
    assert_eq!(name_of(solve(&l, &o)), "max_iterations");
    let o = SolveOptions {
        warm_start: Some(WarmStart::wrench([0.0, 0.0, f64::NAN, 0.0, 0.0, 0.0])),
        ..d
    };
    assert_eq!(name_of(solve(&l, &o)), "warm_start.base_wrench[2]");
    let o = SolveOptions {
        integrator: Integrator::Adaptive(softrod::integrate::AdaptiveOptions {
            rtol: -1.0,
            ..Default::default()
        }),
        ..d
    };
    assert_eq!(name_of(solve(&l, &o)), "rtol");
}

#[test]
fn extreme_inputs_never_panic() {
    // Enormous tensions (the tendon path folds back), loads, stiffnesses and tiny step counts:
    // each returns a result, a convergence error, or (beyond the load limit) a named error.
    for e in [1e-6, 1.0, 1e12, 1e300] {
        for tau in [0.0, 1e-9, 1.0, 1e6, 1e15] {
            for f in [0.0, 1e-3, 1e3, 1e12] {
                let material = match LinearElastic::new(e, 0.3) {
                    Ok(m) => m,
                    Err(err) => {
                        // Beyond softrod::limits::MAX_MODULUS: a named error, not a solve.
                        assert_eq!(name_of::<()>(Err(err)), "youngs_modulus");
                        assert!(e > softrod::limits::MAX_MODULUS);
                        continue;
                    }
                };
                let rod = Rod::new(0.3, Section::circular(0.002).unwrap(), material).unwrap();
                let t = common::tendon([0.0015, 0.0], tau, Some(0.2)).unwrap();
                let loads = Loads::tip_force(Vector3::new(f, 0.0, -f));
                let opts = SolveOptions {
                    integrator: Integrator::Rk4 { steps: 3 },
                    newton: softrod::NewtonOptions {
                        max_load_steps: 4,
                        max_iterations: 5,
                        ..SolveOptions::default().newton
                    },
                    ..Default::default()
                };
                let r = common::solve(&rod, &[t], &loads, &opts);
                if let Ok(sol) = &r {
                    assert!(sol.stats.converged);
                }
                let r2 = common::solve(
                    &rod,
                    &[],
                    &loads,
                    &SolveOptions {
                        newton: softrod::NewtonOptions {
                            throw: false,
                            ..opts.newton
                        },
                        ..opts
                    },
                );
                // Loads beyond softrod::limits::MAX_LOAD_NUMBER are refused by name.
                let refused = |r: &softrod::Result<_>| {
                    matches!(r, Err(Error::InvalidParameter { name, .. })
                        if name.starts_with("loads.") || name.starts_with("tensions["))
                };
                assert!(r.is_ok() || matches!(r, Err(Error::NotConverged { .. })) || refused(&r));
                assert!(
                    r2.is_ok() || matches!(r2, Err(Error::NotConverged { .. })) || refused(&r2)
                );
                let number =
                    f * 2f64.sqrt() * 0.09 / (e * std::f64::consts::PI * 0.002f64.powi(4) / 4.0);
                assert_eq!(refused(&r2), number > softrod::limits::MAX_LOAD_NUMBER);
            }
        }
    }
}

/// A rod compressed to or through zero length is refused by name, not returned converged: an
/// axial tip force of 1.5 `E A` gives a linear law the stretch `v₃ = 1 - F/(E A) = -0.5` (the
/// rod inverted through its base), and a tip held at the base leaves it a point (`v₃ = 0`).
/// Half of `E A` is an answer (`v₃ = 0.5` exactly, the closed form of the linear law).
#[test]
fn a_rod_compressed_through_zero_length_is_refused_by_name() {
    let r = rod();
    let ea = 1e7 * std::f64::consts::PI * 0.002f64.powi(2);
    let axial = |f: f64| {
        let m = Arc::new(
            softrod::RobotModel::rod_only(r.clone(), Loads::tip_force(Vector3::new(0.0, 0.0, f)))
                .unwrap(),
        );
        softrod::solve_statics(&m, &softrod::Actuation::default(), &SolveOptions::default())
    };
    let half = axial(-0.5 * ea).unwrap();
    for v in &half.v {
        assert!((v[2] - 0.5).abs() < 1e-12, "stretch {}", v[2]);
    }
    assert_eq!(name_of(axial(-1.5 * ea)), "loads");
    let m = Arc::new(softrod::RobotModel::rod_only(r, Loads::default()).unwrap());
    let pinned = softrod::solve_constrained(
        &m,
        &softrod::Actuation::default(),
        &SolveOptions::default(),
        Some(&softrod::TipConstraint::pin([0.0; 3]).unwrap()),
        &[],
    );
    assert_eq!(name_of(pinned), "tip_constraint");
}

/// One tendon pulled with the rod's axial stiffness `E A` (computed here, as a user would, so
/// it may differ from the core's `1 / c` in the last place), or so little below it that the
/// stretch left is below the least accepted, compresses the rod to zero length: refused
/// naming the tension, on the axis and off it, as for any larger tension; 0.9 `E A` is an
/// answer on the axis (stretch `1 - τ / (E A)`).
#[test]
fn a_tendon_pulled_with_the_axial_stiffness_is_named() {
    let ea = 1e7 * std::f64::consts::PI * 0.002f64.powi(2);
    let solve = |offset: f64, tension: f64| {
        let tendon = softrod::Tendon::constant([offset, 0.0], None).unwrap();
        let m =
            softrod::RobotModel::new(rod(), vec![tendon], Vec::new(), Loads::default()).unwrap();
        softrod::solve_statics(
            &m,
            &softrod::Actuation::tensions(&[tension]),
            &SolveOptions::default(),
        )
    };
    // `E A`, one unit in the last place below it, 1e-12 below it (a stretch under the least
    // accepted, 1e-9) and above it.
    let below = f64::from_bits(ea.to_bits() - 1);
    for offset in [0.0, 1e-4, 5e-4] {
        for tension in [ea, below, (1.0 - 1e-12) * ea, 1.5 * ea] {
            assert_eq!(
                name_of(solve(offset, tension)),
                "tensions[0]",
                "{tension} N"
            );
        }
    }
    let near = solve(0.0, 0.9 * ea).unwrap();
    for v in &near.v {
        assert!((v[2] - 0.1).abs() < 1e-12, "stretch {}", v[2]);
    }
}

/// A tendon pulled hard enough to bend the rod tighter than its own distance from the
/// backbone has no equilibrium: its path `p' = v + u × r` would turn back on itself
/// (`u d >= v₃`). It was a bare `ConvergenceError` ("the actuated rod without external loads
/// could not be integrated"); the solve names the tension, on a rod that can stretch and one
/// that cannot, with the limit `τ* = v₃ E I / d²` (`v₃ = 1 - τ / (E A)`). Below it, the
/// single straight tendon's closed form: a constant curvature `τ d / (E I)`.
#[test]
fn a_tendon_that_would_bend_the_rod_inside_its_own_offset_is_named() {
    let (e, radius, d) = (1e7, 0.002, 0.01);
    let area = std::f64::consts::PI * radius * radius;
    let ei = e * area * radius * radius / 4.0;
    for inextensible in [true, false] {
        let solve = |tension: f64| {
            let tendon = softrod::Tendon::constant([d, 0.0], None).unwrap();
            let rod = rod().with_inextensible(inextensible);
            let m =
                softrod::RobotModel::new(rod, vec![tendon], Vec::new(), Loads::default()).unwrap();
            softrod::solve_statics(
                &m,
                &softrod::Actuation::tensions(&[tension]),
                &SolveOptions::default(),
            )
        };
        // The limit: τ d² / (E I) = v₃.
        let limit = if inextensible {
            ei / (d * d)
        } else {
            1.0 / (d * d / ei + 1.0 / (e * area))
        };
        for factor in [1.01, 2.0, 10.0] {
            match solve(factor * limit) {
                Err(Error::InvalidParameter { name, expected, .. }) => {
                    assert_eq!(name, "tensions[0]");
                    assert!(expected.contains("radius of curvature"), "{expected}");
                    println!("{factor} x the limit: {expected}");
                }
                other => panic!("{factor} x the limit, inextensible {inextensible}: {other:?}"),
            }
        }
        let tension = 0.9 * limit;
        let sol = solve(tension).unwrap();
        for u in &sol.u {
            let exact = tension * d / ei;
            assert!(
                (u[1].abs() - exact).abs() <= 1e-10 * exact,
                "{u:?} vs {exact}"
            );
        }
    }
}

/// A user routing's derivative is checked against the offset it goes with: a helix whose
/// derivative forgot the chain rule's `2 pi / pitch`, or has the wrong sign, is refused naming
/// `tendons[0].derivative(s)`; the exact one passes, and so does a routing with a kink at a
/// check point (mid-length) whose derivative is one of the kink's one-sided slopes.
#[test]
fn a_user_routing_whose_derivative_is_not_its_offsets_is_named() {
    let (radius, pitch) = (1e-3, 0.05);
    let w = 2.0 * std::f64::consts::PI / pitch;
    let helix = move |scale: f64| {
        common::tendon_with(
            Routing::Function {
                offset: Arc::new(move |s| [radius * (w * s).cos(), radius * (w * s).sin()]),
                derivative: Arc::new(move |s| {
                    [
                        -scale * radius * (w * s).sin(),
                        scale * radius * (w * s).cos(),
                    ]
                }),
            },
            1.0,
            None,
        )
        .unwrap()
    };
    let solve = |t| common::solve(&rod(), &[t], &Loads::default(), &SolveOptions::default());
    assert!(solve(helix(w)).is_ok());
    for wrong in [1.0, -w, 1.01 * w] {
        let name = name_of(solve(helix(wrong)));
        assert!(name.starts_with("tendons[0].derivative"), "{wrong}: {name}");
    }
    // A kink at s = L/2 (a check point): the offset moves out at slope 0.002 after it.
    let half = 0.15;
    let kinked = common::tendon_with(
        Routing::Function {
            offset: Arc::new(move |s| [1e-3 + 2e-3 * (s - half).max(0.0), 0.0]),
            derivative: Arc::new(move |s| [if s < half { 0.0 } else { 2e-3 }, 0.0]),
        },
        1.0,
        None,
    )
    .unwrap();
    assert!(solve(kinked).is_ok());
}

/// Absurd values are named as themselves: a density of 1e30 kg/m³ was blamed on
/// `loads.gravity` (its load number), a chamber area of 1e30 m² on `chambers[0].pressure`, and
/// a tolerance of 1 or more was accepted (a residual as large as the loads counted as
/// converged: a tip 11 % of the length off the solve at the default tolerance).
#[test]
fn an_absurd_density_chamber_area_or_tolerance_is_named_as_itself() {
    assert_eq!(name_of(rod().with_density(1e30)), "density");
    assert!(rod().with_density(2e4).is_ok());
    let chamber = softrod::Chamber::new(
        softrod::ChamberArea::Constant(1e30),
        [0.005, 0.0],
        0.0,
        None,
    )
    .unwrap();
    let name = name_of(softrod::RobotModel::new(
        rod(),
        Vec::new(),
        vec![chamber],
        Loads::default(),
    ));
    assert!(name.starts_with("chambers[0].area("), "{name}");
    let model = softrod::RobotModel::rod_only(
        rod(),
        Loads::tip_force(softrod::nalgebra::Vector3::new(0.01, 0.0, 0.0)),
    )
    .unwrap();
    for tolerance in [1.0, 1e30] {
        let mut o = SolveOptions::default();
        o.newton.tolerance = tolerance;
        let got = softrod::solve_statics(&model, &softrod::Actuation::default(), &o);
        assert_eq!(name_of(got), "tolerance", "{tolerance}");
    }
    let mut o = SolveOptions::default();
    o.newton.tolerance = 0.5;
    assert!(softrod::solve_statics(&model, &softrod::Actuation::default(), &o).is_ok());
}
