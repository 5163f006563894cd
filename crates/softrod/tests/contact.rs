//! Unilateral frictionless contact with obstacles, against beam theory: a cantilever pushed
//! onto a parallel plane at its tip; every contact solution checked for penetration, the sign
//! and direction of the forces and global balance.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use softrod::nalgebra::Vector3;
use softrod::{solve_constrained, Actuation, ContactSolution, Loads, Obstacle, RobotModel};

use common::{beam as rod, rk4_options as options, BEAM_E as E, BEAM_LENGTH as L, BEAM_NU as NU};

/// The checks of every contact solution: no penetration beyond 1e-9 m at any node,
/// non-negative normal forces along the obstacle normal, and the base wrench equal to the
/// applied tip force and the contact forces (about the base) to 1e-10 of `scale`.
fn assert_contact_solution(
    sol: &ContactSolution,
    obstacles: &[Obstacle],
    radius: f64,
    applied: &[(Vector3<f64>, Vector3<f64>)],
    scale: f64,
) {
    for p in &sol.solution.position {
        for o in obstacles {
            let g = o.distance(&Vector3::from(*p)).0 - radius;
            assert!(g >= -1e-9, "penetration {g:e} at {p:?}");
        }
    }
    let (mut f, mut m) = (Vector3::zeros(), Vector3::zeros());
    for c in &sol.contacts {
        assert!(c.normal_force >= 0.0, "pulling contact {c:?}");
        assert!(c.tangential_force.iter().all(|t| *t == 0.0));
        let (_, n) = obstacles[c.obstacle].distance(&Vector3::from(c.point));
        assert!((n - Vector3::from(c.normal)).norm() < 1e-9);
    }
    let total: Vector3<f64> = sol.contact_force.iter().map(|v| Vector3::from(*v)).sum();
    let by_contact: Vector3<f64> = sol
        .contacts
        .iter()
        .map(|c| Vector3::from(c.normal) * c.normal_force)
        .sum();
    assert!((total - by_contact).norm() <= 1e-12 * scale);
    for (j, cf) in sol.contact_force.iter().enumerate() {
        let cf = Vector3::from(*cf);
        f += cf;
        m += Vector3::from(sol.solution.position[j]).cross(&cf);
    }
    for (p, force) in applied {
        f += force;
        m += p.cross(force);
    }
    let b = sol.solution.base_wrench;
    for k in 0..3 {
        assert!(
            (b[k] - f[k]).abs() <= 1e-10 * scale,
            "force {k}: {} vs {}",
            b[k],
            f[k]
        );
        assert!(
            (b[3 + k] - m[k]).abs() <= 1e-10 * scale * L,
            "moment {k}: {} vs {}",
            b[3 + k],
            m[k]
        );
    }
}

/// The cantilever of radius 1 mm beside the plane x = -(R + δ), δ = 1e-3 L (normal +x):
/// `(radius, E I, the tip force 3 E I δ / L³ that closes the gap, δ, the plane)`.
fn beside_a_plane() -> (f64, f64, f64, f64, Obstacle) {
    let radius = 1e-3;
    let delta = 1e-3 * L;
    let (ei, _, _, _) = common::circular_constants(E, NU, radius, 1.0);
    let closing = 3.0 * ei * delta / L.powi(3);
    let plane = Obstacle::plane([-(radius + delta), 0.0, 0.0], [1.0, 0.0, 0.0]).unwrap();
    (radius, ei, closing, delta, plane)
}

