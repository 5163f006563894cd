//! Oracles of the configuration-dependent compliance: closed-form Timoshenko cantilever,
//! Castigliano on a stress-free circular arc (independent quadrature), frame consistency,
//! tangent compliance vs finite differences of the nonlinear solve, fixed-length tendons.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use common::{assert_blocks_close, castigliano_arc, timoshenko};

use std::f64::consts::PI;

use softrod::compliance::{compliance, tangent_compliance, TendonControl};
use softrod::math::se3::rotation_adjoint;
use softrod::math::so3::exp_so3;
use softrod::nalgebra::{Matrix3, Matrix6, Rotation3, Vector3, Vector6};
use softrod::{
    solve_statics, Integrator, LinearElastic, Loads, Pose, Profile, Rod, Section, SolveOptions,
    StaticsSolution,
};

const E: f64 = 2.0e9;
const NU: f64 = 0.3;
const RADIUS: f64 = 0.01;
const LENGTH: f64 = 0.5;

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

fn rot_of(sol: &StaticsSolution, i: usize) -> Matrix3<f64> {
    let r = &sol.rotation[i];
    Matrix3::new(
        r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1], r[2][2],
    )
}

fn section_constants(k: f64) -> (f64, f64, f64, f64) {
    common::circular_constants(E, NU, RADIUS, k)
}

#[test]
fn straight_cantilever_matches_timoshenko_closed_form() {
    let base = Pose::new(
        Vector3::new(0.3, -0.2, 1.0),
        exp_so3(&Vector3::new(0.4, -0.9, 0.3)),
    )
    .unwrap();
    let rod = Rod::new(
        LENGTH,
        Section::circular(RADIUS).unwrap(),
        LinearElastic::new(E, NU).unwrap(),
    )
    .unwrap()
    .with_base_pose(base);
    let sol = common::solve(&rod, &[], &Loads::default(), &rk4(40)).unwrap();
    let c = compliance(&sol).unwrap();
    let (ei, gj, ea, gas) = section_constants(rod.shear_coefficient());
    let exact = timoshenko(LENGTH, ei, gj, ea, Some(gas));
    assert_blocks_close(&c.tip_body(), &exact, 1e-10, "tip body");
    // World = body rotated by the tip rotation (the base rotation here).
    let ad = rotation_adjoint(&base.rotation());
    assert_blocks_close(
        &c.tip_world(),
        &(ad * exact * ad.transpose()),
        1e-10,
        "tip world",
    );
    // Every node: the cantilever of length s.
    for (i, &s) in c.s.iter().enumerate().skip(1) {
        let ex = timoshenko(s, ei, gj, ea, Some(gas));
        assert_blocks_close(&c.body[i], &ex, 1e-10, &format!("s = {s}"));
    }
}

#[test]
fn gamma_c_is_one_at_the_tip_without_shear() {
    let rod = Rod::new(
        LENGTH,
        Section::circular(RADIUS).unwrap(),
        LinearElastic::new(E, NU).unwrap(),
    )
    .unwrap()
    .with_inextensible(true);
    let sol = common::solve(&rod, &[], &Loads::default(), &rk4(40)).unwrap();
    let c = compliance(&sol).unwrap();
    let g = c.gamma_c.last().unwrap();
    assert!((g[0] - 1.0).abs() < 1e-12, "{g:?}");
    assert!((g[1] - 1.0).abs() < 1e-12, "{g:?}");
    assert!(g[2].abs() < 1e-15);
    // Along the arm gamma_c = (s/L)^3.
    for (i, &s) in c.s.iter().enumerate() {
        let e = (s / LENGTH).powi(3);
        assert!((c.gamma_c[i][0] - e).abs() < 1e-12);
    }
    // Without shear and stretch the compliance is singular: reported, not hidden.
    let (k, cond) = c.stiffness_world();
    assert!(cond.last().unwrap().is_infinite());
    assert!(k.last().unwrap()[(0, 0)].is_nan());
}

