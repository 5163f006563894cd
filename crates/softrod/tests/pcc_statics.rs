//! PCC statics against independent oracles: the Cosserat engine (exact arcs without external
//! load, and under a tip moment about the bending axis), the segment-averaged internal moment
//! integrated along the backbone, central finite differences of the equilibrium equations,
//! the Euler–Bernoulli cantilever, the pneumatic closed form, and rotation invariance.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use std::f64::consts::PI;

use softrod::nalgebra::{Matrix3, Vector3};
use softrod::pcc::statics::{
    pcc_equilibrium, solve_pcc_statics, PccLoads, PccRobot, PccSolveOptions, RoutedTendon,
};
use softrod::pcc::{arc_from_pressures, ElasticSegment, PccChambers, PccSegment, PccTendons};
use softrod::{
    Error, Integrator, LinearElastic, Loads, Rod, Section, SolveOptions, StaticsSolution,
};

// The two-segment NiTi robot of the issue.
const NITI_E: f64 = 54e9;
const NITI_NU: f64 = 0.3;
const NITI_R: f64 = 0.0007;
const SEG: f64 = 0.2;
const OFFSET: f64 = 0.01;
const ANGLES_DEG: [f64; 3] = [90.0, -30.0, 210.0];
const TENSIONS: [f64; 6] = [4.0, 0.0, 0.0, 0.0, 2.0, 0.0];

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

fn niti_pcc(extensible: bool) -> PccRobot {
    let body = ElasticSegment::solid_circle(SEG, NITI_R, NITI_E, extensible).unwrap();
    let angles: Vec<f64> = ANGLES_DEG.iter().map(|a| a.to_radians()).collect();
    let tendons = PccTendons::new(&[OFFSET; 3], &angles).unwrap();
    PccRobot::new(vec![body, body])
        .unwrap()
        .with_segment_tendons(0, &tendons)
        .unwrap()
        .with_segment_tendons(1, &tendons)
        .unwrap()
}

fn niti_cosserat(extensible: bool, tensions: &[f64]) -> (Rod, Vec<common::Tensioned>) {
    let rod = Rod::new(
        2.0 * SEG,
        Section::circular(NITI_R).unwrap(),
        LinearElastic::new(NITI_E, NITI_NU).unwrap(),
    )
    .unwrap()
    .with_inextensible(!extensible);
    let tendons = (0..6)
        .map(|i| {
            let b = ANGLES_DEG[i % 3].to_radians();
            let end = if i < 3 { Some(SEG) } else { None };
            common::tendon([OFFSET * b.cos(), OFFSET * b.sin()], tensions[i], end).unwrap()
        })
        .collect();
    (rod, tendons)
}

fn tip_rotation(s: &StaticsSolution) -> Matrix3<f64> {
    let r = s.rotation.last().unwrap();
    Matrix3::from_fn(|i, j| r[i][j])
}

fn pcc_tip(sol: &softrod::pcc::statics::PccStaticsSolution) -> (Vector3<f64>, Matrix3<f64>) {
    let t = sol.tip_pose;
    (
        Vector3::new(t[(0, 3)], t[(1, 3)], t[(2, 3)]),
        t.fixed_view::<3, 3>(0, 0).into_owned(),
    )
}