/// A cantilever along z pushed by a tip force toward the plane x = -(R + δ) (normal +x):
/// no contact below the force 3 E I δ / L³ that closes the gap, and beyond it a tip reaction
/// R = F - 3 E I δ / L³ (slender rod: shear below 1e-5 of it).
#[test]
fn tip_contact_with_a_parallel_plane_is_the_cantilever_closed_form() {
    let (radius, _, closing, _, plane) = beside_a_plane();
    let obstacles = [plane];
    for factor in [0.5, 0.99, 1.5, 2.0, 4.0] {
        let force = Vector3::new(-factor * closing, 0.0, 0.0);
        let model = RobotModel::rod_only(rod(radius), Loads::tip_force(force)).unwrap();
        let sol = solve_constrained(
            &model,
            &Actuation::default(),
            &options(100),
            None,
            &obstacles,
        )
        .unwrap();
        assert!(sol.solution.stats.converged);
        let tip = Vector3::from(sol.solution.tip_position());
        assert_contact_solution(&sol, &obstacles, radius, &[(tip, force)], closing);
        if factor < 1.0 {
            assert!(sol.contacts.is_empty(), "contact at F = {factor} F_c");
            let gap = obstacles[0].distance(&tip).0 - radius;
            assert!(gap > 0.0);
            continue;
        }
        assert_eq!(sol.contacts.len(), 1, "{:?}", sol.contacts);
        let c = sol.contacts[0];
        assert_eq!(c.s, L);
        let exact = (factor - 1.0) * closing;
        let err = (c.normal_force / exact - 1.0).abs();
        assert!(
            err < 1e-4,
            "F = {factor} F_c: R = {:e} vs {exact:e} ({err:e})",
            c.normal_force
        );
        println!(
            "tip contact F = {factor} F_c: R = {:e}, closed form {exact:e}, rel. error {err:e}",
            c.normal_force
        );
    }
}

/// A cantilever under a uniform load q above a frictionless floor at surface gap δ: it lies
/// on the floor from a = (72 E I δ / q)^(1/4) to the tip, with a concentrated reaction q a / 3
/// at the edge and the distributed reaction q beyond; the base, the edge and the floor carry
/// the total load q L.
#[test]
fn distributed_contact_with_a_floor_is_the_beam_closed_form() {
    let radius = 1e-3;
    let delta = 1e-3 * L;
    let (ei, _, _, _) = common::circular_constants(E, NU, radius, 1.0);
    let floor = Obstacle::plane([-(radius + delta), 0.0, 0.0], [1.0, 0.0, 0.0]).unwrap();
    let obstacles = [floor];
    // Below 8 E I δ / L⁴ the tip does not reach the floor.
    for a_exact in [f64::INFINITY, 0.8 * L, 0.5 * L, 0.3 * L] {
        let q = if a_exact.is_finite() {
            72.0 * ei * delta / a_exact.powi(4)
        } else {
            4.0 * ei * delta / L.powi(4)
        };
        let loads = Loads {
            distributed_force: Some(softrod::Profile::Constant(Vector3::new(-q, 0.0, 0.0))),
            ..Loads::default()
        };
        let model = RobotModel::rod_only(rod(radius), loads).unwrap();
        let sol = solve_constrained(
            &model,
            &Actuation::default(),
            &options(400),
            None,
            &obstacles,
        )
        .unwrap();
        assert!(sol.solution.stats.converged);
        if !a_exact.is_finite() {
            assert!(sol.contacts.is_empty());
            continue;
        }
        let edge = sol.contacts.iter().find(|c| c.length == 0.0).unwrap();
        let err_a = (edge.s / a_exact - 1.0).abs();
        let err_r = (edge.normal_force / (q * a_exact / 3.0) - 1.0).abs();
        let floor_part: f64 = sol
            .contacts
            .iter()
            .filter(|c| c.length > 0.0)
            .map(|c| c.normal_force)
            .sum();
        println!(
            "floor contact a = {:.5} (exact {a_exact:.5}, err {err_a:e}); edge reaction {:e} \
             (q a/3 = {:e}, err {err_r:e}); floor {floor_part:e} (q (L - a) = {:e})",
            edge.s,
            edge.normal_force,
            q * a_exact / 3.0,
            q * (L - a_exact)
        );
        assert!(err_a < 1e-2, "free length {} vs {a_exact}", edge.s);
        assert!(err_r < 3e-2, "edge reaction");
        for p in &sol.solution.position {
            let g = obstacles[0].distance(&Vector3::from(*p)).0 - radius;
            assert!(g >= -1e-9, "penetration {g:e}");
        }
        // Global force balance: base force (the base wrench is what the base carries) and the
        // contact forces against the load q L.
        let contact: Vector3<f64> = sol.contact_force.iter().map(|v| Vector3::from(*v)).sum();
        let b = sol.solution.base_wrench;
        let fx = b[0] - (contact.x - q * L);
        assert!(fx.abs() <= 1e-10 * q * L, "force balance {fx:e}");
    }
}

