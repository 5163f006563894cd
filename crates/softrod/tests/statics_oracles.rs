//! Cosserat-rod statics against independent oracles: closed-form arcs, the Bisshopp–Drucker
//! elastica (elliptic integrals computed here with Carlson's forms), and the tendon
//! closed form.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use std::f64::consts::PI;

use softrod::integrate::AdaptiveOptions;
use softrod::nalgebra::{Matrix3, Vector3};
use softrod::{Integrator, LinearElastic, Loads, Rod, Section, SolveOptions};

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

#[test]
fn pure_tip_moment_gives_circular_arc() {
    let (l, r, e): (f64, f64, f64) = (0.5, 0.005, 2e9);
    let ei = e * PI * r.powi(4) / 4.0;
    let kappa = 1.5 / l; // 1.5 rad of bending
    let mtip = kappa * ei;
    for inextensible in [true, false] {
        let rod = Rod::new(
            l,
            Section::circular(r).unwrap(),
            LinearElastic::new(e, 0.3).unwrap(),
        )
        .unwrap()
        .with_inextensible(inextensible);
        let sol = common::solve(
            &rod,
            &[],
            &Loads::tip_moment(Vector3::new(mtip, 0.0, 0.0)),
            &rk4(400),
        )
        .unwrap();
        // u = (kappa, 0, 0): the tangent turns from +z toward -y.
        let exact = [
            0.0,
            -(1.0 - (kappa * l).cos()) / kappa,
            (kappa * l).sin() / kappa,
        ];
        let err = dist(sol.tip_position(), exact);
        println!(
            "arc inextensible={inextensible}: tip error {err:.3e} m, iterations {}",
            sol.stats.iterations
        );
        assert!(err < 1e-10, "tip error {err}");
        for u in &sol.u {
            assert!((u[0] - kappa).abs() < 1e-9 * kappa && u[1].abs() < 1e-9 && u[2].abs() < 1e-9);
        }
        assert!(sol.stats.converged);
    }
}

// ---- Elliptic integrals (Carlson's symmetric forms, duplication + series). ----

fn carlson_rf(mut x: f64, mut y: f64, mut z: f64) -> f64 {
    loop {
        let a = (x + y + z) / 3.0;
        let (dx, dy, dz) = (1.0 - x / a, 1.0 - y / a, 1.0 - z / a);
        if dx.abs().max(dy.abs()).max(dz.abs()) < 1e-4 {
            let e2 = dx * dy - dz * dz;
            let e3 = dx * dy * dz;
            return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0)
                / a.sqrt();
        }
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lam = sx * sy + sy * sz + sz * sx;
        x = (x + lam) / 4.0;
        y = (y + lam) / 4.0;
        z = (z + lam) / 4.0;
    }
}

fn carlson_rd(mut x: f64, mut y: f64, mut z: f64) -> f64 {
    let mut sum = 0.0;
    let mut fac = 1.0;
    loop {
        let a = (x + y + 3.0 * z) / 5.0;
        let (dx, dy, dz) = ((a - x) / a, (a - y) / a, (a - z) / a);
        if dx.abs().max(dy.abs()).max(dz.abs()) < 1e-4 {
            let ea = dx * dy;
            let eb = dz * dz;
            let ec = ea - eb;
            let ed = ea - 6.0 * eb;
            let ee = ed + ec + ec;
            return 3.0 * sum
                + fac
                    * (1.0
                        + ed * (-3.0 / 14.0 + 9.0 / 88.0 * ed - 9.0 / 52.0 * dz * ee)
                        + dz * (ee / 6.0 + dz * (-9.0 / 22.0 * ec + 3.0 / 26.0 * dz * ea)))
                    / (a * a.sqrt());
        }
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lam = sx * (sy + sz) + sy * sz;
        sum += fac / (sz * (z + lam));
        fac *= 0.25;
        x = (x + lam) / 4.0;
        y = (y + lam) / 4.0;
        z = (z + lam) / 4.0;
    }
}

/// Incomplete elliptic integral of the first kind `F(phi, k)`.
fn ell_f(phi: f64, k: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    s * carlson_rf(c * c, 1.0 - k * k * s * s, 1.0)
}

