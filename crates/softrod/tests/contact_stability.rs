//! Stability of contact equilibria with the active contacts as constraints: a straight rod
//! pressing its tip on top of a sphere slides off once the push exceeds the tip's lateral
//! stiffness times the distance to the sphere's centre, `P > k ρ` (closed form), and a
//! tendon-bent rod resting on a cylinder is held by it, with the margin computed
//! independently from the dead-load rod's tangent compliance at the contact (a dead-load
//! reading of the contact force calls both the wrong way).
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use std::sync::Arc;

use softrod::nalgebra::{SymmetricEigen, Vector3};
use softrod::{
    solve_constrained, Actuation, ContactSolution, LinearElastic, Loads, Obstacle, RobotModel, Rod,
    Routing, Section, Tendon,
};

use common::{beam as rod, rk4_options as options, BEAM_E as E, BEAM_LENGTH as L, BEAM_NU as NU};

/// Radius (m) of the slender rod: `L / r = 500`, so that shear and axial strain move the
/// critical loads by about 1e-5.
const R: f64 = 2e-3;

fn ei() -> f64 {
    E * std::f64::consts::PI * R.powi(4) / 4.0
}

fn solve(loads: Loads, obstacles: &[Obstacle]) -> ContactSolution {
    let model = Arc::new(RobotModel::rod_only(rod(R), loads).unwrap());
    solve_constrained(&model, &Actuation::default(), &options(80), None, obstacles).unwrap()
}

/// The tendon-bent soft rod of `examples/contact_cylinder.py` resting on a cylinder at one
/// point: with the contact force read as a dead load it was reported unstable from 2.5 N (the
/// force is what bends the lower rod back), with the contact held it is stable; the margin is
/// the tip criterion
/// of the compliance under contact (itself checked against central differences of the
/// constrained solve in `contact.rs`).
#[test]
fn a_rod_resting_on_a_cylinder_is_held_by_it() {
    let (l, r, e) = (0.3, 0.005, 1e6);
    let rc = 0.03;
    let xc = rc + r + 0.002;
    let rod = Rod::new(
        l,
        Section::circular(r).unwrap(),
        LinearElastic::new(e, 0.45).unwrap(),
    );
    let tendon = Tendon::new(Routing::Constant([0.004, 0.0]), None).unwrap();
    let model = RobotModel::new(rod.unwrap(), vec![tendon], vec![], Loads::default()).unwrap();
    let cylinder = [Obstacle::cylinder([xc, -0.1, 0.14], [xc, 0.1, 0.14], rc).unwrap()];
    for tension in [2.0, 3.0] {
        let expect_stable = tension < 2.5;
        let sol = solve_constrained(
            &model,
            &Actuation::tensions(&[tension]),
            &options(80),
            None,
            &cylinder,
        )
        .unwrap();
        assert_eq!(sol.contacts.len(), 1);
        assert_eq!(sol.contacts[0].length, 0.0);
        let m = &sol.solution.model;
        let expected = common::tip_criterion(&sol.compliance.get().unwrap(), l, m.force_scale());
        let margin = sol.solution.stability_margin();
        println!("{tension} N: margin {margin:e}, tip criterion of the compliance {expected:e}");
        assert_eq!(sol.solution.stable, margin > 0.0);
        if expect_stable {
            assert!(sol.solution.stable, "{tension} N");
        }
        assert!(
            (margin - expected).abs() < 1e-6 * expected.abs(),
            "{margin:e} vs {expected:e}"
        );
    }
}

/// The straight rod pressing its tip on top of a sphere of radius `RS` (centre on the axis)
/// with a push of `ratio` times `k ρ`: `k` the tip's lateral stiffness (bending and shear,
/// Timoshenko), `ρ = RS + R` the distance of the centreline's tip from the centre.
const RS: f64 = 0.05;

fn lateral_stiffness() -> f64 {
    let g = E / (2.0 * (1.0 + NU));
    let area = std::f64::consts::PI * R * R;
    let shear = 6.0 * (1.0 + NU) / (7.0 + 6.0 * NU) * g * area;
    1.0 / (L.powi(3) / (3.0 * ei()) + L / shear)
}

fn on_sphere(ratio: f64) -> ContactSolution {
    let p = ratio * lateral_stiffness() * (RS + R);
    let sphere = [Obstacle::sphere([0.0, 0.0, L + R + RS], RS).unwrap()];
    let sol = solve(Loads::tip_force(Vector3::new(0.0, 0.0, p)), &sphere);
    assert_eq!(sol.contacts.len(), 1, "{:?}", sol.contacts);
    assert!((sol.contacts[0].normal_force - p).abs() < 1e-6 * p);
    sol
}