/// A cantilever pushed at its tip onto a sphere beside its middle: one interior contact at
/// the point of least gap, whose force is the propped-cantilever reaction
/// `R = (F c² (3L - c) / (6 E I) - δ) 3 E I / c³` (c the height of the sphere's centre, δ the
/// surface gap there).
#[test]
fn interior_contact_with_a_sphere_is_the_propped_cantilever() {
    let radius = 1e-3;
    let delta = 1e-3 * L;
    let (ei, _, _, _) = common::circular_constants(E, NU, radius, 1.0);
    let (c, rs) = (0.6 * L, 0.05 * L);
    let sphere = Obstacle::sphere([-(radius + delta + rs), 0.0, c], rs).unwrap();
    let obstacles = [sphere];
    let closing = delta * 6.0 * ei / (c * c * (3.0 * L - c));
    for factor in [0.8, 1.5, 3.0] {
        let force = Vector3::new(-factor * closing, 0.0, 0.0);
        let model = RobotModel::rod_only(rod(radius), Loads::tip_force(force)).unwrap();
        let sol = solve_constrained(
            &model,
            &Actuation::default(),
            &options(200),
            None,
            &obstacles,
        )
        .unwrap();
        assert!(sol.solution.stats.converged);
        let tip = Vector3::from(sol.solution.tip_position());
        assert_contact_solution(&sol, &obstacles, radius, &[(tip, force)], closing);
        if factor < 1.0 {
            assert!(sol.contacts.is_empty());
            continue;
        }
        assert_eq!(sol.contacts.len(), 1);
        let k = sol.contacts[0];
        assert!((k.s - c).abs() < 1e-2 * L, "contact at {}", k.s);
        let f = factor * closing;
        let exact = (f * c * c * (3.0 * L - c) / (6.0 * ei) - delta) * 3.0 * ei / c.powi(3);
        let err = (k.normal_force / exact - 1.0).abs();
        println!("sphere contact F = {factor} F_c at s = {:.6}: R = {:e}, propped cantilever {exact:e}, rel. error {err:e}", k.s, k.normal_force);
        assert!(err < 1e-3, "R = {:e} vs {exact:e}", k.normal_force);
    }
}

/// Compliance under contact: the cantilever's tip pressed on the parallel plane (2 F_c). Along
/// the plane's normal the contact holds the tip (compliance ≤ 1e-9 of the contact-free one);
/// along the plane it slides, and its compliance is the central difference of the
/// constrained nonlinear solve under a tip force along the plane. Without contact the
/// constrained compliance is the tangent compliance of the solution.
#[test]
fn compliance_under_contact_is_the_constrained_derivative() {
    let (radius, ei, closing, _, plane) = beside_a_plane();
    let obstacles = [plane];
    let solve = |force: Vector3<f64>| {
        let model = RobotModel::rod_only(rod(radius), Loads::tip_force(force)).unwrap();
        solve_constrained(
            &model,
            &Actuation::default(),
            &options(100),
            None,
            &obstacles,
        )
        .unwrap()
    };
    // Contact-free (F below the closing force): the constrained compliance is the tangent one.
    let free = solve(Vector3::new(-0.5 * closing, 0.0, 0.0));
    assert!(free.contacts.is_empty());
    let c_free = free.compliance.get().unwrap();
    let tangent =
        softrod::tangent_compliance(&free.solution, softrod::TendonControl::Tension, None)
            .unwrap()
            .world;
    let err_free = (c_free - tangent).amax() / tangent.amax();
    println!("contact-free: constrained vs tangent compliance, rel. {err_free:e}");
    assert!(err_free < 1e-9, "{err_free:e}");
    // Pressed on the plane.
    let force = Vector3::new(-2.0 * closing, 0.0, 0.0);
    let pressed = solve(force);
    assert_eq!(pressed.contacts.len(), 1);
    let c = pressed.compliance.get().unwrap();
    let normal = (c[(0, 0)] / c_free[(0, 0)]).abs();
    println!(
        "normal compliance {:e} (contact-free {:e}, ratio {normal:e})",
        c[(0, 0)],
        c_free[(0, 0)]
    );
    assert!(normal <= 1e-9, "normal compliance ratio {normal:e}");
    // In the plane (y): the central difference of the nonlinear solve.
    let h = 1e-4 * closing;
    let plus = solve(force + Vector3::new(0.0, h, 0.0));
    let minus = solve(force - Vector3::new(0.0, h, 0.0));
    assert!(plus.contacts.len() == 1 && minus.contacts.len() == 1);
    let (tp, tm) = (plus.solution.tip_position(), minus.solution.tip_position());
    for k in 0..3 {
        let fd = (tp[k] - tm[k]) / (2.0 * h);
        let err = (c[(k, 1)] - fd).abs() / c[(1, 1)].abs();
        println!(
            "in-plane: C[{k}][1] = {:e}, central difference {fd:e}, rel. {err:e}",
            c[(k, 1)]
        );
        assert!(err < 1e-6, "C[{k}][1] = {:e} vs {fd:e}", c[(k, 1)]);
    }
    // The slender cantilever: L³ / (3 E I) along the plane.
    let beam = L.powi(3) / (3.0 * ei);
    assert!((c[(1, 1)] / beam - 1.0).abs() < 1e-3);
}