/// Incomplete elliptic integral of the second kind `E(phi, k)`.
fn ell_e(phi: f64, k: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    let q = 1.0 - k * k * s * s;
    s * carlson_rf(c * c, q, 1.0) - k * k * s.powi(3) / 3.0 * carlson_rd(c * c, q, 1.0)
}

/// Composite Gauss–Legendre (5 points, `n` panels) of `f` over `[a, b]`: a check of the
/// elliptic integrals that shares nothing with Carlson's forms.
fn quad(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let x = [
        0.0,
        0.538_469_310_105_683,
        -0.538_469_310_105_683,
        0.906_179_845_938_664,
        -0.906_179_845_938_664,
    ];
    let w = [
        0.568_888_888_888_889,
        0.478_628_670_499_366,
        0.478_628_670_499_366,
        0.236_926_885_056_189,
        0.236_926_885_056_189,
    ];
    let h = (b - a) / n as f64;
    let mut sum = 0.0;
    for i in 0..n {
        let c = a + h * (i as f64 + 0.5);
        for j in 0..5 {
            sum += w[j] * f(c + 0.5 * h * x[j]);
        }
    }
    sum * 0.5 * h
}

#[test]
fn elliptic_integrals_match_quadrature_and_tables() {
    // K(m = 1/2) and E(m = 1/2) (Abramowitz & Stegun table 17.1).
    let k = 0.5f64.sqrt();
    assert!((ell_f(PI / 2.0, k) - 1.854_074_677_301_372).abs() < 1e-14);
    assert!((ell_e(PI / 2.0, k) - 1.350_643_881_047_675).abs() < 1e-14);
    for (phi, k) in [(0.3, 0.9), (1.2, 0.99), (0.8, 0.75)] {
        let f = quad(
            |t| 1.0 / (1.0 - k * k * t.sin().powi(2)).sqrt(),
            0.0,
            phi,
            200,
        );
        let e = quad(|t| (1.0 - k * k * t.sin().powi(2)).sqrt(), 0.0, phi, 200);
        assert!((ell_f(phi, k) - f).abs() < 1e-13, "F({phi},{k})");
        assert!((ell_e(phi, k) - e).abs() < 1e-13, "E({phi},{k})");
    }
}

/// Bisshopp–Drucker: tip of an inextensible cantilever of length 1 under a transverse dead
/// load with `alpha = P L² / (E I)`: (transverse deflection, axial projection) / L.
fn bisshopp_drucker(alpha: f64) -> (f64, f64) {
    let phi1 = |k: f64| (1.0 / (k * 2.0f64.sqrt())).min(1.0).asin();
    let g = |k: f64| ell_f(PI / 2.0, k) - ell_f(phi1(k), k) - alpha.sqrt();
    let (mut lo, mut hi) = (0.5f64.sqrt(), 1.0 - 1e-15);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let k = 0.5 * (lo + hi);
    let p1 = phi1(k);
    let delta = 1.0 - 2.0 * (ell_e(PI / 2.0, k) - ell_e(p1, k)) / alpha.sqrt();
    let x = (2.0 * (2.0 * k * k - 1.0) / alpha).sqrt();
    (delta, x)
}

#[test]
fn bisshopp_drucker_reference_matches_published_values() {
    // Bisshopp & Drucker (1945), table: alpha = 1 -> vertical deflection 0.3017 L, and
    // the small-load limit alpha / 3.
    let (d1, _) = bisshopp_drucker(1.0);
    assert!((d1 - 0.3017).abs() < 1e-4, "{d1}");
    let (ds, xs) = bisshopp_drucker(1e-4);
    assert!((ds - 1e-4 / 3.0).abs() < 1e-9 && (xs - 1.0).abs() < 1e-8);
}

