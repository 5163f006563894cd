//! A contact is reached from the obstacle's near side: a soft rod bent by a tendon against a
//! cylinder whose contact-free shape passes through the cylinder close to its axis.
//!
//! Oracle (geometry, independent of the solver): the unactuated rod is straight along `z`, so
//! the material point of a contact at arc length `s` started at `(0, 0, s)`. A rod that reaches
//! the cylinder without crossing it touches it where that starting point lies on the outer side
//! of the tangent plane of the cylinder grown by the rod's radius: `(P_rest − p)·n > 0`, with
//! `p` the backbone point at the contact and `n` the outward normal. Before a contact past
//! the middle of its obstacle made the solve follow the load path, 0.5–0.8 N returned the rod
//! on the far side (normal ≈ (0.63, 0, −0.78), tip at x ≈ 214 mm), converged and stable: the
//! contact-free actuated rod runs past the cylinder's axis and relaxing the contact's gap
//! pushed it out through the far side. The load path (the tension stepped by 1 % from zero)
//! stays on the near side. Cold solves and a sweep warm-started from the previous tension are
//! checked.
//!
//! The two-segment NiTi robot against a sphere is the opposite case: its contact-free shape
//! also runs past the sphere's middle, but along the load path the rod snaps around the
//! sphere, and the answer is the snapped one. Oracle: the tip of the load path with fixed
//! steps of 1 % and of 0.3 % of the tensions (100 and 334 steps, the same to the printed
//! 1e-6 m), which a stepped solve with steps of 1/4 missed by 12–22 cm.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use std::sync::Arc;

use softrod::nalgebra::Vector3;
use softrod::{
    solve_constrained, Actuation, ContactSolution, Integrator, Loads, Obstacle, RobotModel,
    SolveOptions,
};

use common::SOFT_ARM_RADIUS as R;
use common::{soft_arm, soft_arm_cylinder};

fn setup() -> (Arc<RobotModel>, [Obstacle; 1], SolveOptions) {
    let options = SolveOptions {
        integrator: Integrator::Rk4 { steps: 80 },
        ..SolveOptions::default()
    };
    (soft_arm(), [soft_arm_cylinder()], options)
}

/// The solution at tension `t` (N), from a straight guess or warm-started.
fn solve(t: f64, warm: Option<&ContactSolution>) -> ContactSolution {
    let (model, obstacles, mut options) = setup();
    options.warm_start = warm.map(|w| w.solution.warm_start());
    solve_constrained(
        &model,
        &Actuation::tensions(&[t]),
        &options,
        None,
        &obstacles,
    )
    .unwrap()
}

#[test]

fn a_rod_bent_against_a_cylinder_touches_it_from_its_own_side() {
    for t in [0.3, 0.5, 0.6, 0.7, 0.8, 1.0, 2.0] {
        near_side(t, &solve(t, None));
    }
}

#[test]

fn a_warm_started_sweep_stays_on_the_near_side() {
    let mut last = solve(0.1, None);
    for k in 2..=12 {
        let t = 0.1 * f64::from(k);
        let sol = solve(t, Some(&last));
        near_side(t, &sol);
        last = sol;
    }
}

/// Checks the solution at tension `t` (N): converged, touching, every contact reached from
/// the near side, nothing penetrating.
fn near_side(t: f64, sol: &ContactSolution) {
    let (_, obstacles, _) = setup();
    assert!(sol.solution.stats.converged, "T = {t} N");
    assert!(!sol.contacts.is_empty(), "T = {t} N: no contact");
    for c in &sol.contacts {
        let n = Vector3::from(c.normal);
        // The backbone point at the contact: the surface point moved out by the radius.
        let p = Vector3::from(c.point) + R * n;
        let rest = Vector3::new(0.0, 0.0, c.s);
        let side = (rest - p).dot(&n);
        assert!(
            side > 0.0,
            "T = {t} N: contact at s = {} reached from behind the cylinder \
             (normal {n:?}, (P_rest - p).n = {side:e} m)",
            c.s
        );
    }
    // No penetration anywhere (nodes).
    for q in &sol.solution.position {
        let gap = obstacles[0].distance(&Vector3::from(*q)).0 - R;
        assert!(gap >= -1e-9, "T = {t} N: penetration {gap:e} m");
    }
}