fn arc_rod(angle: f64) -> Rod {
    let kappa = angle / LENGTH;
    Rod::new(
        LENGTH,
        Section::circular(RADIUS).unwrap(),
        LinearElastic::new(E, NU).unwrap(),
    )
    .unwrap()
    .with_rest_curvature(Profile::Constant(Vector3::new(0.0, kappa, 0.0)))
    .unwrap()
}

#[test]
fn stress_free_arc_matches_castigliano() {
    for angle in [PI / 2.0, PI, 1.5 * PI] {
        let rod = arc_rod(angle);
        let sol = common::solve(&rod, &[], &Loads::default(), &rk4(2000)).unwrap();
        let c = compliance(&sol).unwrap();
        let (ei, gj, ea, gas) = section_constants(rod.shear_coefficient());
        let exact = castigliano_arc(angle / LENGTH, LENGTH, [gas, gas, ea, ei, ei, gj]);
        assert_blocks_close(&c.tip_world(), &exact, 1e-8, &format!("arc {angle}"));
    }
}

#[test]
fn compliance_is_under_tolerance_control_on_arcs_up_to_two_pi() {
    use softrod::compliance::compliance_at;
    use softrod::AdaptiveOptions;
    let (ei, gj, ea, gas) = section_constants(
        Rod::new(
            LENGTH,
            Section::circular(RADIUS).unwrap(),
            LinearElastic::new(E, NU).unwrap(),
        )
        .unwrap()
        .shear_coefficient(),
    );
    let stiff = [gas, gas, ea, ei, ei, gj];
    for angle in [PI / 2.0, PI, 1.5 * PI, 2.0 * PI] {
        let rod = arc_rod(angle);
        let kappa = angle / LENGTH;
        // Defaults (RK4 kinematics, compliance marched at COMPLIANCE_RTOL): <= 1e-6.
        let sol = common::solve(&rod, &[], &Loads::default(), &SolveOptions::default()).unwrap();
        let exact = castigliano_arc(kappa, LENGTH, stiff);
        let what = format!("defaults, arc {angle}");
        let marched = compliance_at(&sol, &sol.s).unwrap();
        assert_blocks_close(&marched.tip_world(), &exact, 1e-6, &what);
        // Output at chosen arc lengths (not mesh nodes): the sub-arc [0, s].
        let s_out = [0.3 * LENGTH, 0.77 * LENGTH];
        let c = compliance_at(&sol, &s_out).unwrap();
        assert_eq!(c.s, s_out);
        for (i, &s) in s_out.iter().enumerate() {
            let exact = castigliano_arc(kappa, s, stiff);
            assert_blocks_close(
                &c.world[i],
                &exact,
                1e-6,
                &format!("s_out {s}, arc {angle}"),
            );
        }
        // Adaptive: within 10 rtol.
        for rtol in [1e-6, 1e-8, 1e-10] {
            let opts = SolveOptions {
                integrator: Integrator::Adaptive(AdaptiveOptions {
                    rtol,
                    atol: rtol * 1e-2,
                    ..Default::default()
                }),
                ..Default::default()
            };
            let sol = common::solve(&rod, &[], &Loads::default(), &opts).unwrap();
            let what = format!("adaptive rtol {rtol}, arc {angle}");
            let got = compliance(&sol).unwrap().tip_world();
            assert_blocks_close(&got, &exact, 10.0 * rtol, &what);
        }
    }
}

