//! Pneumatic chambers and hyperelastic rods against closed forms and independent laws: the
//! constant-curvature arc of one pressurised chamber, pure elongation under equal pressures,
//! the uniaxial hyperelastic stretch, the small-strain limit, exactness of the fibre section
//! for a linear law, and the errors.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use std::f64::consts::PI;

use softrod::nalgebra::Vector3;
use softrod::{
    ChamberArea, Error, Hookean, Integrator, LinearElastic, Loads, Material, MooneyRivlin,
    NeoHookean, Rod, Section, Silicone, SolveOptions, StaticsSolution, UniaxialLaw, UniaxialModel,
    Yeoh,
};

/// An arm like the compliance-methodology paper's: length, outer radius, chamber radius, chamber centroid distance (m).
const L: f64 = 0.16;
const R: f64 = 0.012;
const RC: f64 = 0.0025;
const D: f64 = 0.6 * R;

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

/// Angles of the six chambers: three pairs centred at 90°, 210°, 330°, ±25° within a pair.
fn angles() -> [f64; 6] {
    let mut a = [0.0; 6];
    for (i, c) in [90.0f64, 210.0, 330.0].iter().enumerate() {
        a[2 * i] = (c - 25.0).to_radians();
        a[2 * i + 1] = (c + 25.0).to_radians();
    }
    a
}

/// Solid section with the six chamber voids excluded: `(section, A0, I0)` (Ix = Iy = I0).
fn arm_section() -> (Section, f64, f64) {
    let ac = PI * RC * RC;
    let a0 = PI * R * R - 6.0 * ac;
    let mut ix = PI * R.powi(4) / 4.0;
    let mut iy = ix;
    for t in angles() {
        ix -= PI * RC.powi(4) / 4.0 + ac * (D * t.sin()).powi(2);
        iy -= PI * RC.powi(4) / 4.0 + ac * (D * t.cos()).powi(2);
    }
    assert!((ix - iy).abs() < 1e-12 * ix);
    let sec = Section::table(&[0.0, L], &[a0; 2], &[ix; 2], &[iy; 2], &[ix + iy; 2]).unwrap();
    (sec, a0, ix)
}

fn chambers(p: [f64; 6]) -> Vec<common::Pressurised> {
    angles()
        .iter()
        .zip(p)
        .map(|(t, p)| {
            common::constant_chamber(p, PI * RC * RC, [D * t.cos(), D * t.sin()]).unwrap()
        })
        .collect()
}

/// External loads and pressurised chambers.
struct Loaded {
    loads: Loads,
    chambers: Vec<common::Pressurised>,
}

fn with_chambers(chambers: Vec<common::Pressurised>) -> Loaded {
    Loaded {
        loads: Loads::default(),
        chambers,
    }
}

fn solve_p(rod: &Rod, l: &Loaded, opts: &SolveOptions) -> softrod::Result<StaticsSolution> {
    common::solve_with_chambers(rod, &[], &l.chambers, &l.loads, opts)
}