#[test]
fn unloaded_tendon_segment_is_the_cosserat_arc_exactly() {
    // Derivation (Rucker & Webster's model): with no external load the total wrench vanishes
    // along the rod, so the rod carries m_b = -Σ τ r_i × t_i. For u = (u_x, u_y, 0) and
    // v = (0, 0, 1 + ε), u × r_i is along z, so every tendon tangent is t_i = z and
    // m_b = Σ τ d (-sin β, cos β, 0): constant, hence an exact arc with E I u = Σ τ d (...)
    // per *undeformed* length and ε = -Σ τ / E A. The PCC energy model gives the same.
    let (l, r, e) = (0.3, 0.002, 2e9);
    let tendons = PccTendons::new(&[0.004, 0.006, 0.005], &[0.3, 2.5, -1.9]).unwrap();
    let tensions = [1.5, 0.4, 0.9];
    for extensible in [false, true] {
        let body = ElasticSegment::solid_circle(l, r, e, extensible).unwrap();
        let robot = PccRobot::new(vec![body])
            .unwrap()
            .with_segment_tendons(0, &tendons)
            .unwrap();
        let loads = PccLoads {
            tensions: tensions.to_vec(),
            ..Default::default()
        };
        let pcc = solve_pcc_statics(&robot, &loads, &PccSolveOptions::default()).unwrap();
        assert_eq!(pcc.stats.iterations, 0, "the actuator-only start is exact");
        let rod = Rod::new(
            l,
            Section::circular(r).unwrap(),
            LinearElastic::new(e, 0.3).unwrap(),
        )
        .unwrap()
        .with_inextensible(!extensible);
        let ts: Vec<common::Tensioned> = (0..3)
            .map(|i| {
                let (d, b) = (tendons.distances()[i], tendons.angles()[i]);
                common::tendon([d * b.cos(), d * b.sin()], tensions[i], None).unwrap()
            })
            .collect();
        let cos = common::solve(&rod, &ts, &Loads::default(), &rk4(400)).unwrap();
        let (p, rot) = pcc_tip(&pcc);
        let pc = Vector3::from(cos.tip_position());
        let dp = (p - pc).norm() / l;
        let dr = (rot - tip_rotation(&cos)).amax();
        // Curvature per undeformed length: u_cosserat = θ / ℓ0.
        let seg = pcc.segments[0];
        let u_pcc = seg.curvature_vector() * seg.length() / l;
        let du = cos
            .u
            .iter()
            .map(|u| (Vector3::from(*u) - u_pcc).norm())
            .fold(0.0, f64::max)
            / u_pcc.norm();
        let dl = (pcc.tendon_lengths[0] - cos.tendon_lengths[0]).abs() / l;
        println!(
            "extensible={extensible}: |Δp|/L {dp:.2e}, |ΔR| {dr:.2e}, |Δu|/|u| {du:.2e}, \
             |ΔL_tendon|/L {dl:.2e}"
        );
        assert!(dp < 1e-9 && dr < 1e-9 && du < 1e-9 && dl < 1e-9);
    }
}

#[test]
fn unloaded_two_segment_niti_robot_matches_cosserat_exactly() {
    // Segment 2's tendon passes through segment 1 and loads it: segment 1 bends under both
    // tendons' moments, segment 2 under its own only. Both models give exact arcs.
    for extensible in [false, true] {
        let robot = niti_pcc(extensible);
        let loads = PccLoads {
            tensions: TENSIONS.to_vec(),
            ..Default::default()
        };
        let pcc = solve_pcc_statics(&robot, &loads, &PccSolveOptions::default()).unwrap();
        let (rod, ts) = niti_cosserat(extensible, &TENSIONS);
        let cos = common::solve(&rod, &ts, &Loads::default(), &rk4(400)).unwrap();
        let (p, rot) = pcc_tip(&pcc);
        let dp = (p - Vector3::from(cos.tip_position())).norm() / (2.0 * SEG);
        let dr = (rot - tip_rotation(&cos)).amax();
        let dl = pcc
            .tendon_lengths
            .iter()
            .zip(&cos.tendon_lengths)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        // Backbone at the junction.
        let j = cos.s.iter().position(|&s| s == SEG).unwrap();
        let pj = pcc.segments[0].tip_position();
        let dj = (pj - Vector3::from(cos.position[j])).norm();
        println!(
            "NiTi extensible={extensible}: tip {p:?}, |Δp|/L {dp:.2e}, |ΔR| {dr:.2e}, \
             junction {dj:.2e} m, tendon lengths {dl:.2e} m"
        );
        assert!(dp < 1e-9 && dr < 1e-9 && dj < 1e-9 * SEG && dl < 1e-9 * SEG);
        // Segment 1 carries both tendons' moments: τ1 d e(90°) + τ5 d e(-30°).
        let ei = NITI_E * PI * NITI_R.powi(4) / 4.0;
        let m1 = Vector3::new(
            -4.0 * OFFSET * (90f64).to_radians().sin() - 2.0 * OFFSET * (-30f64).to_radians().sin(),
            4.0 * OFFSET * (90f64).to_radians().cos() + 2.0 * OFFSET * (-30f64).to_radians().cos(),
            0.0,
        );
        let s1 = pcc.segments[0];
        let th1 = s1.curvature_vector() * s1.length();
        assert!((th1 - m1 * SEG / ei).norm() < 1e-12 * th1.norm());
    }
}