#[test]
fn frames_are_related_by_the_adjoint_and_k_inverts_c() {
    let rod = common::niti_rod();
    let tendons = common::niti_tendons(&[4.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    let loads = Loads::tip_force(Vector3::new(0.05, -0.02, 0.0));
    let sol = common::solve(&rod, &tendons, &loads, &rk4(50)).unwrap();
    let c = compliance(&sol).unwrap();
    let (kw, cond) = c.stiffness_world();
    let kb = c.stiffness_body();
    assert!(cond[0].is_infinite() && kw[0][(0, 0)].is_nan());
    for i in 1..c.s.len() {
        assert!(cond[i].is_finite() && cond[i] > 1.0);
        let ad = rotation_adjoint(&rot_of(&sol, i));
        let w = ad * c.body[i] * ad.transpose();
        assert!((w - c.world[i]).amax() <= 1e-12 * c.world[i].amax());
        for (cm, km) in [(&c.world[i], &kw[i]), (&c.body[i], &kb[i])] {
            assert!((cm - cm.transpose()).amax() == 0.0);
            assert!(cm.symmetric_eigen().eigenvalues.min() > 0.0);
            // K C = I, columns scaled by units: compare K C with I entry-wise.
            let kc = km * cm;
            assert!(
                (kc - Matrix6::identity()).amax() < 1e-6,
                "{}",
                (kc - Matrix6::identity()).amax()
            );
        }
    }
}

/// Tip twist difference `[δp; δθ_world]` between two solutions.
fn tip_twist(a: &StaticsSolution, b: &StaticsSolution) -> Vector6<f64> {
    let n = a.s.len() - 1;
    let dp = Vector3::from(b.position[n]) - Vector3::from(a.position[n]);
    let dr = rot_of(b, n) * rot_of(a, n).transpose();
    let th = Rotation3::from_matrix_unchecked(dr).scaled_axis();
    Vector6::new(dp.x, dp.y, dp.z, th.x, th.y, th.z)
}

/// Central finite difference of the nonlinear solve (perturbing the world tip wrench),
/// Richardson-extrapolated over steps `h` and `h/2` (fourth order in the step).
fn fd_tip_compliance(
    rod: &Rod,
    tendons: &[common::Tensioned],
    loads: &Loads,
    opts: &SolveOptions,
    sol: &StaticsSolution,
    scale: &Matrix6<f64>,
) -> Matrix6<f64> {
    let central = |j: usize, eps: f64| {
        let mut plus = loads.clone();
        let mut minus = loads.clone();
        if j < 3 {
            plus.tip_force[j] += eps;
            minus.tip_force[j] -= eps;
        } else {
            plus.tip_moment[j - 3] += eps;
            minus.tip_moment[j - 3] -= eps;
        }
        // The derivative along the solution's branch: no search for another equilibrium
        // (the axial step of a straight rod compresses it past buckling).
        let o = SolveOptions {
            warm_start: Some(sol.warm_start()),
            seek_stable: false,
            ..*opts
        };
        let sp = common::solve(rod, tendons, &plus, &o).unwrap();
        let sm = common::solve(rod, tendons, &minus, &o).unwrap();
        tip_twist(&sm, &sp) / (2.0 * eps)
    };
    let mut c = Matrix6::zeros();
    for j in 0..6 {
        // Step: a twist of about 1e-3 of the rod length / 1e-3 rad.
        let eps = 1e-3
            * if j < 3 {
                LENGTH / scale[(j, j)]
            } else {
                1.0 / scale[(j, j)]
            };
        let (d1, d2) = (central(j, eps), central(j, 0.5 * eps));
        c.set_column(j, &((d2 * 4.0 - d1) / 3.0));
    }
    c
}

#[test]
fn unloaded_integrated_tangent_and_finite_difference_agree() {
    for angle in [0.0, PI / 2.0, PI] {
        let rod = arc_rod(angle);
        let opts = rk4(400);
        let loads = Loads::default();
        let sol = common::solve(&rod, &[], &loads, &opts).unwrap();
        let c = compliance(&sol).unwrap().tip_world();
        let t = tangent_compliance(&sol, TendonControl::Tension, None).unwrap();
        let fd = fd_tip_compliance(&rod, &[], &loads, &opts, &sol, &c);
        assert_blocks_close(
            &t.world,
            &c,
            1e-6,
            &format!("tangent vs integrated, arc {angle}"),
        );
        assert_blocks_close(&fd, &c, 1e-6, &format!("fd vs integrated, arc {angle}"));
    }
}

#[test]
fn loaded_tangent_matches_finite_difference() {
    let rod = common::niti_rod();
    let tendons = common::niti_tendons(&[4.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    let loads = Loads {
        tip_force: Vector3::new(0.3, -0.2, -0.1),
        tip_moment: Vector3::new(0.0, 0.002, 0.001),
        ..Default::default()
    };
    let opts = rk4(400);
    let sol = common::solve(&rod, &tendons, &loads, &opts).unwrap();
    let t = tangent_compliance(&sol, TendonControl::Tension, None).unwrap();
    let fd = fd_tip_compliance(&rod, &tendons, &loads, &opts, &sol, &t.world);
    assert_blocks_close(&t.world, &fd, 1e-6, "loaded tangent vs fd");
    // The paper's integrated compliance differs under load and actuation.
    let c = compliance(&sol).unwrap().tip_world();
    let rel = (c - t.world).amax() / t.world.amax();
    assert!(rel > 1e-3, "{rel}");
}

/// Tip pose of `model` under `tensions` plus an extra tip wrench `w` with the tendon path
/// lengths held at `lengths`: Newton on the tensions (finite-difference Jacobian of the
/// lengths in the tensions), each evaluation a full nonlinear solve.
fn held_length_tip(
    model: &std::sync::Arc<softrod::RobotModel>,
    tensions: &[f64],
    lengths: &[f64],
    w: [f64; 6],
    opts: &SolveOptions,
) -> ([f64; 3], [[f64; 3]; 3]) {
    let base = model.loads().clone();
    let loaded = model
        .with_loads(Loads {
            tip_force: base.tip_force + Vector3::new(w[0], w[1], w[2]),
            tip_moment: base.tip_moment + Vector3::new(w[3], w[4], w[5]),
            ..base
        })
        .unwrap();
    let n = tensions.len();
    let solve = |t: &[f64]| solve_statics(&loaded, &softrod::Actuation::tensions(t), opts).unwrap();
    let mut t = tensions.to_vec();
    for _ in 0..20 {
        let s = solve(&t);
        let r: Vec<f64> = (0..n).map(|i| s.tendon_lengths[i] - lengths[i]).collect();
        if r.iter().all(|v| v.abs() < 1e-15) {
            return (s.tip_position(), s.rotation[s.s.len() - 1]);
        }
        let h = 1e-6;
        let mut jac = softrod::nalgebra::DMatrix::zeros(n, n);
        for k in 0..n {
            let mut tp = t.clone();
            tp[k] += h;
            let sp = solve(&tp);
            for i in 0..n {
                jac[(i, k)] = (sp.tendon_lengths[i] - s.tendon_lengths[i]) / h;
            }
        }
        let dt = jac
            .lu()
            .solve(&softrod::nalgebra::DVector::from_vec(r))
            .unwrap();
        for k in 0..n {
            t[k] -= dt[k];
        }
    }
    let s = solve(&t);
    (s.tip_position(), s.rotation[s.s.len() - 1])
}

/// The fixed-length tangent compliance against its definition: central differences of the
/// tip pose under a small tip wrench, the tendon path lengths held by re-solving the
/// tensions (all tendons tensioned, so that none goes slack).
#[test]
fn fixed_length_tangent_matches_the_resolved_finite_difference() {
    let rod = common::niti_rod();
    let tendons = common::niti_tendons(&[4.0, 1.0, 1.5, 0.5, 2.0, 0.8]);
    let loads = Loads::tip_force(Vector3::new(0.02, -0.01, 0.0));
    let opts = rk4(200);
    let sol = common::solve(&rod, &tendons, &loads, &opts).unwrap();
    let t = tangent_compliance(&sol, TendonControl::Length, None).unwrap();
    let tensions = sol.tensions();
    let lengths = sol.tendon_lengths.clone();
    let mut fd = Matrix6::zeros();
    for j in 0..6 {
        let h = if j < 3 { 1e-4 } else { 1e-6 };
        let mut w = [0.0; 6];
        w[j] = h;
        let (pp, rp) = held_length_tip(&sol.model, &tensions, &lengths, w, &opts);
        w[j] = -h;
        let (pm, rm) = held_length_tip(&sol.model, &tensions, &lengths, w, &opts);
        let m = |a: [[f64; 3]; 3], b: [[f64; 3]; 3], i: usize, k: usize| {
            (0..3).map(|q| a[i][q] * b[k][q]).sum::<f64>()
        };
        for i in 0..3 {
            fd[(i, j)] = (pp[i] - pm[i]) / (2.0 * h);
        }
        fd[(3, j)] = 0.5 * (m(rp, rm, 2, 1) - m(rp, rm, 1, 2)) / (2.0 * h);
        fd[(4, j)] = 0.5 * (m(rp, rm, 0, 2) - m(rp, rm, 2, 0)) / (2.0 * h);
        fd[(5, j)] = 0.5 * (m(rp, rm, 1, 0) - m(rp, rm, 0, 1)) / (2.0 * h);
    }
    let err = (t.world - fd).amax() / t.world.amax();
    println!("fixed-length tangent vs re-solved finite difference: {err:e}");
    assert!(err < 1e-6, "relative error {err:e}");
}

/// More tendons held than the old eight-column limit: ten tendons at 36°, ending at 0.04 m
/// intervals (each holds its own stretch of the rod).
#[test]
fn ten_held_tendons_match_the_resolved_finite_difference() {
    let rod = common::niti_rod();
    let tendons: Vec<common::Tensioned> = (0..10)
        .map(|k| {
            let a = (36.0 * k as f64).to_radians();
            let end = Some(0.04 * (k + 1) as f64);
            common::tendon([0.01 * a.cos(), 0.01 * a.sin()], 0.5 + 0.1 * k as f64, end).unwrap()
        })
        .collect();
    let loads = Loads::tip_force(Vector3::new(0.02, -0.01, 0.0));
    let opts = rk4(200);
    let sol = common::solve(&rod, &tendons, &loads, &opts).unwrap();
    let t = tangent_compliance(&sol, TendonControl::Length, None).unwrap();
    let tensions = sol.tensions();
    let lengths = sol.tendon_lengths.clone();
    let mut fd = Matrix6::zeros();
    for j in 0..6 {
        let h = if j < 3 { 1e-4 } else { 1e-6 };
        let mut w = [0.0; 6];
        w[j] = h;
        let (pp, rp) = held_length_tip(&sol.model, &tensions, &lengths, w, &opts);
        w[j] = -h;
        let (pm, rm) = held_length_tip(&sol.model, &tensions, &lengths, w, &opts);
        let m = |a: [[f64; 3]; 3], b: [[f64; 3]; 3], i: usize, k: usize| {
            (0..3).map(|q| a[i][q] * b[k][q]).sum::<f64>()
        };
        for i in 0..3 {
            fd[(i, j)] = (pp[i] - pm[i]) / (2.0 * h);
        }
        fd[(3, j)] = 0.5 * (m(rp, rm, 2, 1) - m(rp, rm, 1, 2)) / (2.0 * h);
        fd[(4, j)] = 0.5 * (m(rp, rm, 0, 2) - m(rp, rm, 2, 0)) / (2.0 * h);
        fd[(5, j)] = 0.5 * (m(rp, rm, 1, 0) - m(rp, rm, 0, 1)) / (2.0 * h);
    }
    let err = (t.world - fd).amax() / t.world.amax();
    println!("fixed-length tangent vs re-solved finite difference: {err:e}");
    assert!(err < 1e-6, "relative error {err:e}");
}

/// Twist `[δp; δθ_world]` of the first node at arc length `s` between two solutions.
fn node_twist(a: &StaticsSolution, b: &StaticsSolution, s: f64) -> Vector6<f64> {
    let ia = a.s.iter().position(|&x| (x - s).abs() < 1e-12).unwrap();
    let ib = b.s.iter().position(|&x| (x - s).abs() < 1e-12).unwrap();
    let dp = Vector3::from(b.position[ib]) - Vector3::from(a.position[ia]);
    let dr = rot_of(b, ib) * rot_of(a, ia).transpose();
    let th = Rotation3::from_matrix_unchecked(dr).scaled_axis();
    Vector6::new(dp.x, dp.y, dp.z, th.x, th.y, th.z)
}

#[test]
fn interior_node_tangent_matches_finite_difference_of_a_point_load() {
    use softrod::PointLoad;
    let rod = common::niti_rod();
    let tendons = common::niti_tendons(&[4.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    let loads = Loads::tip_force(Vector3::new(0.1, 0.0, -0.05));
    let opts = rk4(400);
    let sol = common::solve(&rod, &tendons, &loads, &opts).unwrap();
    // A node inside segment 2 that is a mesh node of the perturbed problems too.
    let node = 300;
    let s = sol.s[node];
    let t = tangent_compliance(&sol, TendonControl::Tension, Some(node)).unwrap();
    assert_eq!(t.s, s);
    let mut fd = Matrix6::zeros();
    for j in 0..6 {
        let eps = 1e-3
            * if j < 3 {
                0.4 / t.world[(j, j)]
            } else {
                1.0 / t.world[(j, j)]
            };
        let central = |e: f64| {
            let mk = |sign: f64| {
                let mut l = loads.clone();
                let mut pl = PointLoad::force(s, Vector3::zeros());
                if j < 3 {
                    pl.force[j] = sign * e;
                } else {
                    pl.moment[j - 3] = sign * e;
                }
                l.point_loads.push(pl);
                let o = SolveOptions {
                    warm_start: Some(sol.warm_start()),
                    ..opts
                };
                common::solve(&rod, &tendons, &l, &o).unwrap()
            };
            node_twist(&mk(-1.0), &mk(1.0), s) / (2.0 * e)
        };
        fd.set_column(j, &((central(0.5 * eps) * 4.0 - central(eps)) / 3.0));
    }
    assert_blocks_close(&t.world, &fd, 1e-6, "interior node tangent vs fd");
}

#[test]
fn adaptive_tangent_matches_finite_difference() {
    use softrod::AdaptiveOptions;
    let rod = common::niti_rod();
    let tendons = common::niti_tendons(&[4.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    let loads = Loads::tip_force(Vector3::new(0.2, 0.1, 0.0));
    let opts = SolveOptions {
        integrator: Integrator::Adaptive(AdaptiveOptions {
            rtol: 1e-12,
            atol: 1e-14,
            ..Default::default()
        }),
        newton: softrod::NewtonOptions {
            tolerance: 1e-12,
            ..SolveOptions::default().newton
        },
        ..Default::default()
    };
    let sol = common::solve(&rod, &tendons, &loads, &opts).unwrap();
    let t = tangent_compliance(&sol, TendonControl::Tension, None).unwrap();
    let fd = fd_tip_compliance(&rod, &tendons, &loads, &opts, &sol, &t.world);
    assert_blocks_close(&t.world, &fd, 1e-6, "adaptive tangent vs fd");
    // The same tangent as RK4 with many steps (both converge to the exact one).
    let r = rk4(800);
    let sr = common::solve(&rod, &tendons, &loads, &r).unwrap();
    let tr = tangent_compliance(&sr, TendonControl::Tension, None).unwrap();
    assert_blocks_close(&t.world, &tr.world, 1e-6, "adaptive vs rk4 tangent");
}

#[test]
fn compliance_at_arc_lengths_in_any_order_with_repeats_is_the_sorted_one_rearranged() {
    // Invariance: each requested arc length is a stop of one march, so the answer at a point
    // does not depend on the order of the request or on repeats in it.
    use softrod::compliance::compliance_at;
    let rod = common::niti_rod();
    let tendons = common::niti_tendons(&[4.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    let loads = Loads::tip_force(Vector3::new(0.05, -0.02, 0.0));
    let sol = common::solve(&rod, &tendons, &loads, &SolveOptions::default()).unwrap();
    let length = rod.length();
    let sorted: Vec<f64> = (0..=200).map(|i| length * i as f64 / 200.0).collect();
    let base = compliance_at(&sol, &sorted).unwrap();
    // Reversed, every other point repeated, the ends and the break (0.2 m) again.
    let mut request: Vec<usize> = (0..=200).rev().collect();
    request.extend((0..=200).step_by(2));
    request.extend([0, 200, 100, 100]);
    let s_out: Vec<f64> = request.iter().map(|&i| sorted[i]).collect();
    let c = compliance_at(&sol, &s_out).unwrap();
    assert_eq!(c.s, s_out);
    for (k, &i) in request.iter().enumerate() {
        // The same set of stops: the same march, bit for bit.
        assert_eq!(c.world[k], base.world[i], "s = {}", s_out[k]);
        assert_eq!(c.body[k], base.body[i], "s = {}", s_out[k]);
    }
}