/// Tip of a rod of length `l` with constant strains `v = (0, 0, lambda)`, `u = (ux, uy, 0)`.
fn arc_tip(l: f64, lambda: f64, ux: f64, uy: f64) -> [f64; 3] {
    let k = ux.hypot(uy);
    let n = Vector3::new(ux / k, uy / k, 0.0);
    let side = n.cross(&Vector3::z());
    let p = (Vector3::z() * (k * l).sin() + side * (1.0 - (k * l).cos())) * (lambda / k);
    [p.x, p.y, p.z]
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn silicone_linear() -> LinearElastic {
    LinearElastic::new(300e3, 0.5).unwrap()
}

#[test]
fn one_chamber_bends_linear_arm_into_the_closed_form_arc() {
    let (sec, a0, i0) = arm_section();
    let e = 300e3;
    let rod = Rod::new(L, sec, silicone_linear()).unwrap();
    let ac = PI * RC * RC;
    for (k, p) in [(0usize, 20e3), (3, 50e3), (4, 80e3)] {
        let mut pr = [0.0; 6];
        pr[k] = p;
        let loads = with_chambers(chambers(pr));
        let sol = solve_p(&rod, &loads, &rk4(400)).unwrap();
        // Rod's own wrench: axial p A_c, moment p A_c r_c × (-e_z)... = p A_c (y, -x, 0).
        let t = angles()[k];
        let (x, y) = (D * t.cos(), D * t.sin());
        let f = p * ac;
        let (ux, uy, lambda) = (f * y / (e * i0), -f * x / (e * i0), 1.0 + f / (e * a0));
        for i in 0..sol.s.len() {
            assert!((sol.u[i][0] - ux).abs() < 1e-12 * ux.abs().max(1.0));
            assert!((sol.u[i][1] - uy).abs() < 1e-12 * uy.abs().max(1.0));
            assert!(sol.u[i][2].abs() < 1e-12);
            assert!((sol.v[i][2] - lambda).abs() < 1e-12);
            assert!(sol.v[i][0].abs() < 1e-12 && sol.v[i][1].abs() < 1e-12);
            assert!((sol.n_body[i][2] - f).abs() < 1e-12 * f);
        }
        // Self-equilibrated: no reaction at the base.
        assert!(sol.base_wrench.iter().all(|w| w.abs() < 1e-12));
        let tip = arc_tip(L, lambda, ux, uy);
        let err = dist(sol.tip_position(), tip);
        assert!(err < 1e-9, "p = {p}: tip error {err:e} m");
    }
}

#[test]
fn equal_pressures_only_elongate() {
    let (sec, a0, _) = arm_section();
    let rod = Rod::new(L, sec, silicone_linear()).unwrap();
    let p = 60e3;
    let sol = solve_p(&rod, &with_chambers(chambers([p; 6])), &rk4(100)).unwrap();
    let lambda = 1.0 + 6.0 * p * PI * RC * RC / (300e3 * a0);
    for u in &sol.u {
        assert!(u.iter().all(|c| c.abs() < 1e-12), "{u:?}");
    }
    let tip = sol.tip_position();
    assert!(tip[0].abs() < 1e-12 && tip[1].abs() < 1e-12);
    assert!((tip[2] - lambda * L).abs() < 1e-12);
}

#[test]
fn hyperelastic_elongation_matches_the_uniaxial_solution() {
    let (sec, a0, _) = arm_section();
    let ac = PI * RC * RC;
    for law in [
        UniaxialModel::from(Silicone::DragonSkin10.yeoh()),
        UniaxialModel::from(Silicone::Ecoflex0030.neo_hookean()),
        UniaxialModel::from(MooneyRivlin::new(40e3, 10e3).unwrap()),
    ] {
        let rod = Rod::new(L, sec.clone(), law.clone()).unwrap();
        for p in [10e3, 30e3, 60e3] {
            let sol = solve_p(&rod, &with_chambers(chambers([p; 6])), &rk4(50)).unwrap();
            let lambda = law.stretch_from_axial_force(a0, 6.0 * p * ac).unwrap();
            let tip = sol.tip_position();
            assert!(
                (tip[2] - lambda * L).abs() < 1e-9 && tip[0].abs() < 1e-12,
                "{law}, p = {p}: tip {tip:?} vs stretch {lambda}"
            );
            for v in &sol.v {
                assert!((v[2] - lambda).abs() < 1e-12);
            }
        }
    }
}

#[test]
fn linear_fibre_law_equals_the_linear_material_at_any_load() {
    // A Hookean uniaxial law makes every fibre linear: the fibre section is then exactly the
    // linear section (E, G = E/3), for bending, stretch, shear and torsion together.
    let (sec, _, _) = arm_section();
    let e = 300e3;
    let lin = Rod::new(L, sec.clone(), LinearElastic::new(e, 0.5).unwrap()).unwrap();
    let hyp = Rod::new(L, sec, UniaxialModel::from(Hookean::new(e).unwrap())).unwrap();
    let loads = Loaded {
        loads: Loads {
            tip_force: Vector3::new(0.3, -0.2, 0.3),
            tip_moment: Vector3::new(0.0, 0.0, 2e-3),
            ..Default::default()
        },
        chambers: chambers([0.0, 120e3, 0.0, 0.0, 150e3, 0.0]),
    };
    let a = solve_p(&lin, &loads, &rk4(200)).unwrap();
    let b = solve_p(&hyp, &loads, &rk4(200)).unwrap();
    let err = dist(a.tip_position(), b.tip_position());
    assert!(err < 1e-12, "{err:e}");
    let disp = dist(a.tip_position(), [0.0, 0.0, L]);
    assert!(disp > 0.02, "the load must be large: {disp}");
}

#[test]
fn small_strains_equal_the_linear_rod_with_the_initial_modulus() {
    let sec = Section::circular(R).unwrap();
    let laws = [
        UniaxialModel::from(NeoHookean::new(70e3).unwrap()),
        UniaxialModel::from(MooneyRivlin::new(40e3, 10e3).unwrap()),
        UniaxialModel::from(Yeoh::new(25e3, 3e3, -100.0).unwrap()),
    ];
    for law in laws {
        let e0 = law.small_strain_modulus();
        let lin = Rod::new(L, sec.clone(), LinearElastic::new(e0, 0.5).unwrap()).unwrap();
        let hyp = Rod::new(L, sec.clone(), law.clone()).unwrap();
        let mut rel = Vec::new();
        for scale in [1e-4, 1e-5] {
            let loads = Loaded {
                loads: Loads {
                    tip_force: Vector3::new(0.2, -0.1, 0.5) * scale,
                    ..Default::default()
                },
                chambers: vec![common::constant_chamber(2e5 * scale, 2e-5, [0.0, 0.006]).unwrap()],
            };
            let a = solve_p(&lin, &loads, &rk4(100)).unwrap();
            let b = solve_p(&hyp, &loads, &rk4(100)).unwrap();
            let disp = dist(a.tip_position(), [0.0, 0.0, L]);
            rel.push(dist(a.tip_position(), b.tip_position()) / disp);
        }
        // The difference is of the order of the strain (~1e-5, 1e-6) and vanishes with it.
        assert!(rel[0] < 1e-4 && rel[1] < 1e-5, "{law}: {rel:?}");
        assert!(rel[1] < 0.2 * rel[0], "{law}: {rel:?}");
    }
}

#[test]
fn a_partial_chamber_bends_only_its_extent() {
    let (sec, a0, i0) = arm_section();
    let e = 300e3;
    let rod = Rod::new(L, sec, silicone_linear()).unwrap();
    let (a, b, p) = (0.04, 0.12, 50e3);
    let ac = PI * RC * RC;
    let c = common::chamber(p, ChamberArea::Constant(ac), [0.0, D], a, Some(b)).unwrap();
    let sol = solve_p(&rod, &with_chambers(vec![c]), &rk4(400)).unwrap();
    let (ux, lambda) = (p * ac * D / (e * i0), 1.0 + p * ac / (e * a0));
    for i in 0..sol.s.len() {
        let inside = sol.s[i] > a && sol.s[i] < b;
        let (want_u, want_v) = if inside { (ux, lambda) } else { (0.0, 1.0) };
        if sol.s[i] != a && sol.s[i] != b {
            assert!((sol.u[i][0] - want_u).abs() < 1e-12, "s = {}", sol.s[i]);
            assert!((sol.v[i][2] - want_v).abs() < 1e-12);
        }
    }
    // Tip: straight base part, arc, straight distal part along the rotated tangent.
    let th = ux * (b - a);
    let arc = arc_tip(b - a, lambda, ux, 0.0);
    let want = [
        0.0,
        arc[1] - (L - b) * th.sin(),
        a + arc[2] + (L - b) * th.cos(),
    ];
    let err = dist(sol.tip_position(), want);
    assert!(err < 1e-9, "{err:e}");
}

#[test]
fn a_varying_chamber_area_matches_the_local_closed_form() {
    // A(s) linear: n_z = p A(s) and u_x = p A(s) d / EI pointwise; the base reaction is zero.
    let (sec, a0, i0) = arm_section();
    let e = 300e3;
    let rod = Rod::new(L, sec, silicone_linear()).unwrap();
    let area = |s: f64| PI * RC * RC * (1.0 - 0.5 * s / L);
    let c = common::chamber(
        40e3,
        ChamberArea::Function(std::sync::Arc::new(area)),
        [0.0, D],
        0.0,
        None,
    )
    .unwrap();
    let sol = solve_p(&rod, &with_chambers(vec![c]), &rk4(200)).unwrap();
    for i in 0..sol.s.len() {
        let f = 40e3 * area(sol.s[i]);
        assert!((sol.n_body[i][2] - f).abs() < 1e-12);
        assert!((sol.u[i][0] - f * D / (e * i0)).abs() < 1e-12);
        assert!((sol.v[i][2] - 1.0 - f / (e * a0)).abs() < 1e-12);
    }
    assert!(sol.base_wrench.iter().all(|w| w.abs() < 1e-12));
}

fn name_of(e: Error) -> String {
    match e {
        Error::InvalidParameter { name, .. } => name,
        other => panic!("not a parameter error: {other:?}"),
    }
}

#[test]
fn bad_input_names_the_parameter() {
    assert_eq!(name_of(NeoHookean::new(-1.0).unwrap_err()), "mu");
    assert_eq!(name_of(Yeoh::new(-1.0, 0.0, 0.0).unwrap_err()), "c10");
    assert_eq!(
        name_of(MooneyRivlin::new(-2.0, 1.0).unwrap_err()),
        "c10 + c01"
    );
    assert_eq!(
        name_of(common::constant_chamber(1e3, -1.0, [0.0, 0.0]).unwrap_err()),
        "area"
    );
    assert_eq!(
        name_of(common::constant_chamber(-2e5, 1e-5, [0.0, 0.0]).unwrap_err()),
        "pressure"
    );
    assert_eq!(
        name_of(common::constant_chamber(1e3, 1e-5, [f64::NAN, 0.0]).unwrap_err()),
        "offset[0]"
    );
    let area = ChamberArea::Constant(1e-5);
    assert_eq!(
        name_of(common::chamber(1e3, area.clone(), [0.0, 0.0], 0.1, Some(0.05)).unwrap_err()),
        "end"
    );
    assert_eq!(
        name_of(common::chamber(1e3, area.clone(), [0.0, 0.0], -0.1, None).unwrap_err()),
        "start"
    );

    let (sec, _, _) = arm_section();
    let rod = Rod::new(L, sec, silicone_linear()).unwrap();
    let solve = |c: common::Pressurised| solve_p(&rod, &with_chambers(vec![c]), &rk4(20));
    let c = common::chamber(1e3, area.clone(), [0.0, D], 0.0, Some(2.0 * L)).unwrap();
    assert_eq!(name_of(solve(c).unwrap_err()), "chambers[0].end");
    let c = common::chamber(1e3, area.clone(), [0.0, D], L, None).unwrap();
    assert_eq!(name_of(solve(c).unwrap_err()), "chambers[0].start");
    // Offset in mm instead of m.
    let c = common::constant_chamber(1e3, 1e-5, [0.0, 7.2]).unwrap();
    assert_eq!(name_of(solve(c).unwrap_err()), "chambers[0].offset");
    let c = common::chamber(
        1e3,
        ChamberArea::Function(std::sync::Arc::new(|s| if s > 0.1 { -1.0 } else { 1e-5 })),
        [0.0, D],
        0.0,
        None,
    )
    .unwrap();
    assert!(name_of(solve(c).unwrap_err()).starts_with("chambers[0].area("));
}

#[test]
fn material_failures_during_the_solve_are_named() {
    let (sec, a0, _) = arm_section();
    let ac = PI * RC * RC;
    // A Yeoh set whose nominal stress peaks (dP/dλ < 0 beyond): pressurise past the peak.
    let law = Yeoh::new(20e3, -2e3, 0.0).unwrap();
    let p_max = (0..4000)
        .map(|i| law.nominal_stress(1.0 + i as f64 * 1e-3).unwrap())
        .fold(0.0f64, f64::max);
    let rod = Rod::new(L, sec.clone(), UniaxialModel::from(law)).unwrap();
    let p = 1.5 * p_max * a0 / (6.0 * ac);
    let err = solve_p(&rod, &with_chambers(chambers([p; 6])), &rk4(20)).unwrap_err();
    assert_eq!(name_of(err), "Yeoh parameters");
    // A compression the law cannot carry: a fibre stretch would reach zero.
    let rod = Rod::new(L, sec, UniaxialModel::from(Hookean::new(300e3).unwrap())).unwrap();
    let loads = Loads::tip_force(Vector3::new(0.0, 0.0, -2.0 * 300e3 * a0));
    let err = common::solve(&rod, &[], &loads, &rk4(20)).unwrap_err();
    assert_eq!(name_of(err), "stretch");
}

#[test]
fn hyperelastic_material_reports_its_small_strain_moduli() {
    let m = Material::from(UniaxialModel::from(NeoHookean::new(50e3).unwrap()));
    assert_eq!(m.small_strain_moduli(), (150e3, 50e3));
    assert_eq!(m.poisson_ratio(), 0.5);
    assert!(!m.is_linear());
}

#[test]
fn tangent_compliance_of_a_pressurised_hyperelastic_arm_matches_finite_differences() {
    // The compliance module's exact tangent goes through the hyperelastic local solve; it must
    // equal the finite-difference response of the tip to a small tip wrench, and be symmetric
    // (the fibre section and the pressure are conservative).
    let (sec, _, _) = arm_section();
    let rod = Rod::new(L, sec, UniaxialModel::from(Silicone::DragonSkin10.yeoh())).unwrap();
    let loads = with_chambers(chambers([30e3, 30e3, 15e3, 15e3, 0.0, 0.0]));
    let opts = rk4(100);
    let sol = solve_p(&rod, &loads, &opts).unwrap();
    let t = softrod::tangent_compliance(&sol, softrod::TendonControl::Tension, None).unwrap();
    assert!(t.symmetric);
    let tip = |w: [f64; 6]| {
        let l = Loaded {
            loads: Loads {
                tip_force: Vector3::new(w[0], w[1], w[2]),
                tip_moment: Vector3::new(w[3], w[4], w[5]),
                ..Default::default()
            },
            chambers: loads.chambers.clone(),
        };
        let s = solve_p(&rod, &l, &opts).unwrap();
        (s.tip_position(), s.rotation[s.s.len() - 1])
    };
    let mut worst = 0.0f64;
    for j in 0..6 {
        let h = if j < 3 { 1e-5 } else { 1e-7 };
        let mut w = [0.0; 6];
        w[j] = h;
        let (pp, rp) = tip(w);
        w[j] = -h;
        let (pm, rm) = tip(w);
        // Translation column, and the rotation from R+ R-ᵀ (world-frame δθ).
        let dp: Vec<f64> = (0..3).map(|i| (pp[i] - pm[i]) / (2.0 * h)).collect();
        let m = |a: [[f64; 3]; 3], b: [[f64; 3]; 3], i: usize, k: usize| {
            (0..3).map(|q| a[i][q] * b[k][q]).sum::<f64>()
        };
        let dth = [
            0.5 * (m(rp, rm, 2, 1) - m(rp, rm, 1, 2)) / (2.0 * h),
            0.5 * (m(rp, rm, 0, 2) - m(rp, rm, 2, 0)) / (2.0 * h),
            0.5 * (m(rp, rm, 1, 0) - m(rp, rm, 0, 1)) / (2.0 * h),
        ];
        for i in 0..3 {
            let scale = t.world.column(j).amax();
            worst = worst.max((t.world[(i, j)] - dp[i]).abs() / scale);
            worst = worst.max((t.world[(i + 3, j)] - dth[i]).abs() / scale);
        }
    }
    println!("tangent compliance vs finite differences: {worst:e}");
    assert!(worst < 1e-6, "relative difference {worst:e}");
}

/// The adaptive integrator at rtol 1e-10, atol 1e-12: the reference of the mesh checks.
fn tight_adaptive() -> SolveOptions {
    SolveOptions {
        integrator: Integrator::Adaptive(softrod::AdaptiveOptions {
            rtol: 1e-10,
            atol: 1e-12,
            ..Default::default()
        }),
        ..SolveOptions::default()
    }
}

/// A tapered Neo-Hookean arm (0.4 m, radius 5.5 mm to 1.3 mm, one chamber at 2.3 MPa) that
/// curls 3.7 turns, to 660 1/m at its thin tip: the default 40 RK4 steps turn by up to 6.6 rad
/// a step there, where RK4's rotations are meaningless, and the solve reported a tip 30 L
/// from the base as converged. Under error control the default mesh is refined when its
/// estimated tip error (`Σ θ⁵/120 (L - s)/L`) exceeds 1e-4; a chosen mesh estimated off by
/// more than a tenth of the length is refused naming `steps`, and 320 steps (estimated
/// 2.7e-4, off by 5.7e-5 L) are kept. Oracle: the tip on 640 steps and with the adaptive
/// integrator (they agree to 2e-6 m).
#[test]
fn a_curl_the_default_mesh_cannot_resolve_is_solved_on_a_finer_one() {
    let (l, radius, tip_radius) = (0.4, 0.0055, 0.0013);
    let rod = Rod::new(
        l,
        Section::tapered_circular(radius, tip_radius).unwrap(),
        Material::from(UniaxialModel::from(NeoHookean::new(0.25e6).unwrap())),
    )
    .unwrap();
    let area = PI * (0.3 * tip_radius).powi(2);
    let chamber = softrod::Chamber::new(
        ChamberArea::Constant(area),
        [0.5 * tip_radius, 0.0],
        0.0,
        None,
    )
    .unwrap();
    let model = softrod::RobotModel::new(rod, Vec::new(), vec![chamber], Loads::default()).unwrap();
    let act = softrod::Actuation::pressures(&[2.3e6]);
    let solve = |o: &SolveOptions| softrod::compliance::solve_at_output(&model, &act, o, &[]);
    let fine = solve(&rk4(640)).unwrap();
    let reference = solve(&tight_adaptive()).unwrap();
    let tip = |s: &StaticsSolution| Vector3::from(s.tip_position());
    println!("640 steps {:?}, adaptive {:?}", tip(&fine), tip(&reference));
    assert!((tip(&fine) - tip(&reference)).norm() <= 1e-5);
    let default = solve(&SolveOptions::default()).unwrap();
    let error = (tip(&default) - tip(&reference)).norm();
    println!(
        "default: {} steps, tip {:?}, {error:.2e} m from the adaptive one",
        match default.options.integrator {
            Integrator::Rk4 { steps } => steps,
            Integrator::Adaptive(_) => 0,
        },
        tip(&default)
    );
    assert!(default.stats.converged);
    assert!(error <= 1e-4 * l, "{error:e} m");
    let kept = solve(&rk4(320)).unwrap();
    let off = (tip(&kept) - tip(&reference)).norm();
    let estimate = softrod::compliance::rk4_position_error(&kept);
    assert!(
        off <= estimate * l && estimate < 1e-3,
        "{off:e} m, estimated {estimate:e} L"
    );
    match solve(&rk4(50)) {
        Err(Error::InvalidParameter { name, .. }) => assert_eq!(name, "steps"),
        other => panic!("50 steps: {:?}", other.map(|s| s.tip_position())),
    }
}

/// A tapered Mooney–Rivlin arm (0.12 m, radius 5 mm to 2 mm) whose three chambers curl it
/// tight, under a small tip force and gravity: on 20 to 80 RK4 steps the march of the curl
/// goes wild (moments of 1e18 N m at the base), and the default solve raised a
/// `ParameterError` naming a fibre `stretch` of 1.0 as "must be > 0". A default mesh that fails
/// is tried again on one eight times finer (here it converges, stable, and is refined once
/// more to meet the default mesh's estimated accuracy, 1e-4 L); a chosen mesh that fails is
/// judged on that shape and named (`steps`). Oracle: the adaptive integrator's tip (rtol 1e-10),
/// within the refined solve's own estimate of its error.
#[test]
fn a_pneumatic_curl_the_default_mesh_fails_on_is_solved_on_a_finer_one() {
    let rod = Rod::new(
        0.1223,
        Section::tapered_circular(0.005, 0.002).unwrap(),
        Material::from(UniaxialModel::from(
            MooneyRivlin::new(25.6e3, 13.3e3).unwrap(),
        )),
    )
    .unwrap()
    .with_density(1198.0)
    .unwrap();
    let chambers = [
        (1.447e6, [0.0001, -0.00094]),
        (0.398e6, [0.00076, 0.00055]),
        (0.154e6, [-0.00086, 0.00038]),
    ];
    let list = chambers
        .iter()
        .map(|(_, o)| {
            softrod::Chamber::new(ChamberArea::Constant(1.333e-6), *o, 0.0, None).unwrap()
        })
        .collect();
    let loads = Loads {
        tip_force: Vector3::new(-9.8e-5, 8.7e-5, 4.7e-4),
        gravity: Vector3::new(8.459, -3.767, -3.239),
        ..Default::default()
    };
    let model = softrod::RobotModel::new(rod, Vec::new(), list, loads).unwrap();
    let act = softrod::Actuation::pressures(&chambers.map(|c| c.0));
    let solve = |o: &SolveOptions| softrod::compliance::solve_at_output(&model, &act, o, &[]);
    let reference = Vector3::from(solve(&tight_adaptive()).unwrap().tip_position());
    let default = solve(&SolveOptions::default()).unwrap();
    let off = (Vector3::from(default.tip_position()) - reference).norm();
    println!(
        "default: {:?}, {off:.2e} m from the adaptive tip",
        default.options.integrator
    );
    let estimate = softrod::compliance::rk4_position_error(&default);
    assert!(default.stats.converged && default.stable);
    assert!(
        off <= estimate * 0.1223 && estimate <= softrod::compliance::DEFAULT_MESH_POSITION_LIMIT,
        "{off:e} m, estimated {estimate:e} L"
    );
    // (40 steps are the default mesh, whichever way they are asked for.) A chosen mesh that
    // fails is judged on the shape the default mesh finds: 41 steps would err by 5.5 L.
    match solve(&rk4(41)) {
        Err(Error::InvalidParameter { name, .. }) => assert_eq!(name, "steps"),
        other => panic!("41 chosen steps: {:?}", other.map(|s| s.tip_position())),
    }
    // Asked at chosen arc lengths, the solve that fails on the default mesh is tried on the
    // finer one too (it raised the default mesh's `ConvergenceError`), refined toward the
    // output target up to the largest mesh (32 times the default, as above), and the values
    // there are the adaptive integrator's at the same arc lengths, within the estimate.
    let s_out = [0.03, 0.0611, 0.1223];
    let at = softrod::compliance::solve_at_output(&model, &act, &SolveOptions::default(), &s_out)
        .unwrap();
    let reference =
        softrod::compliance::solve_at_output(&model, &act, &tight_adaptive(), &s_out).unwrap();
    assert!(at.stats.converged && at.s == s_out.to_vec());
    assert_eq!(at.options.integrator, default.options.integrator);
    for (p, q) in at.position.iter().zip(&reference.position) {
        let off = (Vector3::from(*p) - Vector3::from(*q)).norm();
        assert!(
            off <= estimate * 0.1223,
            "{off:e} m at the chosen arc lengths, estimated {estimate:e} L"
        );
    }
}