#[test]
fn tip_moment_about_the_bending_axis_is_exact() {
    // A tendon at 90° bends about body x; a tip moment along world x keeps the internal moment
    // constant along the arc (R(s)ᵀ M = M for rotations about x): an exact arc in both models.
    let (l, r, e) = (0.25, 0.0015, 5e9);
    let body = ElasticSegment::solid_circle(l, r, e, false).unwrap();
    let ei = body.bending_stiffness();
    let robot = PccRobot::new(vec![body])
        .unwrap()
        .with_tendon(RoutedTendon::new(0.005, PI / 2.0, 0).unwrap())
        .unwrap();
    let (tau, m) = (2.0, 0.004);
    let loads = PccLoads {
        tensions: vec![tau],
        tip_moment: Vector3::new(-m, 0.0, 0.0),
        ..Default::default()
    };
    let pcc = solve_pcc_statics(&robot, &loads, &PccSolveOptions::default()).unwrap();
    let theta = (tau * 0.005 + m) * l / ei; // about -x
    let seg = pcc.segments[0];
    assert!((seg.bending_angle() - theta).abs() < 1e-12 * theta);
    assert!((seg.plane_angle() - PI / 2.0).abs() < 1e-12);
    let rod = Rod::new(
        l,
        Section::circular(r).unwrap(),
        LinearElastic::new(e, 0.3).unwrap(),
    )
    .unwrap()
    .with_inextensible(true);
    let t = common::tendon([0.0, 0.005], tau, None).unwrap();
    let cos = common::solve(&rod, &[t], &Loads::tip_moment(loads.tip_moment), &rk4(400)).unwrap();
    let (p, _) = pcc_tip(&pcc);
    let dp = (p - Vector3::from(cos.tip_position())).norm() / l;
    println!("tip moment: θ {theta:.6} rad, |Δp|/L vs Cosserat {dp:.2e}");
    assert!(dp < 1e-9);
}

/// A robot with every kind of actuator, mixed extensibility, and a load.
fn mixed_robot() -> (PccRobot, PccLoads) {
    let b0 = ElasticSegment::new(0.15, 0.02, Some(400.0)).unwrap();
    let b1 = ElasticSegment::new(0.12, 0.015, None).unwrap();
    let b2 = ElasticSegment::new(0.1, 0.01, Some(250.0)).unwrap();
    let robot = PccRobot::new(vec![b0, b1, b2])
        .unwrap()
        .with_segment_tendons(0, &PccTendons::equally_spaced(3, 0.008, 0.2).unwrap())
        .unwrap()
        .with_tendon(RoutedTendon::new(0.007, 1.1, 2).unwrap())
        .unwrap()
        .with_tendon(RoutedTendon::new(0.006, -2.0, 1).unwrap())
        .unwrap()
        .with_chambers(2, PccChambers::equally_spaced(3, 2e-5, 0.004, 0.5).unwrap())
        .unwrap();
    let loads = PccLoads {
        tensions: vec![0.9, 0.0, 0.3, 1.2, 0.7],
        pressures: vec![3e4, 0.0, 1e4],
        tip_force: Vector3::new(0.3, -0.5, 0.2),
        tip_moment: Vector3::new(0.02, 0.01, -0.03),
    };
    (robot, loads)
}

const Q_TEST: [[f64; 3]; 3] = [[3.0, -2.0, 0.151], [-4.0, 1.5, 0.12], [6.0, 5.0, 0.099]];

