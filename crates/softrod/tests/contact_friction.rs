//! Coulomb friction at a tip contact, against the small-deflection cantilever under
//! proportional loading: a cantilever along z beside the plane x = -(R + δ) (normal +x) under
//! the tip force (-Fx, Fy, 0), Fx above the force F_c = 3 E I δ / L³ that closes the gap.
//!
//! The tip touches the plane at the load fraction λ0 = F_c / Fx, where its tangential
//! position is y_touch = λ0 Fy L³ / (3 E I); the normal reaction is then R = Fx - F_c. If it
//! sticks it stays at y_touch and the tangential reaction is -(1 - λ0) Fy, inside the cone
//! iff |Fy| ≤ μ Fx (the ratio of the reaction components is the same at every load fraction
//! after the touch); otherwise it slides, the tangential reaction is -sign(Fy) μ R and the tip
//! is at y = (Fy - sign(Fy) μ R) L³ / (3 E I).
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use softrod::nalgebra::Vector3;
use softrod::{
    solve_constrained, Actuation, ContactSolution, ContactState, Error, Loads, Obstacle, RobotModel,
};

use common::{beam as rod, rk4_options as options, BEAM_E as E, BEAM_LENGTH as L, BEAM_NU as NU};

/// Radius (m) of the cantilever.
const RADIUS: f64 = 1e-3;
/// Surface gap (m) to the plane.
const DELTA: f64 = 1e-3 * L;

/// `(E I, F_c)` of the cantilever.
fn constants() -> (f64, f64) {
    let (ei, _, _, _) = common::circular_constants(E, NU, RADIUS, 1.0);
    (ei, 3.0 * ei * DELTA / L.powi(3))
}

fn plane(mu: f64) -> Obstacle {
    Obstacle::plane([-(RADIUS + DELTA), 0.0, 0.0], [1.0, 0.0, 0.0])
        .unwrap()
        .with_friction(mu)
        .unwrap()
}

fn solve(force: Vector3<f64>, obstacle: &Obstacle) -> ContactSolution {
    solve_rod(RADIUS, force, obstacle)
}

/// The cantilever of radius `radius` (m) under the tip force `force` (N) against `obstacle`,
/// RK4 on 100 steps; converged.
fn solve_rod(radius: f64, force: Vector3<f64>, obstacle: &Obstacle) -> ContactSolution {
    let model = RobotModel::rod_only(rod(radius), Loads::tip_force(force)).unwrap();
    let sol = solve_constrained(
        &model,
        &Actuation::default(),
        &options(100),
        None,
        std::slice::from_ref(obstacle),
    )
    .unwrap();
    assert!(sol.solution.stats.converged);
    sol
}

/// [`assert_balanced_with`] for the cantilever of radius [`RADIUS`].
fn assert_balanced(sol: &ContactSolution, obstacle: &Obstacle, force: Vector3<f64>, scale: f64) {
    assert_balanced_with(sol, obstacle, RADIUS, force, scale);
}

/// No node of a rod of radius `radius` penetrates by more than 1e-9 m, the force is inside
/// the cone (on it to 1e-10 when sliding) and split into its normal and tangential parts,
/// and the base wrench equals the applied tip force and the contact forces (about the base)
/// to 1e-10 of `scale`.
fn assert_balanced_with(
    sol: &ContactSolution,
    obstacle: &Obstacle,
    radius: f64,
    force: Vector3<f64>,
    scale: f64,
) {
    for p in &sol.solution.position {
        let g = obstacle.distance(&Vector3::from(*p)).0 - radius;
        assert!(g >= -1e-9, "penetration {g:e} at {p:?}");
    }
    let mu = obstacle.friction();
    for c in &sol.contacts {
        let n = Vector3::from(c.normal);
        let t = Vector3::from(c.tangential_force);
        assert!(c.normal_force >= 0.0);
        assert!(t.dot(&n).abs() <= 1e-15 * scale, "tangential force along n");
        // Inside the cone (on it to 1e-10 of μ f_n when sliding), beyond the round-off of
        // splitting the force into its normal and tangential parts (1e-14 f_n, which a
        // vanishing μ shows).
        let split = 1e-14 * c.normal_force;
        assert!(
            t.norm() <= mu * c.normal_force * (1.0 + 1e-9) + split,
            "outside the cone: |f_t| = {:e}, mu f_n = {:e}",
            t.norm(),
            mu * c.normal_force
        );
        if c.state == ContactState::Slide {
            let off = (t.norm() - mu * c.normal_force).abs();
            assert!(
                off <= 1e-10 * mu * c.normal_force + split,
                "sliding off the cone by {off:e} N"
            );
        }
    }
    let tip = Vector3::from(sol.solution.tip_position());
    let (mut f, mut m) = (force, tip.cross(&force));
    for (j, cf) in sol.contact_force.iter().enumerate() {
        let cf = Vector3::from(*cf);
        f += cf;
        m += Vector3::from(sol.solution.position[j]).cross(&cf);
    }
    let by_contact: Vector3<f64> = sol
        .contacts
        .iter()
        .map(|c| Vector3::from(c.normal) * c.normal_force + Vector3::from(c.tangential_force))
        .sum();
    let total: Vector3<f64> = sol.contact_force.iter().map(|v| Vector3::from(*v)).sum();
    assert!((total - by_contact).norm() <= 1e-12 * scale);
    let b = sol.solution.base_wrench;
    for k in 0..3 {
        assert!((b[k] - f[k]).abs() <= 1e-10 * scale, "force {k}");
        assert!((b[3 + k] - m[k]).abs() <= 1e-10 * scale * L, "moment {k}");
    }
}