/// Compliance under an interior contact: the cantilever propped by the sphere at 0.6 L
/// (1.5 F_c). The frictionless contact holds the normal and slides along the sphere; every
/// column of the constrained tip compliance (tip forces and moments) is the central
/// difference of the constrained nonlinear solve to 1e-6 of its largest entry.
#[test]
fn compliance_under_an_interior_contact_is_the_constrained_derivative() {
    let radius = 1e-3;
    let delta = 1e-3 * L;
    let (ei, _, _, _) = common::circular_constants(E, NU, radius, 1.0);
    let (c, rs) = (0.6 * L, 0.05 * L);
    let obstacles = [Obstacle::sphere([-(radius + delta + rs), 0.0, c], rs).unwrap()];
    let closing = delta * 6.0 * ei / (c * c * (3.0 * L - c));
    let base = [-1.5 * closing, 0.2 * closing, 0.0, 0.0, 0.0, 0.0];
    let solve = |w: [f64; 6]| {
        let loads = Loads {
            tip_force: Vector3::new(w[0], w[1], w[2]),
            tip_moment: Vector3::new(w[3], w[4], w[5]),
            ..Loads::default()
        };
        let model = RobotModel::rod_only(rod(radius), loads).unwrap();
        solve_constrained(
            &model,
            &Actuation::default(),
            &options(200),
            None,
            &obstacles,
        )
        .unwrap()
    };
    let sol = solve(base);
    assert_eq!(sol.contacts.len(), 1);
    assert!(sol.contacts[0].s < 0.99 * L, "an interior contact");
    let cm = sol.compliance.get().unwrap();
    let big = cm.amax();
    for k in 0..6 {
        let h = if k < 3 {
            1e-4 * closing
        } else {
            1e-4 * closing * L
        };
        let (mut wp, mut wm) = (base, base);
        wp[k] += h;
        wm[k] -= h;
        let (p, m) = (solve(wp), solve(wm));
        assert!(p.contacts.len() == 1 && m.contacts.len() == 1);
        let tip = |s: &ContactSolution| {
            let q = s.solution.tip_position();
            let r = s.solution.rotation.last().copied().unwrap();
            (
                Vector3::from(q),
                softrod::nalgebra::Matrix3::from_row_slice(r.concat().as_slice()),
            )
        };
        let ((pp, rp), (pm, rm)) = (tip(&p), tip(&m));
        // The rotation change as the axial vector of (R+ - R-) R0ᵀ / 2h (skew part).
        let (_, r0) = tip(&sol);
        let d = (rp - rm) * r0.transpose() / (2.0 * h);
        let w = Vector3::new(
            d[(2, 1)] - d[(1, 2)],
            d[(0, 2)] - d[(2, 0)],
            d[(1, 0)] - d[(0, 1)],
        ) * 0.5;
        let dp = (pp - pm) / (2.0 * h);
        let fd = [dp.x, dp.y, dp.z, w.x, w.y, w.z];
        let err = (0..6)
            .map(|i| (cm[(i, k)] - fd[i]).abs())
            .fold(0.0, f64::max)
            / big;
        println!("interior contact: compliance column {k} vs central difference, rel. {err:e}");
        assert!(err < 1e-6, "column {k}: rel. {err:e}");
    }
}