#[test]
fn tip_loaded_cantilever_matches_elastica() {
    let (l, r, e): (f64, f64, f64) = (0.3, 0.002, 5e6);
    let ei = e * PI * r.powi(4) / 4.0;
    let rod = Rod::new(
        l,
        Section::circular(r).unwrap(),
        LinearElastic::new(e, 0.3).unwrap(),
    )
    .unwrap()
    .with_inextensible(true);
    println!("alpha   delta/L (ref)        x/L (ref)         tip error / L   iters  load steps");
    for alpha in [0.1, 0.3, 1.0, 2.0, 3.0, 5.0, 7.5, 10.0] {
        let p = alpha * ei / (l * l);
        let sol = common::solve(
            &rod,
            &[],
            &Loads::tip_force(Vector3::new(p, 0.0, 0.0)),
            &adaptive(1e-12),
        )
        .unwrap();
        let (d, x) = bisshopp_drucker(alpha);
        let tip = sol.tip_position();
        let err = dist(tip, [d * l, 0.0, x * l]) / l;
        println!(
            "{alpha:5.1}  {d:.12}  {x:.12}  {err:.3e}      {:3}   {}",
            sol.stats.iterations, sol.stats.load_steps
        );
        assert!(err < 1e-7, "alpha {alpha}: tip error {err} L");
    }
}

#[test]
fn constant_offset_tendon_gives_constant_curvature_and_strain() {
    let (l, r, e, nu): (f64, f64, f64, f64) = (0.25, 0.004, 3e6, 0.45);
    let (tau, d) = (2.0, 0.003);
    let mat = LinearElastic::new(e, nu).unwrap();
    let rod = Rod::new(l, Section::circular(r).unwrap(), mat).unwrap();
    let ei = e * PI * r.powi(4) / 4.0;
    let ea = e * PI * r * r;
    let kappa = tau * d / ei;
    let eps = -tau / ea;
    let tendon = common::tendon([d, 0.0], tau, None).unwrap();
    let sol = common::solve(&rod, &[tendon], &Loads::default(), &rk4(400)).unwrap();
    for (u, v) in sol.u.iter().zip(&sol.v) {
        assert!((u[1] - kappa).abs() <= 1e-10 * kappa, "u {u:?} vs {kappa}");
        assert!(u[0].abs() < 1e-10 * kappa && u[2].abs() < 1e-10 * kappa);
        assert!(
            (v[2] - 1.0 - eps).abs() < 1e-10 * eps.abs(),
            "v {v:?} vs {eps}"
        );
        assert!(v[0].abs() < 1e-12 && v[1].abs() < 1e-12);
    }
    // Arc of curvature kappa per undeformed length, stretched by 1 + eps, toward the tendon.
    let exact = [
        (1.0 + eps) * (1.0 - (kappa * l).cos()) / kappa,
        0.0,
        (1.0 + eps) * (kappa * l).sin() / kappa,
    ];
    let err = dist(sol.tip_position(), exact);
    println!("tendon arc: kappa {kappa:.6} 1/m, eps {eps:.3e}, tip error {err:.3e} m");
    assert!(err < 1e-10);
    // The tendon runs parallel to the backbone at distance d: length (1 + eps - kappa d) L.
    let lt = (1.0 + eps - kappa * d) * l;
    assert!(
        (sol.tendon_lengths[0] - lt).abs() < 1e-12,
        "{} vs {lt}",
        sol.tendon_lengths[0]
    );
    // Tendon-only loading: the total base wrench is zero and no Newton step is needed.
    assert_eq!(sol.stats.iterations, 0);
    // The rod's own internal force is the tendon's compression.
    assert!((sol.n_body[0][2] + tau).abs() < 1e-12);
}

/// Composite Simpson's rule of `f` over `[a, b]` with `n` (even) panels.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let inner: f64 = (1..n)
        .map(|i| f(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(a) + f(b) + inner) * h / 3.0
}

