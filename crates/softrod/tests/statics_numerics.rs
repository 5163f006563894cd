//! Numerical properties of the statics solver: RK4 convergence order, the adaptive
//! integrator's tolerance, warm starts, the two-segment robot's accuracy at the default step
//! count, frames of tip loads, and inspection of non-converged results.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use std::f64::consts::PI;

use softrod::integrate::AdaptiveOptions;
use softrod::nalgebra::{Matrix3, Vector3};
use softrod::{
    solve_statics, Actuation, Error, Frame, Integrator, LinearElastic, Loads, Material, PointLoad,
    RobotModel, Rod, Routing, Section, SolveOptions, StaticsSolution,
};

fn rk4(steps: usize) -> SolveOptions {
    SolveOptions {
        integrator: Integrator::Rk4 { steps },
        newton: softrod::NewtonOptions {
            tolerance: 1e-13,
            ..SolveOptions::default().newton
        },
        ..Default::default()
    }
}

fn adaptive(rtol: f64) -> SolveOptions {
    SolveOptions {
        integrator: Integrator::Adaptive(AdaptiveOptions {
            rtol,
            atol: rtol * 1e-3,
            max_steps: 1_000_000,
        }),
        newton: softrod::NewtonOptions {
            tolerance: 1e-13,
            ..SolveOptions::default().newton
        },
        ..Default::default()
    }
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The two-segment NiTi robot of the benchmark.
/// A 3-D test problem: tapered soft rod, helical tendon ending mid-way, tip force.
fn helix_problem() -> (Rod, Vec<common::Tensioned>, Loads) {
    let rod = Rod::new(
        0.3,
        Section::tapered_circular(0.004, 0.0025).unwrap(),
        LinearElastic::new(2e6, 0.45).unwrap(),
    )
    .unwrap();
    let t = common::tendon_with(
        Routing::Helical {
            radius: 0.002,
            pitch: 0.25,
            phase: 0.0,
        },
        0.3,
        Some(0.2),
    )
    .unwrap();
    (
        rod,
        vec![t],
        Loads::tip_force(Vector3::new(0.0, 0.01, -0.005)),
    )
}

#[test]
fn rk4_converges_with_order_four() {
    let (rod, tendons, loads) = helix_problem();
    let reference = common::solve(&rod, &tendons, &loads, &adaptive(1e-13)).unwrap();
    let r = reference.tip_position();
    // Asymptotic range (at 10 steps the tendon's helix is resolved by 8 points per turn).
    let errors: Vec<f64> = [20, 40, 80, 160]
        .iter()
        .map(|&n| {
            dist(
                common::solve(&rod, &tendons, &loads, &rk4(n))
                    .unwrap()
                    .tip_position(),
                r,
            )
        })
        .collect();
    println!("RK4 tip errors for 20, 40, 80, 160 steps: {errors:?}");
    for w in errors.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((3.7..4.3).contains(&order), "observed order {order}");
    }
    // The tendon path length converges too.
    let lt = common::solve(&rod, &tendons, &loads, &rk4(80))
        .unwrap()
        .tendon_lengths[0];
    assert!(
        (lt - reference.tendon_lengths[0]).abs() < 1e-9,
        "{lt} {}",
        reference.tendon_lengths[0]
    );
}

#[test]
fn adaptive_integrator_meets_its_tolerance() {
    let (rod, tendons, loads) = helix_problem();
    let reference = common::solve(&rod, &tendons, &loads, &rk4(4000)).unwrap();
    let r = reference.tip_position();
    for rtol in [1e-6, 1e-8, 1e-10] {
        let sol = common::solve(&rod, &tendons, &loads, &adaptive(rtol)).unwrap();
        let e = dist(sol.tip_position(), r) / rod.length();
        println!(
            "rtol {rtol:e}: tip error {e:.2e} L, {} samples, {} evaluations",
            sol.s.len(),
            sol.stats.function_evaluations
        );
        assert!(e < rtol, "rtol {rtol}: error {e} L");
        assert!(sol.stats.converged);
    }
}