/// The stability of a contact solution with a free tip holds its frictionless contacts: for a
/// rod pressed on a small sphere by a tip force, its margin is the tip criterion of the
/// compliance under contact (checked above against central differences of the constrained
/// solve; the margin is the coarse mesh's, its sign being clear there: 2.9e-9 apart); the rod with the contact force as a dead load, solved again without obstacles, is
/// stable too (both softest in torsion; see `contact_stability.rs` for the closed forms).
#[test]
fn contact_stability_holds_the_contact() {
    let radius = 1e-3;
    let delta = 1e-3 * L;
    let (ei, _, _, _) = common::circular_constants(E, NU, radius, 1.0);
    let (c, rs) = (0.6 * L, 0.05 * L);
    let obstacles = [Obstacle::sphere([-(radius + delta + rs), 0.0, c], rs).unwrap()];
    let closing = delta * 6.0 * ei / (c * c * (3.0 * L - c));
    let force = Vector3::new(-1.5 * closing, 0.0, 0.0);
    let model = RobotModel::rod_only(rod(radius), Loads::tip_force(force)).unwrap();
    let opts = options(200);
    let sol = solve_constrained(&model, &Actuation::default(), &opts, None, &obstacles).unwrap();
    assert_eq!(sol.contacts.len(), 1);
    let margin = sol.solution.stability_margin();
    let m = &sol.solution.model;
    let expected =
        common::tip_criterion(&sol.compliance.get().unwrap(), m.length(), m.force_scale());
    let again = softrod::solve_statics(m, &Actuation::default(), &opts).unwrap();
    let err = (margin / expected - 1.0).abs();
    println!(
        "contact stability margin {margin:e}, tip criterion {expected:e} (rel. {err:e}), dead-load re-solve {:e}",
        again.stability_margin()
    );
    assert!(sol.solution.stable && again.stable);
    assert!(err < 1e-6, "{margin:e} vs {expected:e}");
}

/// An obstacle the rod lies in at rest is refused by name (`obstacles[i]`), before any solve:
/// a plane whose solid side holds the base (half the rod inside), a sphere around the base, and
/// a sphere of 1 mm around the backbone midway between two nodes 25 mm apart (only the samples
/// between the nodes see it). Before, the first two returned converged with no contact and the
/// rod half inside the plane (the least gap lay at the clamped base, where no contact is
/// sought), and the third raised a convergence error naming no obstacle. A rod mounted on a
/// plane through its base lies on its surface, not in it: it solves, and its tip is the
/// contact-free cantilever's (the tip force pulls it away from the plane).
#[test]
fn an_obstacle_the_rod_lies_in_at_rest_is_refused_by_name() {
    let radius = 1e-3;
    let model =
        RobotModel::rod_only(rod(radius), Loads::tip_force(Vector3::new(0.005, 0.0, 0.0))).unwrap();
    let opts = options(40);
    let refused = |obstacles: &[Obstacle], index: usize| match solve_constrained(
        &model,
        &Actuation::default(),
        &opts,
        None,
        obstacles,
    ) {
        Err(softrod::Error::InvalidParameter { name, expected, .. }) => {
            assert_eq!(name, format!("obstacles[{index}]"));
            assert!(expected.contains("clear of the rod at rest"), "{expected}");
        }
        Ok(sol) => panic!(
            "obstacles[{index}] accepted: tip {:?}",
            sol.solution.tip_position()
        ),
        Err(e) => panic!("obstacles[{index}]: {e}"),
    };
    let far = Obstacle::sphere([0.5, 0.5, 0.5], 0.01).unwrap();
    refused(
        &[Obstacle::plane([0.0, 0.0, 0.5], [0.0, 0.0, 1.0]).unwrap()],
        0,
    );
    refused(&[Obstacle::sphere([0.0, 0.0, 0.0], 0.01).unwrap()], 0);
    refused(
        &[
            far.clone(),
            Obstacle::sphere([0.0, 0.0, 0.5125], 1e-3).unwrap(),
        ],
        1,
    );
    let mount = Obstacle::plane([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]).unwrap();
    let mounted = solve_constrained(&model, &Actuation::default(), &opts, None, &[mount]).unwrap();
    let free = softrod::solve_statics(&model, &Actuation::default(), &opts).unwrap();
    let (a, b) = (mounted.solution.tip_position(), free.tip_position());
    assert!(
        (Vector3::from(a) - Vector3::from(b)).norm() < 1e-12,
        "{a:?} vs {b:?}"
    );
}
