//! Triangle-mesh obstacles against the analytic ones: a flat two-triangle mesh is the plane
//! (to round-off), and an icosphere inscribed in a sphere gives a reaction between those of
//! the sphere and of the sphere shrunk by the tessellation error.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use softrod::nalgebra::Vector3;
use softrod::{solve_constrained, Actuation, ContactSolution, Loads, Obstacle, RobotModel};

use common::{beam as rod, rk4_options as options, BEAM_E as E, BEAM_LENGTH as L, BEAM_NU as NU};

const RADIUS: f64 = 1e-3;

fn solve(force: Vector3<f64>, obstacles: &[Obstacle]) -> ContactSolution {
    let model = RobotModel::rod_only(rod(RADIUS), Loads::tip_force(force)).unwrap();
    solve_constrained(
        &model,
        &Actuation::default(),
        &options(200),
        None,
        obstacles,
    )
    .unwrap()
}

/// No node inside the obstacle beyond 1e-9 m, and the base wrench equal to the tip force and
/// the contact forces (about the base) to 1e-10 of `scale`.
fn assert_admissible(sol: &ContactSolution, o: &Obstacle, force: Vector3<f64>, scale: f64) {
    for p in &sol.solution.position {
        let g = o.distance(&Vector3::from(*p)).0 - RADIUS;
        assert!(g >= -1e-9, "penetration {g:e} at {p:?}");
    }
    let tip = Vector3::from(sol.solution.tip_position());
    let (mut f, mut m) = (force, tip.cross(&force));
    for (j, cf) in sol.contact_force.iter().enumerate() {
        let cf = Vector3::from(*cf);
        f += cf;
        m += Vector3::from(sol.solution.position[j]).cross(&cf);
    }
    for c in &sol.contacts {
        assert!(c.normal_force >= 0.0);
    }
    let b = sol.solution.base_wrench;
    for k in 0..3 {
        assert!((b[k] - f[k]).abs() <= 1e-10 * scale, "force {k}");
        assert!((b[3 + k] - m[k]).abs() <= 1e-10 * scale * L, "moment {k}");
    }
}

/// The largest relative difference of two contact solutions: contacts (arc length, force)
/// and the shape.
fn difference(a: &ContactSolution, b: &ContactSolution) -> f64 {
    assert_eq!(a.contacts.len(), b.contacts.len());
    let mut worst: f64 = 0.0;
    for (p, q) in a.contacts.iter().zip(&b.contacts) {
        worst = worst.max((p.s - q.s).abs() / L);
        worst = worst.max((p.normal_force - q.normal_force).abs() / p.normal_force.abs());
    }
    assert_eq!(a.solution.position.len(), b.solution.position.len());
    for (p, q) in a.solution.position.iter().zip(&b.solution.position) {
        worst = worst.max((Vector3::from(*p) - Vector3::from(*q)).norm() / L);
    }
    worst
}

/// The cantilever pushed onto the plane x = -(R + δ) at its tip, and propped on a sphere
/// inside the span, with the plane as two triangles of a large square: the same solution to
/// 1e-10.
#[test]
fn a_flat_two_triangle_mesh_is_the_plane() {
    let delta = 1e-3 * L;
    let (ei, _, _, _) = common::circular_constants(E, NU, RADIUS, 1.0);
    let closing = 3.0 * ei * delta / L.powi(3);
    let x = -(RADIUS + delta);
    let plane = Obstacle::plane([x, 0.0, 0.0], [1.0, 0.0, 0.0]).unwrap();
    // Counter-clockwise seen from +x: the outward normal +x.
    let v = vec![[x, -L, -L], [x, L, -L], [x, L, 2.0 * L], [x, -L, 2.0 * L]];
    let mesh = Obstacle::mesh(v, vec![[0, 1, 2], [0, 2, 3]]).unwrap();
    for factor in [1.5, 4.0] {
        let force = Vector3::new(-factor * closing, 0.3 * closing, 0.0);
        let a = solve(force, std::slice::from_ref(&plane));
        let b = solve(force, std::slice::from_ref(&mesh));
        assert!(a.solution.stats.converged && b.solution.stats.converged);
        assert_eq!(b.contacts.len(), 1);
        assert_admissible(&b, &mesh, force, closing);
        let d = difference(&a, &b);
        println!("two-triangle mesh vs plane, F = {factor} F_c: rel. difference {d:e}");
        assert!(d < 1e-10, "{d:e}");
    }
}