/// Sticking and sliding at the tip: reactions, tip position and state against the
/// proportional-loading closed form to 1e-4 relative.
#[test]
fn tip_friction_sticks_and_slides_as_the_cantilever_closed_form() {
    let (ei, fc) = constants();
    let c = L.powi(3) / (3.0 * ei);
    let mu = 0.5;
    let obstacle = plane(mu);
    // (Fx / F_c, Fy / F_c): stick iff |Fy| <= mu Fx.
    for (ax, ay) in [
        (2.0, 0.5),
        (2.0, -0.9),
        (3.0, 1.2),
        (2.0, 2.0),
        (2.0, -1.5),
        (4.0, 3.0),
    ] {
        let (fx, fy) = (ax * fc, ay * fc);
        let force = Vector3::new(-fx, fy, 0.0);
        let sol = solve(force, &obstacle);
        assert_balanced(&sol, &obstacle, force, fx);
        assert_eq!(sol.contacts.len(), 1, "{:?}", sol.contacts);
        let k = sol.contacts[0];
        assert_eq!(k.s, L);
        let lambda0 = fc / fx;
        let normal = fx - fc;
        let stick = fy.abs() <= mu * fx;
        let (ft, y) = if stick {
            (-(1.0 - lambda0) * fy, lambda0 * fy * c)
        } else {
            let ft = -fy.signum() * mu * normal;
            (ft, (fy + ft) * c)
        };
        let tip = sol.solution.tip_position();
        let err_n = (k.normal_force / normal - 1.0).abs();
        let err_t = (k.tangential_force[1] / ft - 1.0).abs();
        let err_y = (tip[1] / y - 1.0).abs();
        println!(
            "Fx = {ax} F_c, Fy = {ay} F_c: {:?}; R = {:e} (err {err_n:e}), f_t = {:e} \
             (closed form {ft:e}, err {err_t:e}), tip y = {:e} (closed form {y:e}, err {err_y:e})",
            k.state, k.normal_force, k.tangential_force[1], tip[1]
        );
        let expected = if stick {
            ContactState::Stick
        } else {
            ContactState::Slide
        };
        assert_eq!(k.state, expected, "Fx = {ax} F_c, Fy = {ay} F_c");
        assert!(err_n < 1e-4, "normal reaction");
        assert!(err_t < 1e-4, "tangential reaction");
        assert!(err_y < 1e-4, "tip y");
        // Along the rod: zero in the closed form. Sticking, the tip is held where it touched
        // and the rod feels only the total tip force, so the reaction is -(1 - λ0) times
        // the applied force in every component (here to the accuracy of the touch point
        // times the axial stiffness E A / L); sliding, the slip has the axial shortening of
        // the bent rod (second order in the deflection).
        let axial = k.tangential_force[2].abs();
        println!("  axial component {axial:e} N (F_c = {fc:e} N)");
        assert!(k.tangential_force[0].abs() <= 1e-12 * fc);
        assert!(axial <= if stick { 1e-6 * fc } else { 1e-2 * ft.abs() });
        if !stick {
            let ratio = Vector3::from(k.tangential_force).norm() / (mu * k.normal_force);
            assert!(
                (ratio - 1.0).abs() < 1e-10,
                "sliding force off the cone: {ratio}"
            );
        }
    }
}