#[test]
fn tendon_on_a_tapered_rod_bends_with_the_local_stiffness() {
    // A straight tendon at a constant offset d carries no total wrench with the rod: at every
    // s the tendon runs along e_z (v + u x r = (0, 0, 1 + eps - kappa d)), so
    // kappa(s) = tau d / EI(s) and eps(s) = -tau / EA(s) section by section. The shape is the
    // planar curve of those strains, integrated here by quadrature.
    let (l, r0, r1, e, nu): (f64, f64, f64, f64, f64) = (0.25, 0.004, 0.002, 3e6, 0.45);
    let (tau, d) = (0.4, 0.0015);
    let radius = |s: f64| r0 + (r1 - r0) * s / l;
    let kappa = |s: f64| tau * d / (e * PI * radius(s).powi(4) / 4.0);
    let eps = |s: f64| -tau / (e * PI * radius(s).powi(2));
    let mat = LinearElastic::new(e, nu).unwrap();
    let rod = Rod::new(l, Section::tapered_circular(r0, r1).unwrap(), mat).unwrap();
    let tendon = common::tendon([d, 0.0], tau, None).unwrap();
    let sol = common::solve(&rod, &[tendon], &Loads::default(), &rk4(400)).unwrap();
    for ((s, u), v) in sol.s.iter().zip(&sol.u).zip(&sol.v) {
        let (k, ep) = (kappa(*s), eps(*s));
        assert!((u[1] - k).abs() <= 1e-10 * k, "s {s}: u {u:?} vs {k}");
        assert!(u[0].abs() < 1e-12 * k && u[2].abs() < 1e-12 * k);
        assert!((v[2] - 1.0 - ep).abs() < 1e-10 * ep.abs(), "s {s}: v {v:?}");
    }
    let theta = |s: f64| simpson(kappa, 0.0, s, 200);
    let x = simpson(|s| (1.0 + eps(s)) * theta(s).sin(), 0.0, l, 400);
    let z = simpson(|s| (1.0 + eps(s)) * theta(s).cos(), 0.0, l, 400);
    let err = dist(sol.tip_position(), [x, 0.0, z]);
    println!(
        "tapered tendon arc: tip angle {:.4} rad, tip error {err:.3e} m",
        theta(l)
    );
    assert!(err < 1e-10, "tip {:?} vs [{x}, 0, {z}]", sol.tip_position());
    // The tendon runs at distance d from the backbone: its length is the integral of
    // 1 + eps - kappa d.
    let lt = simpson(|s| 1.0 + eps(s) - kappa(s) * d, 0.0, l, 400);
    assert!((sol.tendon_lengths[0] - lt).abs() < 1e-12);
}

#[test]
fn base_pose_rotation_rotates_the_solution() {
    use softrod::{Pose, Routing};
    let (l, r, e) = (0.3, 0.003, 1e7);
    let mat = LinearElastic::new(e, 0.4).unwrap();
    let tendon = common::tendon_with(
        Routing::Helical {
            radius: 0.002,
            pitch: 0.2,
            phase: 0.3,
        },
        1.5,
        Some(0.25),
    )
    .unwrap();
    let q = softrod::math::so3::exp_so3(&Vector3::new(0.7, -1.9, 0.4));
    let t0 = Vector3::new(0.1, -0.2, 0.05);
    let f = Vector3::new(0.02, -0.05, 0.01);
    let base = Rod::new(l, Section::tapered_circular(r, 0.6 * r).unwrap(), mat).unwrap();
    let rotated = base.clone().with_base_pose(Pose::new(t0, q).unwrap());
    let mut loads = Loads::tip_force(f);
    let mut loads_q = Loads::tip_force(q * f);
    loads
        .point_loads
        .push(softrod::PointLoad::force(0.1, Vector3::new(0.0, 0.03, 0.0)));
    loads_q.point_loads.push(softrod::PointLoad::force(
        0.1,
        q * Vector3::new(0.0, 0.03, 0.0),
    ));
    let a = common::solve(&base, std::slice::from_ref(&tendon), &loads, &rk4(60)).unwrap();
    let b = common::solve(&rotated, &[tendon], &loads_q, &rk4(60)).unwrap();
    assert_eq!(a.s.len(), b.s.len());
    let mut worst: f64 = 0.0;
    for i in 0..a.s.len() {
        let pa = Vector3::from(a.position[i]);
        let pb = Vector3::from(b.position[i]);
        worst = worst.max((q * pa + t0 - pb).amax());
        let ra = Matrix3::from_fn(|r, c| a.rotation[i][r][c]);
        let rb = Matrix3::from_fn(|r, c| b.rotation[i][r][c]);
        worst = worst.max((q * ra - rb).amax());
        for k in 0..3 {
            worst = worst.max((a.u[i][k] - b.u[i][k]).abs() * l);
        }
    }
    println!("rotation invariance: worst difference {worst:.3e}");
    assert!(worst < 1e-12, "{worst}");
    assert!((a.tendon_lengths[0] - b.tendon_lengths[0]).abs() < 1e-14);
}