/// The NiTi robot under `t` (N) against `sphere` from a straight guess: its tip (m) and the
/// load steps taken.
fn niti_tip(t: [f64; 6], sphere: Obstacle) -> (Vector3<f64>, usize) {
    let rod = common::niti_rod();
    let (model, act) =
        common::split(&rod, &common::niti_tendons(&t), &[], &Loads::default()).unwrap();
    let sol = solve_constrained(&model, &act, &SolveOptions::default(), None, &[sphere]).unwrap();
    assert!(sol.solution.stats.converged);
    let contacts = &sol.contacts;
    assert!(!contacts.is_empty(), "no contact");
    (
        Vector3::from(sol.solution.tip_position()),
        sol.solution.stats.load_steps,
    )
}

#[test]
fn the_niti_robot_snaps_around_a_sphere_as_on_its_load_path() {
    for (t, sphere, path) in [
        (
            [
                2.643_999, 2.190_388, 2.163_049, 2.986_370, 0.146_052, 0.206_723,
            ],
            Obstacle::sphere([0.0, 0.07, 0.25], 0.06).unwrap(),
            Vector3::new(-0.003_800, 0.253_545, 0.270_434),
        ),
        (
            [
                2.1043912186045906,
                2.638165513963029,
                0.8356882954227295,
                2.097262909859873,
                2.835060898027651,
                1.8844156087340984,
            ],
            Obstacle::sphere([0.06, 0.0, 0.3], 0.04).unwrap(),
            Vector3::new(0.151_059, 0.000_828, 0.362_682),
        ),
    ] {
        let (tip, steps) = niti_tip(t, sphere);
        let error = (tip - path).norm();
        assert!(steps > 0, "the actuation was not stepped");
        assert!(
            error < 2e-6,
            "tip {tip:?}: {error:e} m from the load path's"
        );
    }
}

/// A straight rod pulled along its axis by a tip force toward a sphere 1 mm ahead of its tip
/// (rod radius 1 mm, so a gap of 1 mm at rest): the tip must stop on the near side with the
/// closed-form reaction `R = F - E A δ / L` (axial stretch `1 + n/(E A)` of the linear law).
/// From 94 N the contact-free tip lands past the sphere's centre (15.9 mm at 100 N, centre 12
/// mm ahead), where the nearest surface is the far one; before loads alone (no actuation)
/// were checked for that, 100 N returned the rod through the sphere with a contact on its far
/// side (tip 23 mm ahead, base force 144.5 N), converged. 150 N lands beyond the sphere.
#[test]
fn a_rod_pulled_into_a_sphere_stops_on_its_near_side() {
    let (l, radius, e) = (1.0, 1e-3, 2e9);
    let rod = common::circular_rod(l, radius, e, 0.3);
    let ea = e * std::f64::consts::PI * radius * radius;
    let delta = 1e-3;
    let sphere = Obstacle::sphere([0.0, 0.0, l + 2.0 * radius + 0.01], 0.01).unwrap();
    for f in [30.0, 60.0, 94.0, 100.0, 120.0, 150.0] {
        let model = Arc::new(
            RobotModel::rod_only(rod.clone(), Loads::tip_force(Vector3::new(0.0, 0.0, f))).unwrap(),
        );
        let sol = solve_constrained(
            &model,
            &Actuation::default(),
            &SolveOptions::default(),
            None,
            std::slice::from_ref(&sphere),
        )
        .unwrap();
        let tip = sol.solution.tip_position();
        assert!(
            (tip[2] - (l + delta)).abs() < 1e-9 && tip[0].abs() < 1e-9 && tip[1].abs() < 1e-9,
            "F = {f} N: tip {tip:?}, expected on the near side at z = {}",
            l + delta
        );
        assert_eq!(sol.contacts.len(), 1, "F = {f} N");
        let r = f - ea * delta / l;
        let c = &sol.contacts[0];
        assert!(
            (c.normal_force - r).abs() < 1e-8 * f,
            "F = {f} N: reaction {} against {r}",
            c.normal_force
        );
        assert!(c.normal[2] < -0.999_999, "F = {f} N: normal {:?}", c.normal);
    }
}