/// Radius (m) of the cantilever pressed onto the post: stout enough (R/L = 0.01) that the
/// axial tension a sticking contact inside the rod picks up from the shortening of the bent
/// rod stays far below the friction (see the test below).
const POST_ROD: f64 = 1e-2;
/// Surface gap (m) between that cantilever and the post.
const POST_GAP: f64 = 1e-6 * L;
/// Arc length (m) at which the post lies under the rod.
const POST_AT: f64 = 0.6 * L;
/// Radius (m) of the post.
const POST_RADIUS: f64 = 0.05 * L;

/// The post: a cylinder across the cantilever (axis along y, half-length 0.2 L) at
/// `z = POST_AT`, its top at `x = -(POST_ROD + POST_GAP)` (so the outward normal under the
/// rod is +x), with friction `mu`. Along y its surface is straight: a sideways displacement
/// of the rod does not tilt the normal.
fn post(mu: f64) -> Obstacle {
    let x = -(POST_ROD + POST_GAP + POST_RADIUS);
    Obstacle::cylinder([x, -0.2 * L, POST_AT], [x, 0.2 * L, POST_AT], POST_RADIUS)
        .unwrap()
        .with_friction(mu)
        .unwrap()
}

/// Flexibilities (m/N) of the Timoshenko cantilever of radius [`POST_ROD`] (bending and
/// Cowper's shear area, as the rod's section): `α` at `a` under a unit force at `a`, `β` at
/// `a` under a unit force at `L` (and at `L` under one at `a`), `γ` at `L` under one at `L`.
fn post_flexibilities() -> (f64, f64, f64) {
    let k = 6.0 * (1.0 + NU) / (7.0 + 6.0 * NU);
    let (ei, _, _, gas) = common::circular_constants(E, NU, POST_ROD, k);
    let a = POST_AT;
    (
        a.powi(3) / (3.0 * ei) + a / gas,
        a * a * (3.0 * L - a) / (6.0 * ei) + a / gas,
        L.powi(3) / (3.0 * ei) + L / gas,
    )
}

/// Coulomb friction inside the rod, against the propped cantilever under proportional
/// loading: the cantilever over the post at `a` = 0.6 L (surface gap δ = 1e-6 L) under the
/// tip force (-Fx, Fy, 0). With the flexibilities `α, β, γ` ([`post_flexibilities`]) the
/// rod touches the post at the load fraction `λ0 = δ / (Fx β)`, where the rod at `a` is at
/// `y = λ0 Fy β`; after it the post props the rod at `a`, and the load `(1 - λ0) F` is
/// shared: the normal reaction is `R = (1 - λ0) Fx β / α`. Sticking, `y(a)` stays where it
/// touched and the sideways reaction is `-(1 - λ0) Fy β / α`: the ratio of the two reactions
/// is `|Fy| / Fx` at every load fraction after the touch, so the contact sticks iff
/// `|Fy| <= μ Fx`. Sliding, the sideways reaction is `-sign(Fy) μ R` (the slip has the sign
/// of Fy). The tip is at `x = -Fx γ + R β`, `y = Fy γ + R_y β`. Reactions and tip to 1e-4
/// relative: the neglected effects are far below it (rotations ~1e-5 rad, so the
/// geometric nonlinearity is ~1e-10 and the contact moves along the post by ~5e-7 m; the
/// axial tension a sticking contact takes from the shortening of the bent rod, printed, is
/// of order `E A δ² / a²`, about 1e-2 of the friction, and acts along the rod, not
/// sideways).
#[test]
fn interior_friction_sticks_and_slides_as_the_propped_cantilever() {
    let (alpha, beta, gamma) = post_flexibilities();
    let fc = POST_GAP / beta;
    let mu = 0.5;
    let obstacle = post(mu);
    for (ax, ay) in [
        (2.0, 0.5),
        (2.0, -0.9),
        (3.0, 1.2),
        (2.0, 2.0),
        (2.0, -1.5),
        (4.0, 3.0),
    ] {
        let (fx, fy) = (ax * fc, ay * fc);
        let force = Vector3::new(-fx, fy, 0.0);
        let sol = solve_rod(POST_ROD, force, &obstacle);
        assert_balanced_with(&sol, &obstacle, POST_ROD, force, fx);
        assert_eq!(sol.contacts.len(), 1, "{:?}", sol.contacts);
        let k = sol.contacts[0];
        assert!((k.s - POST_AT).abs() < 1e-4 * L, "contact at {}", k.s);
        let lambda0 = fc / fx;
        let normal = (1.0 - lambda0) * fx * beta / alpha;
        let stick = fy.abs() <= mu * fx;
        let ft = if stick {
            -(1.0 - lambda0) * fy * beta / alpha
        } else {
            -fy.signum() * mu * normal
        };
        let (x, y) = (-fx * gamma + normal * beta, fy * gamma + ft * beta);
        let tip = sol.solution.tip_position();
        let err_n = (k.normal_force / normal - 1.0).abs();
        let err_t = (k.tangential_force[1] / ft - 1.0).abs();
        let (err_x, err_y) = ((tip[0] / x - 1.0).abs(), (tip[1] / y - 1.0).abs());
        println!(
            "Fx = {ax} F_c, Fy = {ay} F_c: {:?} at s = {:.9}; R = {:e} (err {err_n:.1e}), \
             f_t = {:e} (err {err_t:.1e}), tip x err {err_x:.1e}, tip y err {err_y:.1e}; \
             axial {:.1e} of mu R",
            k.state,
            k.s,
            k.normal_force,
            k.tangential_force[1],
            k.tangential_force[2].abs() / (mu * normal)
        );
        let expected = if stick {
            ContactState::Stick
        } else {
            ContactState::Slide
        };
        assert_eq!(k.state, expected, "Fx = {ax} F_c, Fy = {ay} F_c");
        assert!(err_n < 1e-4, "normal reaction");
        assert!(err_t < 1e-4, "sideways reaction");
        assert!(err_x < 1e-4, "tip x");
        assert!(err_y < 1e-4, "tip y");
    }
}