#[test]
fn two_segment_robot_default_options_are_accurate() {
    let rod = common::niti_rod();
    let tendons = common::niti_tendons(&[4.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    let tight = common::solve(&rod, &tendons, &Loads::default(), &adaptive(1e-12)).unwrap();
    let sol = common::solve(&rod, &tendons, &Loads::default(), &SolveOptions::default()).unwrap();
    let e = dist(sol.tip_position(), tight.tip_position());
    println!(
        "two-segment robot: tip {:?}, error {e:.2e} m",
        sol.tip_position()
    );
    assert!(e < 1e-7, "{e}");
    // Both segments bend; the tendon ending at 0.2 m leaves the second segment with the
    // curvature of the 2 N tendon alone: |u| = 2 N * 10 mm / EI.
    let ei = 54e9 * PI * 0.7e-3f64.powi(4) / 4.0;
    let last = sol.u.last().unwrap();
    let k2 = (last[0].powi(2) + last[1].powi(2)).sqrt();
    assert!((k2 - 2.0 * 0.01 / ei).abs() < 1e-9 * k2, "{k2}");
    let first = sol.u[1];
    let k1 = (first[0].powi(2) + first[1].powi(2)).sqrt();
    // 4 N at 90 deg and 2 N at -30 deg: |4 e(90) + 2 e(-30)| = sqrt(12) N.
    assert!((k1 - 12f64.sqrt() * 0.01 / ei).abs() < 1e-9 * k1, "{k1}");
}

/// A warm start reaches the cold solution with less work. The work is counted in right-hand
/// sides: a loaded solve iterates on a coarse mesh first (a fifth of the cost per iteration)
/// and finishes on the mesh asked, so its iteration count mixes the two meshes.
#[test]
fn warm_start_reaches_the_cold_solution_with_fewer_evaluations() {
    let rod = common::niti_rod();
    let loads = Loads::tip_force(Vector3::new(0.05, -0.02, 0.0));
    let a = common::solve(
        &rod,
        &common::niti_tendons(&[4.0, 0.0, 0.0, 0.0, 2.0, 0.0]),
        &loads,
        &rk4(40),
    )
    .unwrap();
    let changed = common::niti_tendons(&[4.08, 0.0, 0.0, 0.0, 2.04, 0.0]);
    let cold = common::solve(&rod, &changed, &loads, &rk4(40)).unwrap();
    let warm_opts = SolveOptions {
        warm_start: Some(a.warm_start()),
        ..rk4(40)
    };
    let warm = common::solve(&rod, &changed, &loads, &warm_opts).unwrap();
    println!(
        "iterations: cold {}, warm {}; evaluations: cold {}, warm {}",
        cold.stats.iterations,
        warm.stats.iterations,
        cold.stats.function_evaluations,
        warm.stats.function_evaluations
    );
    assert!(dist(cold.tip_position(), warm.tip_position()) < 1e-12);
    assert!(warm.stats.function_evaluations < cold.stats.function_evaluations);
}

fn rot(sol: &StaticsSolution, i: usize) -> Matrix3<f64> {
    Matrix3::from_fn(|r, c| sol.rotation[i][r][c])
}

#[test]
fn body_frame_tip_load_is_the_world_load_rotated() {
    let (rod, tendons, _) = helix_problem();
    let f = Vector3::new(0.01, 0.02, -0.01);
    let m = Vector3::new(0.0, 1e-3, 5e-4);
    let world = Loads {
        tip_force: f,
        tip_moment: m,
        ..Default::default()
    };
    let a = common::solve(&rod, &tendons, &world, &rk4(100)).unwrap();
    let rl = rot(&a, a.s.len() - 1);
    let body = Loads {
        tip_force: rl.transpose() * f,
        tip_moment: rl.transpose() * m,
        tip_frame: Frame::Body,
        ..Default::default()
    };
    let b = common::solve(&rod, &tendons, &body, &rk4(100)).unwrap();
    assert!(dist(a.tip_position(), b.tip_position()) < 1e-12);
    // Quaternions are unit, scalar last, and agree with the rotation matrices.
    for i in 0..a.s.len() {
        let q = a.quaternion[i];
        let uq = softrod::nalgebra::UnitQuaternion::from_quaternion(
            softrod::nalgebra::Quaternion::new(q[3], q[0], q[1], q[2]),
        );
        assert!((uq.to_rotation_matrix().matrix() - rot(&a, i)).amax() < 1e-12);
        assert!(q[3] >= 0.0);
        let r = rot(&a, i);
        assert!((r.transpose() * r - Matrix3::identity()).amax() < 1e-13);
    }
}

#[test]
fn internal_wrench_is_consistent_with_strains_and_frames() {
    let (rod, tendons, loads) = helix_problem();
    let sol = common::solve(&rod, &tendons, &loads, &rk4(60)).unwrap();
    let e: f64 = 2e6;
    let g = e / (2.0 * 1.45);
    let k = rod.shear_coefficient();
    for i in 0..sol.s.len() {
        let props = rod.section_at(sol.s[i]);
        let (v, u) = (sol.v[i], sol.u[i]);
        let nb = sol.n_body[i];
        let mb = sol.m_body[i];
        // n = K_se (v - v*), m = K_bt (u - u*), in body components.
        let tol = 1e-9;
        assert!(
            (nb[2] - e * props.area * (v[2] - 1.0)).abs() < tol * (1.0 + nb[2].abs()),
            "s = {}: n_z {} vs EA (v_z - 1) {}",
            sol.s[i],
            nb[2],
            e * props.area * (v[2] - 1.0)
        );
        assert!((nb[0] - k * g * props.area * v[0]).abs() < tol * (1.0 + nb[0].abs()));
        assert!((mb[0] - e * props.ix * u[0]).abs() < tol * (1.0 + mb[0].abs()));
        assert!((mb[2] - g * props.j * u[2]).abs() < tol * (1.0 + mb[2].abs()));
        let r = rot(&sol, i);
        let nw = r * Vector3::from(nb);
        assert!((nw - Vector3::from(sol.n_world[i])).amax() < 1e-14);
    }
    // Beyond the termination at 0.2 m only the tip force acts: n = F.
    let last = sol.n_world.last().unwrap();
    assert!((Vector3::from(*last) - loads.tip_force).amax() < 1e-12);
}

#[test]
fn non_convergence_is_an_error_or_an_inspectable_result() {
    let rod = Rod::new(
        0.3,
        Section::circular(0.002).unwrap(),
        LinearElastic::new(5e6, 0.3).unwrap(),
    )
    .unwrap()
    .with_inextensible(true);
    let loads = Loads::tip_force(Vector3::new(0.5, 0.0, 0.0)); // alpha ~ 1.4e2: hard
    let opts = SolveOptions {
        newton: softrod::NewtonOptions {
            max_iterations: 2,
            continuation: false,
            ..SolveOptions::default().newton
        },
        ..Default::default()
    };
    match common::solve(&rod, &[], &loads, &opts) {
        Err(Error::NotConverged {
            iterations,
            residual,
            ..
        }) => {
            assert!(iterations <= 2);
            assert!(residual > opts.newton.tolerance && residual.is_finite());
        }
        other => panic!("expected NotConverged, got {other:?}"),
    }
    let sol = common::solve(
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
    )
    .unwrap();
    assert!(!sol.stats.converged);
    assert!(sol.stats.residual > opts.newton.tolerance);
    assert_eq!(sol.s.len(), sol.position.len());
    assert!(!sol.s.is_empty());
}

#[test]
fn tendon_termination_applies_point_force_and_moment() {
    // At s = 0.2 m the 4 N tendon ends. Across it the rod's internal wrench jumps by that
    // tendon's point force -tau t and moment -(R r) x tau t (Rucker & Webster 2011), with t its
    // unit tangent R (v + u x r) / |v + u x r| just before the end; and, since the curvature
    // jumps there, the 2 N tendon that continues has a kink in its path and adds the point
    // force tau (t+ - t-) of a tensioned string over a kink (its distributed load -tau t'
    // integrated across the jump).
    let rod = common::niti_rod();
    let tendons = common::niti_tendons(&[4.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    let loads = Loads::tip_force(Vector3::new(0.02, 0.01, 0.0));
    let sol = common::solve(&rod, &tendons, &loads, &rk4(40)).unwrap();
    let i = sol.s.iter().position(|&s| s == 0.2).unwrap();
    assert_eq!(sol.s[i + 1], 0.2);
    let r = rot(&sol, i);
    assert_eq!(r, rot(&sol, i + 1));
    let tangent = |j: usize, off: &Vector3<f64>| {
        let w = Vector3::from(sol.v[j]) + Vector3::from(sol.u[j]).cross(off);
        r * w.normalize()
    };
    let r0 = Vector3::new(0.0, 0.01, 0.0); // 4 N tendon at 90 degrees, ends here
    let a4 = (-30.0f64).to_radians();
    let r4 = Vector3::new(0.01 * a4.cos(), 0.01 * a4.sin(), 0.0); // 2 N tendon, continues
    let f0 = -tangent(i, &r0) * 4.0;
    let kink = (tangent(i + 1, &r4) - tangent(i, &r4)) * 2.0;
    let f = f0 + kink;
    let m = (r * r0).cross(&f0) + (r * r4).cross(&kink);
    let dn = Vector3::from(sol.n_world[i]) - Vector3::from(sol.n_world[i + 1]);
    let dm = Vector3::from(sol.m_world[i]) - Vector3::from(sol.m_world[i + 1]);
    println!("jump: point force {f0:?}, kink force {kink:?}");
    assert!((dn - f).amax() < 1e-12, "{dn:?} vs {f:?}");
    assert!((dm - m).amax() < 1e-14, "{dm:?} vs {m:?}");
    assert_eq!(sol.position[i], sol.position[i + 1]);
}

/// A soft neo-Hookean cantilever under a tip force with a zero point load (a break): the local
/// section solve must converge where the curvature passes zero (its round-off floor is that of
/// the fibre strain, not of the curvature in 1/m), and RK4 and adaptive agree on the tip.
#[test]
fn section_solve_converges_where_the_curvature_vanishes() {
    let rod = Rod::new(
        0.5,
        Section::circular(0.00625).unwrap(),
        Material::Hyperelastic(softrod::NeoHookean::new(1e4).unwrap().into()),
    )
    .unwrap();
    for at in [0.25, 0.4] {
        let mut loads = Loads::tip_force(Vector3::new(1e-3, 0.0, 0.0));
        loads
            .point_loads
            .push(PointLoad::new(at, Vector3::zeros(), Vector3::zeros(), Frame::World).unwrap());
        let model = RobotModel::rod_only(rod.clone(), loads).unwrap();
        let adaptive = SolveOptions {
            integrator: Integrator::Adaptive(AdaptiveOptions {
                rtol: 1e-10,
                atol: 1e-12,
                ..Default::default()
            }),
            ..Default::default()
        };
        let reference = solve_statics(&model, &Actuation::default(), &adaptive).unwrap();
        let sol = solve_statics(&model, &Actuation::default(), &SolveOptions::default()).unwrap();
        for s in [&sol, &reference] {
            assert!(s.stats.converged);
            assert!(s.v.iter().chain(&s.u).flatten().all(|c| c.is_finite()));
            // Force balance: the base carries the tip force.
            assert!(
                (s.base_wrench[0] - 1e-3).abs() < 1e-12,
                "{:?}",
                s.base_wrench
            );
        }
        let (a, b) = (sol.tip_position(), reference.tip_position());
        let d = (Vector3::from(a) - Vector3::from(b)).norm();
        assert!(d < 1e-5 * 0.5, "point load at {at}: tip {a:?} vs {b:?}");
    }
}

/// A soft tapered rod hanging in gravity (0.35 m, 1e5 Pa, radius 4.9 to 1.6 mm, 1100 kg/m³,
/// gravity along its axis) pulled sideways by a 0.05 N tendon at 0.96 mm: its weight's tension
/// over its bending stiffness (`L √(T / EI)` about 18) makes the tip moment of a march about
/// 5e7 times as sensitive to the base moment, so that the residual of a march cannot fall
/// below its round-off (about 1e-6 here, against a tolerance of 1e-10).
fn hanging_soft_rod() -> (std::sync::Arc<RobotModel>, Actuation) {
    let rod = Rod::new(
        0.35,
        Section::tapered_circular(4.9e-3, 1.6e-3).unwrap(),
        LinearElastic::new(1e5, 0.45).unwrap(),
    )
    .unwrap()
    .with_density(1100.0)
    .unwrap();
    let tendons = [0.0f64, 2.094, 4.189]
        .iter()
        .map(|a| softrod::Tendon::constant([0.96e-3 * a.cos(), 0.96e-3 * a.sin()], None).unwrap())
        .collect();
    let loads = Loads {
        gravity: Vector3::new(0.0, 0.0, 9.81),
        ..Default::default()
    };
    let model = RobotModel::new(rod, tendons, Vec::new(), loads).unwrap();
    (model, Actuation::tensions(&[0.05, 0.0, 0.0]))
}

#[test]
fn a_rod_whose_residual_is_bounded_by_round_off_converges_at_fourth_order() {
    // Newton stops where its exact step is below the rounding of the unknowns: the answers
    // on 40 to 320 RK4 steps, each stopped at its round-off, still converge with RK4's order.
    let (model, act) = hanging_soft_rod();
    let tips: Vec<[f64; 3]> = [40, 80, 160, 320]
        .iter()
        .map(|&steps| {
            let opts = SolveOptions {
                integrator: Integrator::Rk4 { steps },
                ..Default::default()
            };
            let sol = solve_statics(&model, &act, &opts).unwrap();
            assert!(sol.stats.converged, "{steps} steps: {:?}", sol.stats);
            if steps == 40 {
                // Above the tolerance asked: converged at the round-off of the march.
                assert!(sol.stats.residual > 1e-9, "{:?}", sol.stats);
            }
            sol.tip_position()
        })
        .collect();
    let d: Vec<f64> = tips.windows(2).map(|w| dist(w[0], w[1])).collect();
    println!("tip differences 40-80, 80-160, 160-320 steps: {d:?}");
    for w in d.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((3.7..4.3).contains(&order), "observed order {order}: {d:?}");
    }
}