#[test]
fn equilibrium_jacobian_matches_central_differences() {
    let (robot, loads) = mixed_robot();
    for q in [
        Q_TEST,
        [[0.0, 0.0, 0.15], [0.0, 1e-3, 0.12], [20.0, -9.0, 0.1]],
    ] {
        let eq = pcc_equilibrium(&robot, &loads, &q).unwrap();
        let mut worst = 0.0f64;
        for col in 0..9 {
            let h = 1e-6 * if col % 3 == 2 { 0.1 } else { 10.0 };
            let (mut qp, mut qm) = (q, q);
            qp[col / 3][col % 3] += h;
            qm[col / 3][col % 3] -= h;
            let gp = pcc_equilibrium(&robot, &loads, &qp).unwrap().residual;
            let gm = pcc_equilibrium(&robot, &loads, &qm).unwrap().residual;
            let fd = (gp - gm) / (2.0 * h);
            for row in 0..9 {
                let scale = eq.jacobian.row(row).amax().max(1e-12);
                worst = worst.max((fd[row] - eq.jacobian[(row, col)]).abs() / scale);
            }
        }
        println!("Jacobian vs central differences: worst relative error {worst:.2e}");
        assert!(worst < 1e-6);
    }
}

/// Composite Simpson over `[0, 1]` with `n` (even) panels.
fn simpson(f: impl Fn(f64) -> Vector3<f64>, n: usize) -> Vector3<f64> {
    let h = 1.0 / n as f64;
    let mut sum = f(0.0) + f(1.0);
    for i in 1..n {
        sum += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * (h / 3.0)
}

#[test]
fn tip_load_generalized_force_is_the_segment_mean_internal_wrench() {
    // Independent of the Jacobian code: integrate the internal moment and force of the tip
    // load, m(s) = M + (p_tip - p(s)) × F, n(s) = F, in body components along each arc
    // (frames from pcc::PccChain), and average over the segment.
    let (robot, loads) = mixed_robot();
    let unloaded = PccLoads {
        tip_force: Vector3::zeros(),
        tip_moment: Vector3::zeros(),
        ..loads.clone()
    };
    let g1 = pcc_equilibrium(&robot, &loads, &Q_TEST).unwrap().residual;
    let g0 = pcc_equilibrium(&robot, &unloaded, &Q_TEST)
        .unwrap()
        .residual;
    let segs: Vec<PccSegment> = Q_TEST
        .iter()
        .map(|q| PccSegment::from_curvature_vector(q[0], q[1], q[2]).unwrap())
        .collect();
    let chain = softrod::pcc::PccChain::new(segs.clone()).unwrap();
    let tip = chain.tip_pose();
    let p_tip = Vector3::new(tip[(0, 3)], tip[(1, 3)], tip[(2, 3)]);
    let (f, m) = (loads.tip_force, loads.tip_moment);
    let mut start = 0.0;
    for (i, seg) in segs.iter().enumerate() {
        let l = seg.length();
        let mean = |want_moment: bool| {
            simpson(
                |t| {
                    let fr = chain.pose_at(start + t * l).unwrap();
                    let r = fr.fixed_view::<3, 3>(0, 0).into_owned();
                    let p = Vector3::new(fr[(0, 3)], fr[(1, 3)], fr[(2, 3)]);
                    if want_moment {
                        r.transpose() * (m + (p_tip - p).cross(&f))
                    } else {
                        r.transpose() * f
                    }
                },
                2000,
            )
        };
        let (mb, nb) = (mean(true), mean(false));
        // Residual difference in θ = ℓ u coordinates: g_u = (ℓ g_a, ℓ g_b, u_x g_a + u_y g_b + g_ℓ).
        let q = Q_TEST[i];
        let d = &g0 - &g1; // = +Q_ext (the load enters with a minus sign)
        let (qa, qb) = (d[3 * i] / l, d[3 * i + 1] / l);
        let ql = d[3 * i + 2] - q[0] * qa - q[1] * qb;
        // δθ = ℓ0 δũ: the generalized force on θ is the mean body moment (x, y).
        let err_m = (qa - mb.x).abs().max((qb - mb.y).abs()) / mb.norm();
        println!(
            "segment {i}: Q_θ ({qa:.9}, {qb:.9}) vs mean m_b ({:.9}, {:.9}), rel {err_m:.1e}",
            mb.x, mb.y
        );
        assert!(err_m < 1e-10);
        if robot.segments()[i].axial_stiffness().is_some() {
            let err_n = (ql - nb.z).abs() / nb.norm();
            println!(
                "segment {i}: Q_ℓ {ql:.9} vs mean n_b,z {:.9}, rel {err_n:.1e}",
                nb.z
            );
            assert!(err_n < 1e-10);
        }
        start += l;
    }
}

#[test]
fn small_tip_force_gives_exact_tip_rotation_and_three_quarter_deflection() {
    // Linearised: E I θ / L = mean of F (L - s) = F L / 2, so θ = F L² / (2 E I) (exact beam
    // tip rotation) and δ = θ L / 2 = F L³ / (4 E I), 3/4 of Euler-Bernoulli's F L³ / (3 E I).
    let (l, ei) = (0.3, 0.05);
    let robot = PccRobot::new(vec![ElasticSegment::new(l, ei, None).unwrap()]).unwrap();
    let f = 1e-6;
    let loads = PccLoads {
        tip_force: Vector3::new(f, 0.0, 0.0),
        ..Default::default()
    };
    let sol = solve_pcc_statics(&robot, &loads, &PccSolveOptions::default()).unwrap();
    let (p, r) = pcc_tip(&sol);
    let rot = r[(0, 2)].atan2(r[(2, 2)]);
    let rot_beam = f * l * l / (2.0 * ei);
    let defl_beam = f * l.powi(3) / (3.0 * ei);
    println!(
        "small force: rotation / beam {:.8}, deflection / beam {:.8}",
        rot / rot_beam,
        p.x / defl_beam
    );
    assert!((rot / rot_beam - 1.0).abs() < 1e-6);
    assert!((p.x / defl_beam - 0.75).abs() < 1e-6);
}

#[test]
fn pressures_match_the_closed_form_map() {
    let chambers = PccChambers::equally_spaced(3, 3e-5, 0.006, 0.4).unwrap();
    let p = [4e4, 1e4, 0.0];
    for extensible in [false, true] {
        let body = ElasticSegment::solid_circle(0.2, 0.012, 3e5, extensible).unwrap();
        let robot = PccRobot::new(vec![body])
            .unwrap()
            .with_chambers(0, chambers.clone())
            .unwrap();
        let loads = PccLoads {
            pressures: p.to_vec(),
            ..Default::default()
        };
        let sol = solve_pcc_statics(&robot, &loads, &PccSolveOptions::default()).unwrap();
        let map = arc_from_pressures(&p, &chambers, &body).unwrap();
        let seg = sol.segments[0];
        // Same length and bending plane; the map's κ is per deformed length (moment / E I),
        // this model's per undeformed length: κ_map = κ (1 + ε).
        let stretch = seg.length() / body.rest_length();
        assert!((seg.length() - map.length()).abs() < 1e-14);
        assert!((seg.plane_angle() - map.plane_angle()).abs() < 1e-12);
        assert!((seg.curvature() * stretch - map.curvature()).abs() < 1e-12 * map.curvature());
        assert_eq!(extensible, stretch > 1.0);
    }
}

#[test]
fn rotating_actuators_and_load_about_the_base_axis_rotates_the_solution() {
    let alpha: f64 = 0.7;
    let rz = Matrix3::new(
        alpha.cos(),
        -alpha.sin(),
        0.0,
        alpha.sin(),
        alpha.cos(),
        0.0,
        0.0,
        0.0,
        1.0,
    );
    let build = |shift: f64| {
        let angles: Vec<f64> = ANGLES_DEG.iter().map(|a| a.to_radians() + shift).collect();
        let t = PccTendons::new(&[OFFSET; 3], &angles).unwrap();
        let body = ElasticSegment::solid_circle(SEG, NITI_R, NITI_E, true).unwrap();
        PccRobot::new(vec![body, body])
            .unwrap()
            .with_segment_tendons(0, &t)
            .unwrap()
            .with_segment_tendons(1, &t)
            .unwrap()
    };
    let loads = PccLoads {
        tensions: TENSIONS.to_vec(),
        tip_force: Vector3::new(0.2, -0.1, 0.05),
        tip_moment: Vector3::new(0.001, 0.0, 0.002),
        ..Default::default()
    };
    let rotated = PccLoads {
        tip_force: rz * loads.tip_force,
        tip_moment: rz * loads.tip_moment,
        ..loads.clone()
    };
    let a = solve_pcc_statics(&build(0.0), &loads, &PccSolveOptions::default()).unwrap();
    let b = solve_pcc_statics(&build(alpha), &rotated, &PccSolveOptions::default()).unwrap();
    let (pa, ra) = pcc_tip(&a);
    let (pb, rb) = pcc_tip(&b);
    let err = (rz * pa - pb)
        .norm()
        .max((rz * ra * rz.transpose() - rb).amax());
    println!("rotation invariance: {err:.2e}");
    assert!(err < 1e-12);
}

#[test]
fn pcc_and_cosserat_diverge_as_the_tip_load_grows() {
    // The table of the documentation (printed with --nocapture; the example
    // `pcc_vs_cosserat` prints the same rows). Both models are exact arcs without load; the
    // PCC error grows with the load while the load is small compared with the tendons'
    // (here up to 0.1 N, which already moves the tip by 200 mm), then saturates as both
    // robots align with the force. Both solvers follow the load path (warm starts): large
    // loads admit several equilibria.
    let robot = niti_pcc(true);
    let (rod, ts) = niti_cosserat(true, &TENSIONS);
    let mut previous = -1.0;
    let mut warm = None;
    let mut warm_pcc = None;
    let mut p0 = Vector3::zeros();
    println!("| F_y (N) | PCC tip (mm) | Cosserat tip (mm) | |Δ| (mm) | |Δ| / tip motion |");
    for f in [0.0, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0] {
        let force = Vector3::new(0.0, -f, 0.0);
        let pcc = solve_pcc_statics(
            &robot,
            &PccLoads {
                tensions: TENSIONS.to_vec(),
                tip_force: force,
                ..Default::default()
            },
            &PccSolveOptions {
                warm_start: warm_pcc.take(),
                ..Default::default()
            },
        )
        .unwrap();
        warm_pcc = Some(pcc.warm_start());
        let opts = SolveOptions {
            warm_start: warm,
            ..rk4(400)
        };
        let cos = common::solve(&rod, &ts, &Loads::tip_force(force), &opts).unwrap();
        warm = Some(cos.warm_start());
        let (p, _) = pcc_tip(&pcc);
        let pc = Vector3::from(cos.tip_position());
        if f == 0.0 {
            p0 = pc;
        }
        let d = (p - pc).norm();
        let motion = (pc - p0).norm();
        println!(
            "| {f:.3} | ({:.2}, {:.2}, {:.2}) | ({:.2}, {:.2}, {:.2}) | {:.3} | {:.3} |",
            p.x * 1e3,
            p.y * 1e3,
            p.z * 1e3,
            pc.x * 1e3,
            pc.y * 1e3,
            pc.z * 1e3,
            d * 1e3,
            if motion > 0.0 { d / motion } else { 0.0 }
        );
        if f == 0.0 {
            assert!(d < 1e-9 * 2.0 * SEG);
        }
        if f <= 0.1 {
            assert!(d > previous, "divergence grows with the load");
        }
        previous = d;
    }
}

#[test]
fn non_convergence_is_reported_or_returned() {
    let robot = niti_pcc(true);
    let loads = PccLoads {
        tensions: TENSIONS.to_vec(),
        tip_force: Vector3::new(0.0, -1.0, 0.0),
        ..Default::default()
    };
    let d = PccSolveOptions::default();
    let opts = PccSolveOptions {
        newton: softrod::NewtonOptions {
            max_iterations: 1,
            continuation: false,
            ..d.newton
        },
        ..d
    };
    match solve_pcc_statics(&robot, &loads, &opts) {
        Err(Error::NotConverged { iterations, .. }) => assert_eq!(iterations, 1),
        other => panic!("expected NotConverged, got {other:?}"),
    }
    let sol = solve_pcc_statics(
        &robot,
        &loads,
        &PccSolveOptions {
            newton: softrod::NewtonOptions {
                throw: false,
                ..opts.newton
            },
            ..opts.clone()
        },
    )
    .unwrap();
    assert!(!sol.stats.converged && sol.stats.residual > 1e-12);
    // Continuation and warm starts converge.
    let full = solve_pcc_statics(&robot, &loads, &PccSolveOptions::default()).unwrap();
    assert!(full.stats.converged);
    let again = solve_pcc_statics(
        &robot,
        &loads,
        &PccSolveOptions {
            warm_start: Some(full.warm_start()),
            ..Default::default()
        },
    )
    .unwrap();
    assert!(again.stats.iterations <= 1);
}

fn name_of(e: Error) -> String {
    match e {
        Error::InvalidParameter { name, .. } => name,
        other => panic!("expected InvalidParameter, got {other:?}"),
    }
}

#[test]
fn invalid_inputs_name_the_parameter() {
    let robot = niti_pcc(true);
    let solve = |loads: PccLoads| {
        name_of(solve_pcc_statics(&robot, &loads, &PccSolveOptions::default()).unwrap_err())
    };
    assert_eq!(
        solve(PccLoads {
            tensions: vec![1.0; 5],
            ..Default::default()
        }),
        "tensions.len()"
    );
    assert_eq!(
        solve(PccLoads {
            tensions: vec![1.0, -1.0, 0.0, 0.0, 0.0, 0.0],
            ..Default::default()
        }),
        "tensions[1]"
    );
    assert_eq!(
        solve(PccLoads {
            pressures: vec![1.0],
            ..Default::default()
        }),
        "pressures.len()"
    );
    assert_eq!(
        solve(PccLoads {
            tip_force: Vector3::new(0.0, 0.0, f64::NAN),
            ..Default::default()
        }),
        "tip_force[2]"
    );
    assert_eq!(
        solve(PccLoads {
            tip_moment: Vector3::new(f64::INFINITY, 0.0, 0.0),
            ..Default::default()
        }),
        "tip_moment[0]"
    );
    // A huge tension compresses an extensible segment to nothing.
    assert_eq!(
        solve(PccLoads {
            tensions: vec![1e6, 0.0, 0.0, 0.0, 0.0, 0.0],
            ..Default::default()
        }),
        "tensions"
    );
    let opts = PccSolveOptions {
        warm_start: Some(vec![PccSegment::straight(0.2).unwrap()]),
        ..Default::default()
    };
    assert_eq!(
        name_of(solve_pcc_statics(&robot, &PccLoads::default(), &opts).unwrap_err()),
        "warm_start.len()"
    );
    let opts = PccSolveOptions {
        newton: softrod::NewtonOptions {
            tolerance: 0.0,
            ..PccSolveOptions::default().newton
        },
        ..Default::default()
    };
    assert_eq!(
        name_of(solve_pcc_statics(&robot, &PccLoads::default(), &opts).unwrap_err()),
        "tolerance"
    );
    let body = ElasticSegment::new(0.1, 1.0, None).unwrap();
    assert_eq!(
        name_of(
            PccRobot::new(vec![body])
                .unwrap()
                .with_tendon(RoutedTendon::new(0.01, 0.0, 1).unwrap())
                .unwrap_err()
        ),
        "last_segment"
    );
    assert_eq!(name_of(PccRobot::new(vec![]).unwrap_err()), "segments");
    assert_eq!(
        name_of(RoutedTendon::new(0.0, 0.0, 0).unwrap_err()),
        "distance"
    );
    assert_eq!(
        name_of(pcc_equilibrium(&robot, &PccLoads::default(), &[[0.0, 0.0, 0.2]]).unwrap_err()),
        "coordinates.len()"
    );
    assert_eq!(
        name_of(
            pcc_equilibrium(
                &robot,
                &PccLoads::default(),
                &[[0.0, 0.0, 0.2], [0.0, 0.0, -0.1]]
            )
            .unwrap_err()
        ),
        "coordinates[1].length"
    );
}
