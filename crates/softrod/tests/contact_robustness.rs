//! Robustness of contact: the two-segment NiTi robot driven into a sphere by random tendon
//! tensions, solved from a straight initial guess (no warm start); frictionless, and with
//! Coulomb friction on the sphere.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use softrod::nalgebra::Vector3;
use softrod::{solve_constrained, Loads, Obstacle, SolveOptions};

use common::Rng;

/// Fraction of the tension vectors whose contact-free shape penetrates the sphere that the
/// contact solve converges for (no penetration, no pulling contact, forces inside the
/// friction cone of the sphere), and how many penetrated.
fn run(samples: usize, seed: u64, sphere: Obstacle) -> (usize, usize, Vec<[f64; 6]>) {
    let rod = common::niti_rod();
    let obstacles = [sphere.clone()];
    let mut rng = Rng(seed);
    let (mut touching, mut solved) = (0, 0);
    let mut failed = Vec::new();
    let options = SolveOptions::default();
    for _ in 0..samples {
        let t: [f64; 6] = std::array::from_fn(|_| 3.0 * rng.uniform());
        let tendons = common::niti_tendons(&t);
        let (model, act) = common::split(&rod, &tendons, &[], &Loads::default()).unwrap();
        let free = softrod::solve_statics(&model, &act, &options).unwrap();
        let radius = 0.7e-3;
        let penetrates = free
            .position
            .iter()
            .any(|p| sphere.distance(&Vector3::from(*p)).0 < radius);
        if !penetrates {
            continue;
        }
        touching += 1;
        match solve_constrained(&model, &act, &options, None, &obstacles) {
            Ok(sol) if sol.solution.stats.converged => {
                let ok = sol
                    .solution
                    .position
                    .iter()
                    .all(|p| sphere.distance(&Vector3::from(*p)).0 - radius >= -1e-9)
                    && sol.contacts.iter().all(|c| {
                        let t = Vector3::from(c.tangential_force).norm();
                        c.normal_force >= 0.0
                            && t <= sphere.friction() * c.normal_force * (1.0 + 1e-9)
                    })
                    && !sol.contacts.is_empty();
                if ok {
                    solved += 1;
                } else {
                    failed.push(t);
                }
            }
            _ => failed.push(t),
        }
    }
    (touching, solved, failed)
}

#[test]
fn niti_robot_into_a_sphere_converges_from_a_straight_guess() {
    let sphere = Obstacle::sphere([0.06, 0.0, 0.3], 0.04).unwrap();
    let (touching, solved, failed) = run(200, 0x5eed, sphere);
    println!("{solved} of {touching} contact solves converged; failed: {failed:?}");
    assert!(touching >= 20, "only {touching} samples touch the sphere");
    assert!(
        solved as f64 >= 0.99 * touching as f64,
        "{solved} of {touching}"
    );
}

/// With friction on the sphere (μ = 0.3): the contact made by the tendons finds its first
/// touch with the actuation stepped (see `docs/contact.md`), and slides.
#[test]
fn niti_robot_into_a_rough_sphere_converges_from_a_straight_guess() {
    let sphere = Obstacle::sphere([0.06, 0.0, 0.3], 0.04)
        .unwrap()
        .with_friction(0.3)
        .unwrap();
    let (touching, solved, failed) = run(200, 0x5eed, sphere);
    println!("{solved} of {touching} contact solves with friction converged; failed: {failed:?}");
    assert!(touching >= 20, "only {touching} samples touch the sphere");
    assert!(
        solved as f64 >= 0.99 * touching as f64,
        "{solved} of {touching}"
    );
}

/// The sample size (run with `--ignored`), frictionless and with friction μ = 0.3.
#[test]
#[ignore = "1,000 random tension vectors: a long run"]
fn niti_robot_into_a_sphere_converges_for_1000_tension_vectors() {
    let rough = |s: Obstacle| s.with_friction(0.3).unwrap();
    for sphere in [
        Obstacle::sphere([0.06, 0.0, 0.3], 0.04).unwrap(),
        Obstacle::sphere([0.0, 0.07, 0.25], 0.06).unwrap(),
        rough(Obstacle::sphere([0.06, 0.0, 0.3], 0.04).unwrap()),
        rough(Obstacle::sphere([0.0, 0.07, 0.25], 0.06).unwrap()),
    ] {
        let (touching, solved, failed) = run(1000, 0x5eed, sphere.clone());
        println!("{sphere:?}: {solved} of {touching} contact solves converged; failed: {failed:?}");
        assert!(
            solved as f64 >= 0.99 * touching as f64,
            "{solved} of {touching}"
        );
    }
}

/// Thin obstacles across the arm's path (run with `--ignored`): a cylinder of radius 5 mm
/// and a capsule of radius 8 mm, 1,000 random tension vectors each (U[0, 3] N). Every solve
/// converges with no node inside the obstacle and pushing contacts, or raises a
/// `ConvergenceError` (never another error). Measured: 3 and 18 raise, where the rod's
/// contact slides off the obstacle's end at a fold and the contact-free shape passes
/// through the obstacle (where it lands is not determined; `docs/contact.md`); 9 and 41
/// raised before the stepped solve snapped off an obstacle's end.
#[test]
#[ignore = "2,000 random tension vectors: a long run"]
fn niti_robot_across_thin_obstacles_converges_or_names_the_fold() {
    let rod = common::niti_rod();
    let radius = 0.7e-3;
    let options = SolveOptions::default();
    for (seed, obstacle, most) in [
        (
            7,
            Obstacle::cylinder([0.03, -0.05, 0.2], [0.03, 0.05, 0.2], 0.005).unwrap(),
            3,
        ),
        (
            9,
            Obstacle::capsule([0.04, -0.05, 0.25], [0.04, 0.05, 0.25], 0.008).unwrap(),
            18,
        ),
    ] {
        let mut rng = Rng(seed);
        let mut raised = Vec::new();
        for _ in 0..1000 {
            let t: [f64; 6] = std::array::from_fn(|_| 3.0 * rng.uniform());
            let tendons = common::niti_tendons(&t);
            let (model, act) = common::split(&rod, &tendons, &[], &Loads::default()).unwrap();
            match solve_constrained(
                &model,
                &act,
                &options,
                None,
                std::slice::from_ref(&obstacle),
            ) {
                Ok(sol) => {
                    assert!(sol.solution.stats.converged, "{t:?}");
                    let inside = sol
                        .solution
                        .position
                        .iter()
                        .map(|p| obstacle.distance(&Vector3::from(*p)).0 - radius)
                        .fold(f64::INFINITY, f64::min);
                    assert!(inside >= -1e-9, "{t:?}: {inside:e}");
                    assert!(sol.contacts.iter().all(|c| c.normal_force >= 0.0), "{t:?}");
                }
                Err(softrod::Error::NotConverged { .. }) => raised.push(t),
                Err(e) => panic!("{t:?}: {e}"),
            }
        }
        println!("{obstacle:?}: {} of 1000 raise: {raised:?}", raised.len());
        assert!(raised.len() <= most, "{} raise", raised.len());
    }
}