/// μ = 0 and μ = 1e-12 reproduce the frictionless solve (tip position to 1e-12 m), and a
/// frictionless obstacle reports frictionless contacts with no tangential force.
#[test]
fn vanishing_friction_is_the_frictionless_solve() {
    let (_, fc) = constants();
    let base = Obstacle::plane([-(RADIUS + DELTA), 0.0, 0.0], [1.0, 0.0, 0.0]).unwrap();
    assert_eq!(base.friction(), 0.0);
    for (ax, ay) in [(2.0, 0.7), (3.0, -2.0)] {
        let force = Vector3::new(-ax * fc, ay * fc, 0.0);
        let free = solve(force, &base);
        assert_eq!(free.contacts[0].state, ContactState::Frictionless);
        assert_eq!(free.contacts[0].tangential_force, [0.0; 3]);
        for mu in [0.0, 1e-12] {
            let sol = solve(force, &plane(mu));
            assert_balanced(&sol, &plane(mu), force, ax * fc);
            let (a, b) = (sol.solution.tip_position(), free.solution.tip_position());
            let d = (Vector3::from(a) - Vector3::from(b)).norm();
            println!("Fx = {ax} F_c, Fy = {ay} F_c, mu = {mu:e}: tip vs frictionless {d:e} m");
            assert!(d <= 1e-12, "mu = {mu}: {d:e} m");
            let want = if mu == 0.0 {
                ContactState::Frictionless
            } else {
                ContactState::Slide
            };
            assert_eq!(sol.contacts[0].state, want);
        }
    }
}

/// Inside the rod too: μ = 0 is the frictionless solve exactly (the same shape and
/// contact), and μ = 1e-12 reproduces its tip to 1e-12 m (the deflection is ~1e-5 m here).
#[test]
fn vanishing_friction_inside_the_rod_is_the_frictionless_solve() {
    let (_, beta, _) = post_flexibilities();
    let fc = POST_GAP / beta;
    let x = -(POST_ROD + POST_GAP + POST_RADIUS);
    let base =
        Obstacle::cylinder([x, -0.2 * L, POST_AT], [x, 0.2 * L, POST_AT], POST_RADIUS).unwrap();
    for (ax, ay) in [(2.0, 0.7), (3.0, -2.0)] {
        let force = Vector3::new(-ax * fc, ay * fc, 0.0);
        let free = solve_rod(POST_ROD, force, &base);
        assert_eq!(free.contacts[0].state, ContactState::Frictionless);
        assert_eq!(free.contacts[0].tangential_force, [0.0; 3]);
        let same = solve_rod(POST_ROD, force, &post(0.0));
        assert_eq!(same.contacts, free.contacts);
        assert_eq!(same.solution.position, free.solution.position);
        let sol = solve_rod(POST_ROD, force, &post(1e-12));
        assert_balanced_with(&sol, &post(1e-12), POST_ROD, force, ax * fc);
        let (a, b) = (sol.solution.tip_position(), free.solution.tip_position());
        let d = (Vector3::from(a) - Vector3::from(b)).norm();
        println!("Fx = {ax} F_c, Fy = {ay} F_c, mu = 1e-12: tip vs frictionless {d:e} m");
        assert!(d <= 1e-12, "{d:e} m");
        assert_eq!(sol.contacts[0].state, ContactState::Slide);
    }
}