#[test]
fn a_rod_pushing_on_top_of_a_sphere_slides_off_past_its_lateral_stiffness() {
    for ratio in [0.5, 0.99] {
        let sol = on_sphere(ratio);
        assert!(
            sol.solution.stable,
            "{ratio}: {}",
            sol.solution.stability_margin()
        );
    }
    for ratio in [1.01, 2.0] {
        let sol = on_sphere(ratio);
        assert!(
            !sol.solution.stable,
            "{ratio}: {}",
            sol.solution.stability_margin()
        );
    }
    for ratio in [0.9, 1.1] {
        let margin = on_sphere(ratio).solution.stability_margin();
        let expected = pushed_tip_margin(ratio);
        println!("{ratio}: margin {margin:e}, closed form {expected:e}");
        assert!(
            (margin - expected).abs() < 1e-6 * expected.abs(),
            "{margin:e} vs {expected:e}"
        );
    }
}

/// The margin in closed form of the straight rod pushing its tip on a convex point with
/// `P / ρ = ratio k`: the tip's bending stiffness (Timoshenko) with `ratio k` taken off its
/// lateral term, in units of `E I / L` (`D = diag(L, 1)`), or the torsion's
/// `G J / E I = 1 / (1 + ν)` if softer.
fn pushed_tip_margin(ratio: f64) -> f64 {
    let g = E / (2.0 * (1.0 + NU));
    let shear = 6.0 * (1.0 + NU) / (7.0 + 6.0 * NU) * g * std::f64::consts::PI * R * R;
    let c = softrod::nalgebra::Matrix2::new(
        L.powi(3) / (3.0 * ei()) + L / shear,
        L * L / (2.0 * ei()),
        L * L / (2.0 * ei()),
        L / ei(),
    );
    let mut k = c.try_inverse().unwrap();
    k[(0, 0)] -= ratio * lateral_stiffness();
    let hat = softrod::nalgebra::Matrix2::new(
        k[(0, 0)] * L.powi(3) / ei(),
        k[(0, 1)] * L * L / ei(),
        k[(1, 0)] * L * L / ei(),
        k[(1, 1)] * L / ei(),
    );
    let bending = SymmetricEigen::new(hat).eigenvalues.min();
    bending.min(1.0 / (1.0 + NU))
}

