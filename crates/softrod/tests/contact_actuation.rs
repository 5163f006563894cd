//! The actuation Jacobian of a contact equilibrium with the active contacts and the tip
//! constraint as constraints, against central finite differences of the nonlinear contact
//! solve: the two-segment NiTi robot pressing a sphere (a contact inside the rod) with its tip
//! resting on a plane (a tip contact), every tendon taut, the active set unchanged by the
//! perturbation; and the same robot with its tip pinned, sliding on a plane or clamped.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use softrod::nalgebra::{DMatrix, Matrix3, Vector3};
use softrod::{
    solve_constrained, Actuation, ContactSolution, Loads, Obstacle, Pose, SolveOptions,
    TipConstraint,
};

/// Tensions (N) that press the robot onto the sphere; the plane stops its tip.
const TENSIONS: [f64; 6] = [
    2.480_475_99,
    2.656_560_8,
    1.981_066_14,
    0.736_656_8,
    2.305_551,
    0.635_024_23,
];
/// Tension step of the differences (N).
const H: f64 = 1e-5;

fn options() -> SolveOptions {
    let mut o = common::rk4_options(50);
    o.newton.tolerance = 1e-14;
    o
}

fn obstacles() -> Vec<Obstacle> {
    vec![
        Obstacle::sphere([0.06, 0.0, 0.3], 0.04).unwrap(),
        Obstacle::plane([0.135, 0.0, 0.0], [-1.0, 0.0, 0.0]).unwrap(),
    ]
}

fn solve(t: &[f64], tip: Option<&TipConstraint>, obstacles: &[Obstacle]) -> ContactSolution {
    let tendons = common::niti_tendons(&std::array::from_fn(|i| t[i]));
    let (model, _) = common::split(&common::niti_rod(), &tendons, &[], &Loads::default()).unwrap();
    let sol =
        solve_constrained(&model, &Actuation::tensions(t), &options(), tip, obstacles).unwrap();
    assert!(sol.solution.stats.converged);
    sol
}

fn rotation(r: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| r[i][j])
}

/// Central differences of the twist `[δp; δθ]` (world) of node `node` per tension; checks that
/// the perturbed solutions keep the active set.
fn differences(tip: Option<&TipConstraint>, obstacles: &[Obstacle], node: usize) -> DMatrix<f64> {
    let base = solve(&TENSIONS, tip, obstacles);
    let sites =
        |s: &ContactSolution| -> Vec<usize> { s.contacts.iter().map(|c| c.obstacle).collect() };
    DMatrix::from_fn(6, 6, |r, i| {
        let (mut up, mut down) = (TENSIONS, TENSIONS);
        up[i] += H;
        down[i] -= H;
        let (sp, sm) = (solve(&up, tip, obstacles), solve(&down, tip, obstacles));
        assert_eq!(sites(&sp), sites(&base));
        assert_eq!(sites(&sm), sites(&base));
        if r < 3 {
            (sp.solution.position[node][r] - sm.solution.position[node][r]) / (2.0 * H)
        } else {
            let d = rotation(&sp.solution.rotation[node])
                * rotation(&sm.solution.rotation[node]).transpose();
            let w = 0.5
                * Vector3::new(
                    d[(2, 1)] - d[(1, 2)],
                    d[(0, 2)] - d[(2, 0)],
                    d[(1, 0)] - d[(0, 1)],
                );
            w[r - 3] / (2.0 * H)
        }
    })
}

fn relative(j: &DMatrix<f64>, fd: &DMatrix<f64>) -> f64 {
    (j - fd).amax() / fd.amax()
}

/// The nodes checked: the tip, one in the first segment and the end of the first segment
/// (nodes at fixed arc lengths: the mesh between the contact and its neighbours' breaks moves
/// with the contact's arc length).
fn nodes(sol: &ContactSolution) -> Vec<usize> {
    let n = sol.solution.s.len();
    let end1 = sol
        .solution
        .s
        .iter()
        .rposition(|&s| (s - 0.2).abs() < 1e-12)
        .unwrap();
    vec![n - 1, 10, end1]
}