/// The two-segment NiTi robot pressing a sphere with friction (μ = 0.1, 1), solved from a
/// straight rod: by its tendons (tensions [3, 0, 0, 0, 1, 0] N against the sphere of the
/// contact benchmark: the actuation is then stepped with the loads so that the contact's
/// first touch is on that path) and by tip forces on the unactuated robot, the larger of
/// which bends it past the sphere (the frictionless rod slides around its +y side, pushed
/// by the +y component of the force; with friction it must not end on the far side). One
/// contact inside the rod, sliding; converged, no penetration, forces inside the cone (on
/// it when sliding), global balance with the friction forces to 1e-10.
#[test]
fn niti_robot_pressing_a_sphere_with_friction_converges_and_balances() {
    let radius = 0.7e-3;
    // (tensions (N), tip force (N), sphere centre (m), sphere radius (m))
    type Case = ([f64; 6], Vector3<f64>, [f64; 3], f64);
    let cases: [Case; 3] = [
        (
            [3.0, 0.0, 0.0, 0.0, 1.0, 0.0],
            Vector3::zeros(),
            [0.0, 0.07, 0.25],
            0.06,
        ),
        (
            [0.0; 6],
            Vector3::new(-0.02, 0.005, 0.0),
            [-0.0357, 0.0, 0.25],
            0.03,
        ),
        (
            [0.0; 6],
            Vector3::new(-0.05, 0.02, 0.0),
            [-0.0357, 0.0, 0.25],
            0.03,
        ),
    ];
    for (tensions, force, center, r) in cases {
        for mu in [0.1, 1.0] {
            let sphere = Obstacle::sphere(center, r)
                .unwrap()
                .with_friction(mu)
                .unwrap();
            let tendons = common::niti_tendons(&tensions);
            let loads = Loads::tip_force(force);
            let (model, act) = common::split(&common::niti_rod(), &tendons, &[], &loads).unwrap();
            let sol = solve_constrained(
                &model,
                &act,
                &softrod::SolveOptions::default(),
                None,
                std::slice::from_ref(&sphere),
            )
            .unwrap();
            assert!(sol.solution.stats.converged);
            assert!(!sol.contacts.is_empty());
            for c in &sol.contacts {
                println!(
                    "tensions {tensions:?}, tip force {force:?}, mu = {mu}: {:?} at s = {:.4}, \
                     f_n = {:.4e} N, |f_t| = {:.4e} N ({} iterations)",
                    c.state,
                    c.s,
                    c.normal_force,
                    Vector3::from(c.tangential_force).norm(),
                    sol.solution.stats.iterations
                );
                assert!(c.s < 0.4, "a contact inside the rod");
                assert_ne!(c.state, ContactState::Frictionless);
            }
            let scale = sol.contacts.iter().map(|c| c.normal_force).sum::<f64>() + force.norm();
            assert_balanced_with(&sol, &sphere, radius, force, scale);
            assert!(
                sol.solution.tip_position()[1] * force.y >= 0.0,
                "on the far side"
            );
        }
    }
}