/// The NiTi robot driven into a sphere by the tensions of the contact benchmark and some
/// others: the margin reported (from the coarse mesh when its sign is clear there) against
/// the tip criterion of the compliance under contact on the mesh asked; the same sign, and
/// the coarse mesh's value within 1e-3 of it (the difference of the meshes).
#[test]
fn the_niti_robot_against_a_sphere_reads_its_margin_on_the_coarse_mesh() {
    let model = common::niti_model(Loads::default(), None, 0.0);
    let sphere = [Obstacle::sphere([0.0, 0.07, 0.25], 0.06).unwrap()];
    let opts = softrod::SolveOptions::default();
    let mut worst: f64 = 0.0;
    for t in [
        [3.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        [4.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0, 2.0, 0.0, 0.0],
        [5.0, 0.0, 1.0, 1.0, 0.0, 0.0],
    ] {
        let sol =
            solve_constrained(&model, &Actuation::tensions(&t), &opts, None, &sphere).unwrap();
        if sol.contacts.is_empty() {
            continue;
        }
        let l = model.length();
        let expected =
            common::tip_criterion(&sol.compliance.get().unwrap(), l, model.force_scale());
        let margin = sol.solution.stability_margin();
        let rel = (margin - expected).abs() / expected.abs();
        println!("{t:?}: margin {margin:e}, mesh asked {expected:e}, rel. {rel:e}");
        assert_eq!(sol.solution.stable, expected > 0.0);
        worst = worst.max(rel);
    }
    assert!(worst < 1e-3, "{worst:e}");
}

/// A triangle mesh is held like the other obstacles: a square pyramid of half-width `W` and
/// height `W`, apex down at `(0, 0, L + R)` on the straight rod's axis, and a tetrahedron
/// whose bottom face lies at the same height. The tip pushing on the apex touches a vertex,
/// where the distance is that to a point: it slides off once `P > k ρ` with `ρ = R` (the
/// sphere's closed form with the sphere's radius zero, margin included); pushing on the
/// tetrahedron's bottom face with nine tenths of the rod's Euler load it is held as on a
/// plane, with the margin of a `Plane` obstacle (an independent formulation), where the same
/// push on the vertex slides off.
const W: f64 = 0.05;

fn pyramid() -> Obstacle {
    let z = L + R;
    let vertices = vec![
        [0.0, 0.0, z],
        [-W, -W, z + W],
        [W, -W, z + W],
        [W, W, z + W],
        [-W, W, z + W],
    ];
    // Counter-clockwise seen from outside.
    let faces = vec![
        [0, 2, 1],
        [0, 3, 2],
        [0, 4, 3],
        [0, 1, 4],
        [1, 2, 3],
        [1, 3, 4],
    ];
    Obstacle::mesh(vertices, faces).unwrap()
}

/// A tetrahedron whose bottom face (horizontal, at `z = L + R`) lies over the rod's tip, its
/// edges at least `W / 2` from the axis.
fn face_above() -> Obstacle {
    let z = L + R;
    let vertices = vec![[-W, -W, z], [W, -W, z], [0.0, W, z], [0.0, 0.0, z + W]];
    // Counter-clockwise seen from outside (the bottom face seen from below).
    let faces = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
    Obstacle::mesh(vertices, faces).unwrap()
}

#[test]
fn a_rod_pushing_on_a_mesh_vertex_slides_off_and_on_a_mesh_face_is_held() {
    let k = lateral_stiffness();
    for (ratio, stable) in [(0.5, true), (0.99, true), (1.01, false), (2.0, false)] {
        let p = ratio * k * R;
        let sol = solve(Loads::tip_force(Vector3::new(0.0, 0.0, p)), &[pyramid()]);
        assert_eq!(sol.contacts.len(), 1, "{:?}", sol.contacts);
        assert!((sol.contacts[0].normal_force - p).abs() < 1e-6 * p);
        let margin = sol.solution.stability_margin();
        let expected = pushed_tip_margin(ratio);
        println!("vertex, {ratio} k R: margin {margin:e}, closed form {expected:e}");
        assert_eq!(sol.solution.stable, stable, "{ratio}: {margin:e}");
        // (Near the flip the margin's relative error grows as the margin goes to zero.)
        if (ratio - 1.0f64).abs() > 0.1 {
            assert!(
                (margin - expected).abs() < 1e-6 * expected.abs(),
                "{margin:e} vs {expected:e}"
            );
        }
    }
    // Far past the vertex's k R: on the face as on the plane.
    let p = 0.9 * std::f64::consts::PI.powi(2) * ei() / (4.0 * L * L);
    let loads = || Loads::tip_force(Vector3::new(0.0, 0.0, p));
    let on_mesh = solve(loads(), &[face_above()]);
    let plane = Obstacle::plane([0.0, 0.0, L + R], [0.0, 0.0, -1.0]).unwrap();
    let on_plane = solve(loads(), &[plane]);
    let (a, b) = (
        on_mesh.solution.stability_margin(),
        on_plane.solution.stability_margin(),
    );
    println!("face: margin {a:e}, plane {b:e}");
    assert!(on_mesh.solution.stable && on_plane.solution.stable);
    assert!((a - b).abs() < 1e-9 * b.abs(), "{a:e} vs {b:e}");
    // (The same push on the vertex, P / (k R) about 370, slides off.)
    assert!(!solve(loads(), &[pyramid()]).solution.stable);
}

/// The rod pressed end-on against a wall (a plane across its axis at the tip): a rest
/// stretch `1 + ε` the wall does not let it take compresses it by `P = E A ε`. On a
/// frictionless wall the tip slides sideways under the wall's fixed-direction force: the
/// clamped-free column, unstable past `π² E I / (4 L²)`. On a rough wall (μ = 0.5) the contact
/// sticks (no sideways force) and holds the tip's point: the clamped-pinned column, stable up
/// to `λ² E I / L²` with `tan λ = λ` (20.1907; read as a dead load the contact gave the
/// clamped-free verdict). Shear and axial strain move these loads by about 1e-4 (`L/r` =
/// 500): the verdicts at 0.999 and 1.001 of them, and the margin near the clamped-pinned
/// load against the closed-form rotational stiffness of the pinned end,
/// `λ (sin λ - λ cos λ) / (2 - 2 cos λ - λ sin λ)` (E I / L), to 1e-3 (the shift of the load
/// times the slope, -0.32 per unit of `P L² / E I`).
#[test]
fn a_column_against_a_rough_wall_is_pinned_and_against_a_smooth_one_slides() {
    let ea = E * std::f64::consts::PI * R * R;
    let column = |mu: f64, ratio: f64| {
        let p = ratio * ei() / (L * L);
        let stretched = Vector3::new(0.0, 0.0, 1.0 + p / ea);
        let rod = rod(R)
            .with_rest_strain(softrod::Profile::Constant(stretched))
            .unwrap();
        let wall = Obstacle::plane([0.0, 0.0, L + R], [0.0, 0.0, -1.0])
            .unwrap()
            .with_friction(mu)
            .unwrap();
        let model = Arc::new(RobotModel::rod_only(rod, Loads::default()).unwrap());
        let sol =
            solve_constrained(&model, &Actuation::default(), &options(80), None, &[wall]).unwrap();
        assert_eq!(sol.contacts.len(), 1, "{:?}", sol.contacts);
        assert!((sol.contacts[0].normal_force / p - 1.0).abs() < 1e-6);
        sol
    };
    let free = std::f64::consts::PI.powi(2) / 4.0;
    let lambda = 4.493_409_457_909_064_f64;
    let pinned = lambda * lambda;
    for (mu, critical) in [(0.0, free), (0.5, pinned)] {
        for (ratio, stable) in [(0.999, true), (1.001, false)] {
            let sol = column(mu, ratio * critical);
            let state = sol.contacts[0].state;
            println!(
                "mu = {mu}, P = {ratio} x {critical:.4} E I / L^2: {state:?}, stable {}, \
                 margin {:e}",
                sol.solution.stable,
                sol.solution.stability_margin()
            );
            assert_eq!(sol.solution.stable, stable, "mu = {mu}, {ratio}");
        }
    }
    // The sticking contact's margin: the pinned end's rotational stiffness.
    for ratio in [19.9, 20.5] {
        let sol = column(0.5, ratio);
        assert_eq!(sol.contacts[0].state, softrod::ContactState::Stick);
        let l: f64 = ratio.sqrt();
        let closed = l * (l.sin() - l * l.cos()) / (2.0 - 2.0 * l.cos() - l * l.sin());
        let margin = sol.solution.stability_margin();
        println!("P = {ratio} E I / L^2: margin {margin:e}, closed form {closed:e}");
        assert!((margin - closed).abs() < 1e-3, "{margin:e} vs {closed:e}");
    }
}

/// A heavy soft rod, one tendon pulled and a small tip force, solved by the adaptive
/// integrator with a sphere on its load path that it leaves without contact: the contact solve
/// lands on a bent-over equilibrium whose tip margin is large (about 1.87) but past which a
/// conjugate point lies along the rod. Its verdict must be the one `solve_statics` gives the
/// same equilibrium (warm-started there, without the sphere): unstable, counting the conjugate
/// points along the march, not the tip margin alone.
#[test]
fn a_contact_solve_without_contacts_counts_the_conjugate_points_too() {
    use softrod::{solve_statics, AdaptiveOptions, Integrator, SolveOptions, WarmStart};
    let rod = common::circular_rod(0.3, 2e-3, 1e6, 0.45)
        .with_density(1100.0)
        .unwrap();
    let tendons = vec![
        Tendon::constant([1e-3, 0.0], None).unwrap(),
        Tendon::constant([0.0, 1e-3], Some(0.15)).unwrap(),
    ];
    let loads = Loads {
        tip_force: Vector3::new(0.0, 1e-3, 0.0),
        gravity: Vector3::new(0.0, 0.0, -9.81),
        ..Default::default()
    };
    let model = RobotModel::new(rod, tendons, Vec::new(), loads).unwrap();
    let act = Actuation::tensions(&[0.05, 0.0]);
    let opts = SolveOptions {
        integrator: Integrator::Adaptive(AdaptiveOptions::default()),
        ..SolveOptions::default()
    };
    let sphere = Obstacle::sphere([0.1, 0.0, 0.25], 0.03).unwrap();
    let c = solve_constrained(&model, &act, &opts, None, std::slice::from_ref(&sphere)).unwrap();
    assert!(c.contacts.is_empty());
    let free = SolveOptions {
        warm_start: Some(WarmStart::wrench(c.solution.base_wrench)),
        seek_stable: false,
        ..opts
    };
    let f = solve_statics(&model, &act, &free).unwrap();
    let tip = (Vector3::from(f.tip_position()) - Vector3::from(c.solution.tip_position())).norm();
    println!(
        "tip {:?}, margin {} / {}, stable {} / {}",
        c.solution.tip_position(),
        c.solution.stability_margin(),
        f.stability_margin(),
        c.solution.stable,
        f.stable
    );
    assert!(tip < 1e-9, "the same equilibrium: tips {tip:e} m apart");
    assert!(c.solution.stability_margin() > 1.0);
    assert!(!f.stable);
    assert_eq!(c.solution.stable, f.stable);
}