#[test]
fn pressing_a_sphere_with_the_tip_on_a_plane_matches_central_differences() {
    let obstacles = obstacles();
    let sol = solve(&TENSIONS, None, &obstacles);
    let l = 0.4;
    let tip_contact = sol.contacts.iter().find(|c| c.obstacle == 1).unwrap();
    let interior = sol.contacts.iter().find(|c| c.obstacle == 0).unwrap();
    assert_eq!(tip_contact.s, l);
    assert!(interior.s > 0.25 && interior.s < 0.35, "{}", interior.s);
    assert!(tip_contact.normal_force > 1e-3 && interior.normal_force > 1e-3);
    for node in nodes(&sol) {
        let j = sol
            .compliance
            .actuation_jacobian(&sol.solution, Some(node))
            .unwrap();
        let fd = differences(None, &obstacles, node);
        let err = relative(&j, &fd);
        println!("node {node}: relative error {err:.2e}");
        assert!(err <= 1e-6, "node {node}: {err:e}\n{j}\n{fd}");
    }
    // The contact forces held as dead loads (the contact-free Jacobian of the same shape) is
    // a different answer: the oracle tells them apart.
    let dead = softrod::actuation_jacobian(&sol.solution, None).unwrap();
    let fd = differences(None, &obstacles, sol.solution.s.len() - 1);
    assert!(relative(&dead, &fd) > 0.1);
}

#[test]
fn a_held_tip_holds_its_directions_under_actuation() {
    let free = solve(&TENSIONS, None, &[]);
    let n = free.solution.s.len();
    let tip = Vector3::from(free.solution.position[n - 1]) - Vector3::new(0.01, 0.0, 0.0);
    let r = rotation(&free.solution.rotation[n - 1]);
    let pin = TipConstraint::pin(tip.into()).unwrap();
    let slide = TipConstraint::slide(tip.into(), [1.0, 0.0, 0.0]).unwrap();
    let clamp = TipConstraint::clamp(Pose::new(tip, r).unwrap());
    for (name, c) in [("pin", pin), ("slide", slide), ("clamp", clamp)] {
        let sol = solve(&TENSIONS, Some(&c), &[]);
        for node in [n - 1, 10] {
            let j = sol
                .compliance
                .actuation_jacobian(&sol.solution, Some(node))
                .unwrap();
            let fd = differences(Some(&c), &[], node);
            if node == n - 1 && name == "clamp" {
                // Every tip direction held: no motion (the differences are round-off).
                assert!(j.amax() <= 1e-9 && fd.amax() <= 1e-8, "{name}: {j}");
                continue;
            }
            let err = relative(&j, &fd);
            println!("{name} node {node}: relative error {err:.2e}");
            assert!(err <= 1e-6, "{name} node {node}: {err:e}");
            if node == n - 1 {
                // The held translations do not move.
                let held = match name {
                    "slide" => vec![0],
                    _ => vec![0, 1, 2],
                };
                for k in held {
                    assert!(j.row(k).amax() <= 1e-10 * j.amax(), "{name}: row {k}");
                }
            }
        }
    }
}

#[test]
fn friction_at_a_contact_and_a_foreign_solution_are_refused_by_name() {
    let rough = [Obstacle::plane([0.135, 0.0, 0.0], [-1.0, 0.0, 0.0])
        .unwrap()
        .with_friction(0.3)
        .unwrap()];
    let sol = solve(&TENSIONS, None, &rough);
    assert!(!sol.contacts.is_empty());
    let err = sol
        .compliance
        .actuation_jacobian(&sol.solution, None)
        .unwrap_err();
    assert!(err.to_string().contains("solution"), "{err}");
    let other = solve(&TENSIONS, None, &obstacles());
    let err = other
        .compliance
        .actuation_jacobian(&solve(&[1.0; 6], None, &[]).solution, None)
        .unwrap_err();
    assert!(err.to_string().contains("solution"), "{err}");
    let n = other.solution.s.len();
    let err = other
        .compliance
        .actuation_jacobian(&other.solution, Some(n))
        .unwrap_err();
    assert!(err.to_string().contains("node"), "{err}");
}