/// A friction coefficient must be finite and >= 0; a rod lying along a plane with friction
/// (a contact interval) is refused with an error naming `friction` (point contacts only).
#[test]
fn bad_friction_and_friction_along_an_interval_are_named_errors() {
    let p = Obstacle::plane([0.0; 3], [1.0, 0.0, 0.0]).unwrap();
    for mu in [-0.1, f64::NAN, f64::INFINITY] {
        let e = p.clone().with_friction(mu).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { ref name, .. } if name == "friction"));
    }
    assert_eq!(p.with_friction(0.3).unwrap().friction(), 0.3);
    // A uniform load on a floor at the gap δ lays the rod along it (an interval).
    let (ei, _) = constants();
    let q = 72.0 * ei * DELTA / (0.5 * L).powi(4);
    let loads = Loads {
        distributed_force: Some(softrod::Profile::Constant(Vector3::new(-q, 0.0, 0.0))),
        ..Loads::default()
    };
    let model = RobotModel::rod_only(rod(RADIUS), loads).unwrap();
    let e = solve_constrained(
        &model,
        &Actuation::default(),
        &options(100),
        None,
        &[plane(0.3)],
    )
    .unwrap_err();
    println!("{e}");
    assert!(e.to_string().contains("friction"), "{e}");
}

/// Compliance under a sticking tip contact: the tip is held along the normal and along the
/// surface, so its translation per tip force is zero (≤ 1e-9 of the contact-free `L³/(3EI)`)
/// in every direction, while a frictionless contact lets it slide along the plane
/// (`C_yy = L³/(3EI)` to 1e-3).
#[test]
fn a_sticking_tip_contact_holds_the_tip_in_the_compliance() {
    let (ei, fc) = constants();
    let free = L.powi(3) / (3.0 * ei);
    let force = Vector3::new(-2.0 * fc, 0.5 * fc, 0.0);
    let stick = solve(force, &plane(0.5));
    assert_eq!(stick.contacts[0].state, ContactState::Stick);
    let c = stick.compliance.get().unwrap();
    let worst = c.fixed_view::<3, 3>(0, 0).amax();
    println!("sticking: largest translational compliance {worst:e} m/N (free {free:e})");
    assert!(worst <= 1e-9 * free, "{c}");
    let slide = solve(force, &plane(0.0)).compliance.get().unwrap();
    println!(
        "frictionless: C_yy = {:e} (L^3/3EI = {free:e})",
        slide[(1, 1)]
    );
    assert!((slide[(1, 1)] / free - 1.0).abs() < 1e-3);
}

/// Compliance under a contact inside the rod, against the propped cantilever of
/// [`interior_friction_sticks_and_slides_as_the_propped_cantilever`] (flexibilities `α, β, γ`,
/// axial `E A`; the same post, μ = 0.5, Fx = 2 F_c). Sticking holds the rod's point at `a` in
/// all three directions: the tip's translation per tip force is `γ - β²/α` across the rod and
/// `(L - a)/(E A)` along it. Sliding (|Fy| > μ Fx) holds the normal only: across the rod along
/// the normal `γ - β²/α`, sideways `γ`; the friction force `-μ R ŝ` follows the normal
/// reaction, `dR/df_x = -β/α`, so a tip force along the normal moves the tip sideways by
/// `sign(Fy) μ β²/α` (the compliance is not symmetric); and `ŝ`, the slip direction of the
/// point at `a` (slip `s` from its first touch), turns with an axial slip, a spring
/// `k = μ R / |s|` along the rod at `a`: `(L - a)/(E A) + 1/(E A / a + k)`. Frictionless:
/// `γ - β²/α`, `γ`, `L/(E A)`. Each entry of the translational block to 1e-5 of its closed
/// form, the others below 1e-5 γ (the same neglected effects as the reactions, ~1e-5
/// rotations).
#[test]
fn compliance_under_interior_friction_is_the_propped_cantilever() {
    let (alpha, beta, gamma) = post_flexibilities();
    let fc = POST_GAP / beta;
    let (_, _, ea, _) = common::circular_constants(E, NU, POST_ROD, 1.0);
    let propped = gamma - beta * beta / alpha;
    let mu = 0.5;
    for (friction, fy) in [(mu, 0.5), (mu, 2.0), (mu, -2.0), (0.0, 0.5)] {
        let (fx, fy) = (2.0 * fc, fy * fc);
        let sol = solve_rod(POST_ROD, Vector3::new(-fx, fy, 0.0), &post(friction));
        let state = sol.contacts[0].state;
        let c = sol.compliance.get().unwrap();
        let mut expected = [[0.0; 3]; 3];
        expected[0][0] = propped;
        match state {
            ContactState::Stick => {
                expected[1][1] = propped;
                expected[2][2] = (L - POST_AT) / ea;
            }
            ContactState::Slide => {
                let lambda0 = fc / fx;
                let r = (1.0 - lambda0) * fx * beta / alpha;
                let ft = -fy.signum() * mu * r;
                let slip = fy * beta + ft * alpha - lambda0 * fy * beta;
                let k = mu * r / slip.abs();
                expected[1][1] = gamma;
                expected[1][0] = fy.signum() * mu * beta * beta / alpha;
                expected[2][2] = (L - POST_AT) / ea + 1.0 / (ea / POST_AT + k);
            }
            ContactState::Frictionless => {
                expected[1][1] = gamma;
                expected[2][2] = L / ea;
            }
        }
        for (i, row) in expected.iter().enumerate() {
            for (k, &e) in row.iter().enumerate() {
                let err = if e == 0.0 {
                    c[(i, k)].abs() / gamma
                } else {
                    (c[(i, k)] / e - 1.0).abs()
                };
                println!(
                    "mu = {friction}, Fy = {fy:e}: {state:?}, C[{i}][{k}] = {:e} vs {e:e} \
                     (err {err:.1e})",
                    c[(i, k)]
                );
                assert!(
                    err < 1e-5,
                    "{state:?}: C[{i}][{k}] = {:e} vs {e:e}",
                    c[(i, k)]
                );
            }
        }
    }
}