#[test]
fn helical_tendon_bends_out_of_plane_with_its_handedness() {
    use softrod::Routing;
    let (l, r, e): (f64, f64, f64) = (0.2, 0.002, 2e8);
    let ei = e * PI * r.powi(4) / 4.0;
    let rod = Rod::new(
        l,
        Section::circular(r).unwrap(),
        LinearElastic::new(e, 0.3).unwrap(),
    )
    .unwrap();
    let (rho, pitch) = (0.0015, 0.4);
    let omega = 2.0 * PI / pitch;
    let tau = 1e-3 * ei / (rho * l); // small: tip rotation ~ 1e-3 rad
    let helix = |p: f64| {
        let t = common::tendon_with(
            Routing::Helical {
                radius: rho,
                pitch: p,
                phase: 0.0,
            },
            tau,
            None,
        )
        .unwrap();
        common::solve(&rod, &[t], &Loads::default(), &rk4(200)).unwrap()
    };
    let right = helix(pitch);
    let left = helix(-pitch);
    // Linear theory: (x, y)'' = kappa (cos ws, sin ws), kappa = tau rho / EI.
    let kappa = tau * rho / ei;
    let lin = [
        kappa * (1.0 - (omega * l).cos()) / (omega * omega),
        kappa * (l / omega - (omega * l).sin() / (omega * omega)),
    ];
    let tr = right.tip_position();
    let tl = left.tip_position();
    println!("helical: right-handed tip {tr:?}, left-handed tip {tl:?}, linear {lin:?}");
    // Out of plane, toward +y for the right-handed helix, mirror image for the left-handed.
    assert!(tr[1] > 0.0 && tl[1] < 0.0);
    assert!(
        (tr[0] - tl[0]).abs() < 1e-15
            && (tr[1] + tl[1]).abs() < 1e-15
            && (tr[2] - tl[2]).abs() < 1e-15
    );
    // Agreement with the linear theory to the order of the neglected terms (kappa L ~ 1e-3).
    for k in 0..2 {
        assert!(
            (tr[k] - lin[k]).abs() < 5e-3 * lin[0].hypot(lin[1]),
            "{k}: {} vs {}",
            tr[k],
            lin[k]
        );
    }
    // And a visible twist appears (nonzero u_z), of opposite sign for the mirror image.
    let uz_r = right.u[right.u.len() / 2][2];
    let uz_l = left.u[left.u.len() / 2][2];
    assert!(uz_r != 0.0 && (uz_r + uz_l).abs() < 1e-12 * uz_r.abs().max(1e-300));
}