/// An icosphere (`level` subdivisions of the icosahedron) with its vertices on the sphere
/// `(center, r)`, outward faces.
fn icosphere(center: Vector3<f64>, r: f64, level: usize) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<Vector3<f64>> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| Vector3::from(*p).normalize())
    .collect();
    let mut f: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut mid = std::collections::HashMap::new();
        let mut half = |a: usize, b: usize, v: &mut Vec<Vector3<f64>>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push(((v[a] + v[b]) / 2.0).normalize());
                v.len() - 1
            })
        };
        let mut next = Vec::with_capacity(4 * f.len());
        for [a, b, c] in f {
            let (ab, bc, ca) = (half(a, b, &mut v), half(b, c, &mut v), half(c, a, &mut v));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = next;
    }
    // Outward: the normal along the centroid.
    for t in &mut f {
        let (a, b, c) = (v[t[0]], v[t[1]], v[t[2]]);
        if (b - a).cross(&(c - a)).dot(&(a + b + c)) < 0.0 {
            t.swap(1, 2);
        }
    }
    let vertices = v.iter().map(|p| (center + p * r).into()).collect();
    (vertices, f)
}

/// The cantilever propped on a sphere at 0.6 L (1.5 and 3 times the closing force), the
/// sphere an inscribed icosphere of 320 faces: its reaction lies between that of the
/// sphere and that of the sphere shrunk by the tessellation error ε (the least distance of
/// the centre to a face is r - ε), and the contact sits within the arc length spanned by
/// those two.
#[test]
fn an_icosphere_is_the_sphere_within_the_tessellation_error() {
    let delta = 1e-3 * L;
    let (ei, _, _, _) = common::circular_constants(E, NU, RADIUS, 1.0);
    let (c, rs) = (0.6 * L, 0.05 * L);
    let center = Vector3::new(-(RADIUS + delta + rs), 0.0, c);
    let (v, f) = icosphere(center, rs, 2);
    assert_eq!(f.len(), 320);
    let inner = f
        .iter()
        .map(|t| {
            let (a, b, cc) = (
                Vector3::from(v[t[0]]),
                Vector3::from(v[t[1]]),
                Vector3::from(v[t[2]]),
            );
            let n = (b - a).cross(&(cc - a)).normalize();
            n.dot(&(a - center))
        })
        .fold(f64::INFINITY, f64::min);
    let eps = rs - inner;
    let mesh = Obstacle::mesh(v, f).unwrap();
    let outer = Obstacle::sphere(center.into(), rs).unwrap();
    let shrunk = Obstacle::sphere(center.into(), rs - eps).unwrap();
    let closing = delta * 6.0 * ei / (c * c * (3.0 * L - c));
    for factor in [1.5, 3.0] {
        let force = Vector3::new(-factor * closing, 0.0, 0.0);
        let m = solve(force, std::slice::from_ref(&mesh));
        let hi = solve(force, std::slice::from_ref(&outer));
        let lo = solve(force, std::slice::from_ref(&shrunk));
        assert!(m.solution.stats.converged);
        assert_admissible(&m, &mesh, force, closing);
        assert_eq!(m.contacts.len(), 1, "{:?}", m.contacts);
        let (r, r_hi, r_lo) = (
            m.contacts[0].normal_force,
            hi.contacts[0].normal_force,
            lo.contacts.first().map_or(0.0, |k| k.normal_force),
        );
        println!(
            "icosphere (eps = {eps:e} m), F = {factor} F_c: R = {r:e}, sphere {r_hi:e}, \
             shrunk sphere {r_lo:e}"
        );
        assert!(
            r_lo <= r * (1.0 + 1e-9) && r <= r_hi * (1.0 + 1e-9),
            "{r_lo:e} {r:e} {r_hi:e}"
        );
        assert!((m.contacts[0].s - c).abs() < 1e-2 * L);
    }
}