/// The NiTi robot bending its tip onto a wall with friction (μ = 0.1, 0.3, 1): the contact is
/// made by the actuation, so its slip is measured from where the tip first touches the wall
/// with the tensions applied proportionally. Oracle: that touch found independently, by
/// bisection of the load factor on contact-free solves until the tip's surface reaches the
/// wall (1e-12 of the load factor); the tip slides (the tendons keep dragging it), its
/// tangential force on the cone and opposite to its slip from that point (to 1e-6). Before,
/// the sticking tip pulled on the wall one load step past the touch and was released and
/// added again until the stepping gave up (7,240 Newton iterations, 1.1 s), and the answer came
/// from a fallback that measured the slip from the contact-free tip's foot on the wall
/// (tangential force 86–87° off the slip from the touch).
#[test]
fn a_tip_dragged_along_a_wall_slides_from_its_first_touch() {
    let model = common::niti_model(Loads::default(), None, 0.0);
    let full = [4.0, 0.0, 0.0, 0.0, 2.0, 0.0];
    let scaled = |lambda: f64| Actuation::tensions(&full.map(|t| t * lambda));
    let (wall_x, radius) = (0.1, 0.0007);
    let tip_x = |lambda: f64| {
        softrod::solve_statics(&model, &scaled(lambda), &options(100))
            .unwrap()
            .tip_position()[0]
            + radius
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    while hi - lo > 1e-12 {
        let mid = 0.5 * (lo + hi);
        if tip_x(mid) < wall_x {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let touch = Vector3::from(
        softrod::solve_statics(&model, &scaled(lo), &options(100))
            .unwrap()
            .tip_position(),
    );
    for mu in [0.1, 0.3, 1.0] {
        let wall = Obstacle::plane([wall_x, 0.0, 0.0], [-1.0, 0.0, 0.0])
            .unwrap()
            .with_friction(mu)
            .unwrap();
        let sol = solve_constrained(
            &model,
            &scaled(1.0),
            &options(100),
            None,
            std::slice::from_ref(&wall),
        )
        .unwrap();
        assert_eq!(sol.contacts.len(), 1);
        let c = sol.contacts[0];
        assert_eq!(c.state, ContactState::Slide);
        let tip = Vector3::from(sol.solution.tip_position());
        let mut slip = tip - touch;
        slip.x = 0.0;
        let ft = Vector3::from(c.tangential_force);
        let off = (ft / ft.norm() + slip / slip.norm()).norm();
        println!(
            "mu = {mu}: touch at load factor {lo:.9}, slip {:.2} mm, friction {:e} N \
             (mu f_n {:e}), direction off by {off:e}; {} iterations, {} evaluations",
            1e3 * slip.norm(),
            ft.norm(),
            mu * c.normal_force,
            sol.solution.stats.iterations,
            sol.solution.stats.function_evaluations
        );
        assert!(off < 1e-6, "friction not opposite to the slip: {off:e}");
        assert!((ft.norm() / (mu * c.normal_force) - 1.0).abs() < 1e-9);
        assert_balanced_with(&sol, &wall, radius, Vector3::zeros(), c.normal_force);
    }
}