#[test]
fn published_arm_agrees_to_the_order_of_its_linearisation() {
    use softrod::{solve_planar, PlanarCableArm, PlanarMethod, Routing};
    // The paper's planar model takes the cable moment as T d (1 - d k) per *deformed* length and
    // neglects shear; the 3-D rod uses the exact tendon direction per *undeformed* length.
    // Their relative difference is of the order of the terms the paper linearises, |q| + d k
    // (both O(T)); with the rod made shear-rigid like the paper, it must stay below their
    // maximum along the arm, and shrink linearly with T.
    let arm = PlanarCableArm::published_arm();
    let rod = Rod::new(
        arm.length(),
        Section::tapered_circular(arm.base_radius(), arm.tip_radius()).unwrap(),
        LinearElastic::new(arm.youngs_modulus(), 0.5).unwrap(),
    )
    .unwrap()
    .with_shear_coefficient(1e9)
    .unwrap();
    let samples = softrod::uniform_samples(arm.length(), 201).unwrap();
    let mut rel = Vec::new();
    println!(" T [N]  |tip diff| [m]  relative   bound max(|q| + d k)");
    for t in [0.05, 0.1, 0.5, 1.0, 2.0, 5.0] {
        let planar = solve_planar(&arm, t, &samples, PlanarMethod::ClosedForm).unwrap();
        let tendon = common::tendon_with(
            Routing::RadiusProportional {
                ratio: arm.offset_ratio(),
                angle: 0.0,
            },
            t,
            None,
        )
        .unwrap();
        let sol = common::solve(&rod, &[tendon], &Loads::default(), &rk4(400)).unwrap();
        let tip = sol.tip_position();
        let (px, py) = (planar.tip[0], planar.tip[1]);
        let diff = ((px - tip[2]).powi(2) + (py - tip[0]).powi(2) + tip[1].powi(2)).sqrt();
        let defl = (py.powi(2) + (arm.length() - px).powi(2)).sqrt();
        let bound = samples
            .iter()
            .zip(planar.curvature.iter().zip(&planar.strain))
            .map(|(&s, (&k, &q))| q.abs() + arm.offset_ratio() * arm.radius(s) * k.abs())
            .fold(0.0f64, f64::max);
        println!("{t:5.2}  {diff:.3e}      {:.3e}  {bound:.3e}", diff / defl);
        assert!(
            diff / defl < bound,
            "T = {t}: relative difference {} >= {bound}",
            diff / defl
        );
        assert!(tip[1].abs() < 1e-12, "planar problem must stay planar");
        rel.push(diff / defl);
    }
    // First order in T: halving T from 0.1 to 0.05 N halves the relative difference.
    let ratio = rel[0] / rel[1];
    assert!((0.45..0.55).contains(&ratio), "ratio {ratio}");
}

#[test]
fn precurved_rod_rests_in_its_rest_shape() {
    use softrod::Profile;
    let (l, kappa): (f64, f64) = (0.4, 5.0);
    let rod = Rod::new(
        l,
        Section::tube(0.003, 0.002).unwrap(),
        LinearElastic::new(1e8, 0.3).unwrap(),
    )
    .unwrap()
    .with_rest_curvature(Profile::Constant(Vector3::new(0.0, kappa, 0.0)))
    .unwrap();
    let sol = common::solve(&rod, &[], &Loads::default(), &rk4(400)).unwrap();
    let exact = [
        (1.0 - (kappa * l).cos()) / kappa,
        0.0,
        (kappa * l).sin() / kappa,
    ];
    assert!(dist(sol.tip_position(), exact) < 1e-10);
    assert!(sol
        .m_world
        .iter()
        .all(|m| m.iter().all(|c| c.abs() < 1e-15)));
}

#[test]
fn small_loads_match_euler_bernoulli_cantilever() {
    use softrod::PointLoad;
    // Inextensible cantilever, deflection/L ~ 1e-5, so geometric nonlinearity is ~1e-10
    // relative: uniform load q -> q L^4 / (8 E I); gravity rho A g is the same load; a point
    // force P at a -> P a^2 (3 L - a) / (6 E I).
    let (l, r, e, rho): (f64, f64, f64, f64) = (0.5, 0.002, 2e9, 1000.0);
    let ei = e * PI * r.powi(4) / 4.0;
    let area = PI * r * r;
    let rod = Rod::new(
        l,
        Section::circular(r).unwrap(),
        LinearElastic::new(e, 0.3).unwrap(),
    )
    .unwrap()
    .with_inextensible(true)
    .with_density(rho)
    .unwrap();
    let q = 8.0 * ei * 1e-5 / l.powi(3);
    let w_q = q * l.powi(4) / (8.0 * ei);
    let dist_load = Loads {
        distributed_force: Some(softrod::Profile::Constant(Vector3::new(q, 0.0, 0.0))),
        ..Default::default()
    };
    let grav = Loads {
        gravity: Vector3::new(q / (rho * area), 0.0, 0.0),
        ..Default::default()
    };
    for loads in [dist_load, grav] {
        let sol = common::solve(&rod, &[], &loads, &rk4(200)).unwrap();
        let w = sol.tip_position()[0];
        assert!((w - w_q).abs() < 1e-6 * w_q, "{w} vs {w_q}");
        // Base reaction: the whole load.
        assert!((sol.n_world[0][0] - q * l).abs() < 1e-12 * q * l);
    }
    let a = 0.3;
    let p = 6.0 * ei * 1e-5 * l / (a * a * (3.0 * l - a));
    let mut loads = Loads::default();
    loads
        .point_loads
        .push(PointLoad::force(a, Vector3::new(p, 0.0, 0.0)));
    let sol = common::solve(&rod, &[], &loads, &rk4(200)).unwrap();
    let w_p = p * a * a * (3.0 * l - a) / (6.0 * ei);
    assert!((sol.tip_position()[0] - w_p).abs() < 1e-6 * w_p);
    // The internal force jumps by the point force at s = a (the sample appears twice).
    let i = sol.s.iter().position(|&s| s == a).unwrap();
    assert_eq!(sol.s[i + 1], a);
    assert!((sol.n_world[i][0] - sol.n_world[i + 1][0] - p).abs() < 1e-12 * p);
}