/// The hierarchy finds the closest triangle: the distance outside an icosphere equals the
/// least distance over its triangles one by one.
#[test]
fn the_mesh_distance_is_the_least_over_its_triangles() {
    let center = Vector3::new(0.1, -0.2, 0.3);
    let (v, f) = icosphere(center, 0.05, 2);
    let mesh = Obstacle::mesh(v.clone(), f.clone()).unwrap();
    let singles: Vec<Obstacle> = f
        .iter()
        .map(|t| Obstacle::mesh(v.clone(), vec![*t]).unwrap())
        .collect();
    let mut worst: f64 = 0.0;
    for i in 0..200 {
        let a = i as f64 * 2.399_963;
        let z = 1.0 - 2.0 * (i as f64 + 0.5) / 200.0;
        let dir = Vector3::new(
            (1.0 - z * z).sqrt() * a.cos(),
            (1.0 - z * z).sqrt() * a.sin(),
            z,
        );
        let x = center + dir * (0.05 + 0.001 * (1 + i % 7) as f64);
        let d = mesh.distance(&x).0;
        let brute = singles
            .iter()
            .map(|o| o.distance(&x).0.abs())
            .fold(f64::INFINITY, f64::min);
        worst = worst.max((d - brute).abs());
    }
    assert!(worst < 1e-15, "{worst:e}");
}

/// A soft rod bent by its tendon into the front face of a closed box (12 triangles, 0.4 m
/// deep): the actuated rod without the box would lie 0.1 m inside it, nearer its side faces
/// than its front face, so the contacts are found with the actuation stepped from the
/// unactuated rod. The same solution as with the plane of the front face, to 1e-9.
#[test]
fn a_closed_box_is_the_plane_of_the_face_the_rod_enters_by() {
    let (l, r, e) = (0.3, 2e-3, 1e6);
    let rod = common::circular_rod(l, r, e, 0.4);
    // The tension that bends the free rod by 2 rad (offset 1 mm).
    let tension = 2.0 / l * e * std::f64::consts::PI * r.powi(4) / 4.0 / 1e-3;
    let tendon = softrod::Tendon::constant([1e-3, 0.0], None).unwrap();
    let model = RobotModel::new(rod, vec![tendon], Vec::new(), Loads::default()).unwrap();
    let xw = 0.1055;
    let plane = Obstacle::plane([xw, 0.0, 0.0], [-1.0, 0.0, 0.0]).unwrap();
    let mut v = Vec::new();
    for x in [xw, xw + 0.4] {
        for y in [-0.1, 0.1] {
            for z in [-0.05, 0.35] {
                v.push([x, y, z]);
            }
        }
    }
    // Counter-clockwise seen from outside.
    let f = vec![
        [0, 1, 3],
        [0, 3, 2],
        [4, 6, 7],
        [4, 7, 5],
        [0, 4, 5],
        [0, 5, 1],
        [2, 3, 7],
        [2, 7, 6],
        [0, 2, 6],
        [0, 6, 4],
        [1, 5, 7],
        [1, 7, 3],
    ];
    let boxed = Obstacle::mesh(v, f).unwrap();
    let act = Actuation::tensions(&[tension]);
    let solve = |o: &Obstacle| {
        solve_constrained(&model, &act, &options(40), None, std::slice::from_ref(o)).unwrap()
    };
    let (a, b) = (solve(&plane), solve(&boxed));
    assert_eq!(a.contacts.len(), 1);
    let worst = difference(&a, &b);
    println!(
        "tip {:?}, contact at s = {} m, {} N; box vs plane {worst:.2e}",
        b.solution.tip_position(),
        b.contacts[0].s,
        b.contacts[0].normal_force
    );
    assert!(worst <= 1e-9, "box vs plane {worst:e}");
}
