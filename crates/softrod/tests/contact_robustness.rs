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