#[test]
fn uniform_distributed_moment_bends_with_the_exact_angle() {
    // A world-frame distributed moment l about x on an inextensible rod along z: the internal
    // moment is l (L - s) about x, the rod bends in the y-z plane with the exact angle
    // theta(s) = l (L s - s²/2) / (E I), and p(s) = ∫ (0, -sin theta, cos theta) ds.
    use softrod::Profile;
    let (l, r, e): (f64, f64, f64) = (0.4, 0.002, 1e8);
    let ei = e * PI * r.powi(4) / 4.0;
    let l0 = 2.0 * ei / (l * l); // tip angle 1 rad
    let rod = Rod::new(
        l,
        Section::circular(r).unwrap(),
        LinearElastic::new(e, 0.3).unwrap(),
    )
    .unwrap()
    .with_inextensible(true);
    let loads = Loads {
        distributed_moment: Some(Profile::Constant(Vector3::new(l0, 0.0, 0.0))),
        ..Default::default()
    };
    let sol = common::solve(&rod, &[], &loads, &rk4(400)).unwrap();
    let theta = |s: f64| l0 * (l * s - 0.5 * s * s) / ei;
    let y = quad(|s| -theta(s).sin(), 0.0, l, 100);
    let z = quad(|s| theta(s).cos(), 0.0, l, 100);
    let err = dist(sol.tip_position(), [0.0, y, z]);
    println!("distributed moment: tip error {err:.2e} m");
    assert!(err < 1e-10);
}

#[test]
fn tabulated_and_function_sections_match_the_circle() {
    use softrod::SectionProperties;
    use std::sync::Arc;
    let (l, r, e): (f64, f64, f64) = (0.3, 0.003, 3e6);
    let mat = LinearElastic::new(e, 0.4).unwrap();
    let c = SectionProperties::circle(r, 0.0);
    let table = Section::table(&[0.0, l], &[c.area; 2], &[c.ix; 2], &[c.iy; 2], &[c.j; 2]).unwrap();
    let func = Section::function(Arc::new(move |_| SectionProperties::circle(r, 0.0)));
    let t = common::tendon([0.002, 0.001], 0.5, Some(0.2)).unwrap();
    let loads = Loads::tip_force(Vector3::new(0.01, 0.0, 0.0));
    let tips: Vec<[f64; 3]> = [Section::circular(r).unwrap(), table, func]
        .into_iter()
        .map(|sec| {
            let rod = Rod::new(l, sec, mat)
                .unwrap()
                .with_shear_coefficient(0.9)
                .unwrap();
            common::solve(&rod, std::slice::from_ref(&t), &loads, &rk4(80))
                .unwrap()
                .tip_position()
        })
        .collect();
    assert!(dist(tips[0], tips[1]) < 1e-14 && dist(tips[0], tips[2]) < 1e-14);
}

#[test]
fn inextensible_rod_with_tendon_bends_without_stretch() {
    // Kirchhoff limit: v = v* exactly, the tendon's compression is a reaction, and the
    // curvature is still tau d / (E I); here with the offset along body y (bending about -x).
    let (l, r, e): (f64, f64, f64) = (0.25, 0.004, 3e6);
    let (tau, d) = (2.0, 0.003);
    let rod = Rod::new(
        l,
        Section::circular(r).unwrap(),
        LinearElastic::new(e, 0.45).unwrap(),
    )
    .unwrap()
    .with_inextensible(true);
    let kappa = tau * d / (e * PI * r.powi(4) / 4.0);
    let t = common::tendon([0.0, d], tau, None).unwrap();
    let sol = common::solve(&rod, &[t], &Loads::default(), &rk4(400)).unwrap();
    for (u, v) in sol.u.iter().zip(&sol.v) {
        assert!((u[0] + kappa).abs() <= 1e-10 * kappa && u[1].abs() < 1e-12 && u[2].abs() < 1e-12);
        assert_eq!(*v, [0.0, 0.0, 1.0]);
    }
    let exact = [
        0.0,
        (1.0 - (kappa * l).cos()) / kappa,
        (kappa * l).sin() / kappa,
    ];
    assert!(dist(sol.tip_position(), exact) < 1e-10);
    assert!((sol.n_body[3][2] + tau).abs() < 1e-12);
}

#[test]
fn user_routing_function_matches_the_builtin_helix() {
    use softrod::Routing;
    use std::sync::Arc;
    let (rho, pitch, phase): (f64, f64, f64) = (0.002, 0.15, 0.4);
    let w = 2.0 * PI / pitch;
    let rod = Rod::new(
        0.3,
        Section::circular(0.003).unwrap(),
        LinearElastic::new(5e6, 0.4).unwrap(),
    )
    .unwrap();
    let builtin = common::tendon_with(
        Routing::Helical {
            radius: rho,
            pitch,
            phase,
        },
        0.8,
        Some(0.25),
    )
    .unwrap();
    let user = common::tendon_with(
        Routing::Function {
            offset: Arc::new(move |s| [rho * (phase + w * s).cos(), rho * (phase + w * s).sin()]),
            derivative: Arc::new(move |s| {
                [
                    -rho * w * (phase + w * s).sin(),
                    rho * w * (phase + w * s).cos(),
                ]
            }),
        },
        0.8,
        Some(0.25),
    )
    .unwrap();
    let loads = Loads::tip_force(Vector3::new(0.0, 0.01, 0.0));
    let a = common::solve(&rod, &[builtin], &loads, &rk4(80)).unwrap();
    let b = common::solve(&rod, &[user], &loads, &rk4(80)).unwrap();
    assert!(dist(a.tip_position(), b.tip_position()) < 1e-14);
    assert!((a.tendon_lengths[0] - b.tendon_lengths[0]).abs() < 1e-15);
}

#[test]
fn the_mesh_control_counts_a_routing_function_s_rate_as_the_builtin_helix_s() {
    // A helix given as a function turns at |r'| / max |r| = 2π / pitch, the built-in helix's
    // rate, and the estimated tip error of the RK4 mesh (which counts it) is the same for both.
    use softrod::Routing;
    use std::sync::Arc;
    let (rho, pitch): (f64, f64) = (0.002, 0.02);
    let w = 2.0 * PI / pitch;
    let function = Routing::Function {
        offset: Arc::new(move |s| [rho * (w * s).cos(), rho * (w * s).sin()]),
        derivative: Arc::new(move |s| [-rho * w * (w * s).sin(), rho * w * (w * s).cos()]),
    };
    let helix = Routing::Helical {
        radius: rho,
        pitch,
        phase: 0.0,
    };
    let rod = Rod::new(
        0.4,
        Section::circular(5e-3).unwrap(),
        LinearElastic::new(5e6, 0.3).unwrap(),
    )
    .unwrap();
    let mut errors = Vec::new();
    for routing in [function, helix] {
        let tendon = common::tendon_with(routing, 1.0, None).unwrap();
        for s in [0.0, 0.013, 0.3] {
            assert!((tendon.tendon.turn_rate_at(s, rho) - w).abs() <= 1e-12 * w);
        }
        let sol = common::solve(&rod, &[tendon], &Loads::default(), &rk4(40)).unwrap();
        errors.push(softrod::cosserat::mesh::rk4_position_error(&sol));
    }
    // (40 steps turn this helix π each: far beyond the default limit of 1e-4 L.)
    assert!(errors[0] > 1e-2, "{errors:?}");
    assert!(
        (errors[0] - errors[1]).abs() <= 1e-9 * errors[1],
        "{errors:?}"
    );
}
