//! Obstacles thinner than the integration mesh: a wire (a capsule of radius 0.2 mm) across a
//! cantilever midway between two nodes of its RK4 mesh (5 mm apart, rod radius 1 mm). No
//! node comes near the wire, so a check of the nodes alone lets the rod pass through it; the
//! gap is also checked along the arc between the nodes, and the wire props the cantilever
//! with the closed-form reaction `R = (F c² (3L - c) / (6 E I) - δ) 3 E I / c³`.
//!
//! A rod that slides off the end of a thin obstacle it was pressed on: the two-segment NiTi
//! robot bent across a capsule (radius 8 mm, axis along `y` from -50 to 50 mm). Along the
//! load path (checked at 60 % and 62 % of the tensions) the rod presses on the capsule's near
//! side and its contact slides along the axis toward the end; past the end (62.7 %) there
//! is no equilibrium on that side and the rod snaps free. Oracle: the contact-free solve (no
//! obstacle) at the full tensions, whose shape is clear of the capsule on its far side.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use softrod::nalgebra::Vector3;
use softrod::{solve_constrained, Actuation, Loads, Obstacle, RobotModel, SolveOptions};

use common::{beam as rod, rk4_options as options, BEAM_E as E, BEAM_LENGTH as L, BEAM_NU as NU};

/// RK4 steps over the cantilever (nodes every `L / STEPS`).
const STEPS: usize = 200;

/// The least gap (m) between the rod's surface and `o` along the polyline of the nodes,
/// sampled 64 times per cell (no node lies near the wire: this is what a node check misses).
fn least_gap_on_chords(positions: &[[f64; 3]], o: &Obstacle, radius: f64) -> f64 {
    let mut least = f64::INFINITY;
    for w in positions.windows(2) {
        let (a, b) = (Vector3::from(w[0]), Vector3::from(w[1]));
        for k in 0..=64 {
            let x = a + (b - a) * (f64::from(k) / 64.0);
            least = least.min(o.distance(&x).0 - radius);
        }
    }
    least
}

#[test]
fn a_wire_between_two_nodes_props_the_cantilever() {
    let radius = 1e-3;
    let delta = 1e-3 * L;
    let wire = 2e-4;
    let (ei, _, _, _) = common::circular_constants(E, NU, radius, 1.0);
    // Midway between the nodes at 0.6 L and 0.6 L + L / STEPS.
    let c = 0.6 * L + 0.5 * L / STEPS as f64;
    let x = -(radius + delta + wire);
    let obstacles = [Obstacle::capsule([x, -0.05, c], [x, 0.05, c], wire).unwrap()];
    let closing = delta * 6.0 * ei / (c * c * (3.0 * L - c));
    // At 10 F_c the contact-free cantilever lies wholly beyond the wire (deflection 10 δ at
    // c against δ + 2 R + 2 r_wire = 3.4 δ): the rod must meet it on its way.
    for factor in [0.8, 1.5, 2.0, 10.0] {
        let force = Vector3::new(-factor * closing, 0.0, 0.0);
        let model = RobotModel::rod_only(rod(radius), Loads::tip_force(force)).unwrap();
        let sol = solve_constrained(
            &model,
            &Actuation::default(),
            &options(STEPS),
            None,
            &obstacles,
        )
        .unwrap();
        assert!(sol.solution.stats.converged);
        let least = least_gap_on_chords(&sol.solution.position, &obstacles[0], radius);
        println!("wire, F = {factor} F_c: least gap along the chords {least:e} m");
        if factor < 1.0 {
            assert!(sol.contacts.is_empty());
            assert!(least > 0.0);
            continue;
        }
        // The chords cut the arc by its sagitta (below 1e-10 m here), nothing more.
        assert!(
            least >= -1e-9,
            "the rod passes through the wire: gap {least:e} m"
        );
        assert_eq!(sol.contacts.len(), 1, "{:?}", sol.contacts);
        let k = sol.contacts[0];
        assert!(
            (k.s - c).abs() < 0.1 * L / STEPS as f64,
            "contact at {}",
            k.s
        );
        let f = factor * closing;
        let exact = (f * c * c * (3.0 * L - c) / (6.0 * ei) - delta) * 3.0 * ei / c.powi(3);
        let err = (k.normal_force / exact - 1.0).abs();
        println!(
            "wire contact at s = {:.6}: R = {:e}, propped cantilever {exact:e}, rel. error {err:e}",
            k.s, k.normal_force
        );
        assert!(err < 1e-3, "R = {:e} vs {exact:e}", k.normal_force);
        // Global balance: base force = tip force + contact force.
        let b = sol.solution.base_wrench;
        let fc = Vector3::from(k.normal) * k.normal_force;
        for i in 0..3 {
            let want = force[i] + fc[i];
            assert!(
                (b[i] - want).abs() <= 1e-10 * closing,
                "force {i}: {} vs {want}",
                b[i]
            );
        }
    }
}

#[test]
fn the_niti_robot_slides_off_the_end_of_a_capsule_and_snaps_free() {
    let t = [
        0.264_747_984_257_505_2,
        2.180_351_781_701_029,
        0.504_262_202_902_081_9,
        0.353_654_675_678_841_46,
        2.609_703_895_885_274_5,
        0.959_686_396_973_821,
    ];
    let (a, b) = ([0.04, -0.05, 0.25], [0.04, 0.05, 0.25]);
    let capsule = Obstacle::capsule(a, b, 0.008).unwrap();
    let rod = common::niti_rod();
    let radius = 0.7e-3;
    let solve = |scale: f64, obstacles: &[Obstacle]| {
        let (model, act) = common::split(
            &rod,
            &common::niti_tendons(&t.map(|v| scale * v)),
            &[],
            &Loads::default(),
        )
        .unwrap();
        solve_constrained(&model, &act, &SolveOptions::default(), None, obstacles).unwrap()
    };
    // The load path: pressed on the near side (normal along -x), sliding toward y = -50 mm.
    let mut y = 0.0;
    for scale in [0.60, 0.62] {
        let sol = solve(scale, std::slice::from_ref(&capsule));
        assert_eq!(sol.contacts.len(), 1, "{scale}: {:?}", sol.contacts);
        let k = sol.contacts[0];
        println!("{scale} T: contact at {:?}, normal {:?}", k.point, k.normal);
        assert!(k.normal[0] < -0.9 && k.normal_force > 0.0);
        assert!(k.point[1] < y && k.point[1] > -0.05);
        y = k.point[1];
    }
    let sol = solve(1.0, std::slice::from_ref(&capsule));
    let free = solve(1.0, &[]);
    assert!(sol.solution.stats.converged && sol.solution.stable);
    assert!(sol.contacts.is_empty(), "{:?}", sol.contacts);
    let (tip, want) = (
        Vector3::from(sol.solution.tip_position()),
        Vector3::from(free.solution.tip_position()),
    );
    println!("tip {tip:?}, contact-free {want:?}");
    assert!((tip - want).norm() < 1e-12);
    let least = least_gap_on_chords(&free.solution.position, &capsule, radius);
    println!("least gap of the contact-free shape {least:e} m");
    assert!(least > 1e-3);
    // Beyond the capsule: the backbone where it touched (s = 0.26 m) has passed its axis.
    let node = free.solution.s.iter().position(|&s| s >= 0.26).unwrap();
    assert!(free.solution.position[node][0] > a[0] + 0.008);
}

/// A long stepped solve counts each right-hand-side evaluation once. The NiTi robot at the
/// tensions of its robot file, [4, 0, 0, 0, 2, 0] N, with a sphere (radius 30 mm, friction
/// 0.3) between its straight and bent shapes: the actuation is stepped (about 1,600 Newton iterations), the
/// rod presses on the sphere on the way and slides off it, and lands on its contact-free
/// shape (oracle: the solve without the obstacle, tip to 1e-12 m, 12 mm clear of the sphere).
/// A Newton iteration marches at most `MAX_LINE_SEARCH_HALVINGS + 1` trial points and once
/// with the columns: so at most 16 marches of `4 × steps` evaluations per iteration (4.3
/// measured). The count grew with the square of the solve's length before (the contact rows'
/// evaluations, kept from march to march, were added again at every march with the
/// columns: 1.07e9 here).
#[test]
fn a_long_stepped_solve_counts_each_evaluation_once() {
    let steps = 100;
    let model = common::niti_model(Loads::default(), None, 0.0);
    let act = Actuation::tensions(&[4.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    let sphere = Obstacle::sphere([0.1, 0.1, 0.34], 0.03)
        .unwrap()
        .with_friction(0.3)
        .unwrap();
    let sol = solve_constrained(
        &model,
        &act,
        &options(steps),
        None,
        std::slice::from_ref(&sphere),
    )
    .unwrap();
    let stats = sol.solution.stats;
    println!(
        "iterations {}, load steps {}, evaluations {} ({:.1} marches per iteration)",
        stats.iterations,
        stats.load_steps,
        stats.function_evaluations,
        stats.function_evaluations as f64 / (4 * steps * stats.iterations.max(1)) as f64
    );
    assert!(stats.converged && stats.load_steps > 0 && stats.iterations > 100);
    let free = softrod::solve_statics(&model, &act, &options(steps)).unwrap();
    let (a, b) = (sol.solution.tip_position(), free.tip_position());
    let apart = (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max);
    assert!(
        sol.contacts.is_empty() && apart < 1e-12,
        "{:?}, {apart:e}",
        sol.contacts
    );
    let clear = least_gap_on_chords(&sol.solution.position, &sphere, 0.0007);
    assert!(clear > 0.01, "{clear:e}");
    let bound = 16 * 4 * steps * (stats.iterations + stats.load_steps + 1);
    assert!(
        stats.function_evaluations <= bound,
        "{} evaluations for {} iterations",
        stats.function_evaluations,
        stats.iterations
    );
}

/// The least gap (m) between the rod's surface and `o` along the cubic Hermite arcs through
/// consecutive nodes with tangents `Δs R e₃` (the backbone the check between the nodes
/// bounds), sampled 400 times per cell, and the cell's length there (m).
fn least_gap_on_arcs(
    s: &[f64],
    positions: &[[f64; 3]],
    rotations: &[[[f64; 3]; 3]],
    o: &Obstacle,
    radius: f64,
) -> (f64, f64) {
    let mut least = (f64::INFINITY, 0.0);
    for i in 1..s.len() {
        let h = s[i] - s[i - 1];
        if h <= 0.0 {
            continue;
        }
        let (p0, p1) = (Vector3::from(positions[i - 1]), Vector3::from(positions[i]));
        let axis = |r: &[[f64; 3]; 3]| Vector3::new(r[0][2], r[1][2], r[2][2]) * h;
        let (m0, m1) = (axis(&rotations[i - 1]), axis(&rotations[i]));
        for k in 0..=400 {
            let t = f64::from(k) / 400.0;
            let (t2, t3) = (t * t, t * t * t);
            let x = p0 * (2.0 * t3 - 3.0 * t2 + 1.0)
                + m0 * (t3 - 2.0 * t2 + t)
                + p1 * (3.0 * t2 - 2.0 * t3)
                + m1 * (t3 - t2);
            let g = o.distance(&x).0 - radius;
            if g < least.0 {
                least = (g, h);
            }
        }
    }
    least
}

/// A rod bent by its tendon onto a small sphere (radius 10 mm) that it meets with its tip and
/// then lies across: the last cell (2.8 mm) ran 84 µm (9 % of the rod's radius) into the
/// sphere between a tip contact and a node just clear of it, because the check between the
/// nodes skipped the cells next to a contact. Oracles: the documented bound on the arc
/// between the nodes (`-max(10 tol L, 10⁻³ Δs)`), and the balance of the rod (the base force
/// against the contact forces: the tendon's pull is internal).
#[test]
fn a_rod_bent_across_a_small_sphere_does_not_cut_into_it_next_to_its_contact() {
    let (l, radius, offset, tension) = (0.110, 9.2e-4, 2.3e-3, 5.879);
    let rod = common::circular_rod(l, radius, 2.36e9, 0.3);
    let tendon = softrod::Tendon::constant([offset, 0.0], None).unwrap();
    let model = RobotModel::new(rod, vec![tendon], Vec::new(), Loads::default()).unwrap();
    let sphere = Obstacle::sphere([0.055_473_6, 0.005_862_2, 0.086_230_1], 0.010).unwrap();
    let o = SolveOptions::default();
    let sol = solve_constrained(
        &model,
        &Actuation::tensions(&[tension]),
        &o,
        None,
        std::slice::from_ref(&sphere),
    )
    .unwrap();
    let x = &sol.solution;
    assert!(x.stats.converged);
    let (least, h) = least_gap_on_arcs(&x.s, &x.position, &x.rotation, &sphere, radius);
    let bound = (10.0 * o.newton.tolerance * l).max(1e-3 * h);
    println!(
        "least gap on the arcs {least:e} m (bound {bound:e} m), contacts {:?}",
        sol.contacts
            .iter()
            .map(|c| (c.s, c.normal_force))
            .collect::<Vec<_>>()
    );
    assert!(
        least >= -bound,
        "{least:e} m into the sphere (bound {bound:e} m)"
    );
    let mut total = Vector3::from(x.base_wrench[..3].try_into().unwrap_or([0.0; 3]));
    for f in &sol.contact_force {
        total -= Vector3::from(*f);
    }
    let scale = sol
        .contacts
        .iter()
        .map(|c| c.normal_force)
        .fold(0.0, f64::max);
    assert!(total.norm() <= 1e-9 * scale, "unbalanced by {total} N");
}

/// A soft arm (0.37 m, 5.7 mm, E 10.5 MPa) curled by two tendons and pressed onto a plane
/// with a force of 5.4 N: its shearable backbone kinks at the contact, and the surface
/// interpolated between the nodes dips below the plane next to it. On meshes finer than 1.2
/// mm (800 RK4 steps and more) the check between the nodes added one contact after another
/// in that cell, and the merge of a plane touched twice into an interval to the tip (the
/// arm's distal turns clear of the plane) cycled: the solve failed after 40 rounds, then
/// stepped the actuation from the unactuated rod for 6 to 9 s and failed again, while 720
/// steps converged in 5 ms. A cell is now checked once, and a plane touched twice becomes an
/// interval only where the rod lies on it to the tip. Oracles: the converged meshes' tips
/// (one contact on 320 steps, a patch of three to five on the finer ones: within 1e-6 m),
/// the bound on the arcs between the nodes away from the checked cells, and the balance of
/// the rod.
#[test]
fn a_soft_arm_pressed_onto_a_plane_is_solved_on_fine_meshes() {
    let (l, r0, r1) = (
        0.369_082_175_735_971_6,
        0.005_744_967_655_878_824,
        0.005_687_265_155_640_431,
    );
    let rod = softrod::Rod::new(
        l,
        softrod::Section::tapered_circular(r0, r1).unwrap(),
        softrod::LinearElastic::new(10_543_184.136_131_344, 0.365_992_691_077_091_6).unwrap(),
    )
    .unwrap();
    let tendons = [
        [0.000_852_925_098_293_697_8, 0.001_037_891_894_817_503_5],
        [-0.001_035_240_000_425_26, 0.000_551_268_967_112_326],
        [0.000_565_454_170_044_816, -0.004_225_781_057_125_604],
    ]
    .map(|o| softrod::Tendon::constant(o, None).unwrap());
    let model = RobotModel::new(rod, tendons.to_vec(), Vec::new(), Loads::default()).unwrap();
    let act = Actuation::tensions(&[108.754_920_214_864, 0.0, 92.427_068_903_114_8]);
    let plane = Obstacle::plane(
        [0.019_468_490_651_460_453, -0.037_279_679_141_238_094, 0.0],
        [-0.462_906_559_550_684, 0.886_407_083_187_487_2, 0.0],
    )
    .unwrap();
    let solve = |steps| {
        let o = options(steps);
        solve_constrained(&model, &act, &o, None, std::slice::from_ref(&plane)).unwrap()
    };
    let reference = solve(320);
    assert_eq!(reference.contacts.len(), 1);
    let tip = Vector3::from(reference.solution.tip_position());
    for steps in [800, 960, 1280] {
        let sol = solve(steps);
        let x = &sol.solution;
        assert!(x.stats.converged);
        let error = (Vector3::from(x.tip_position()) - tip).norm();
        let forces: Vec<(f64, f64)> = sol.contacts.iter().map(|c| (c.s, c.normal_force)).collect();
        println!("{steps} steps: tip {error:e} m from 320 steps, contacts {forces:?}");
        assert!(
            error <= 1e-6,
            "{steps} steps: tip {error:e} m from 320 steps"
        );
        // The patch of contacts: within 0.3 mm of the one found on 320 steps, all pushing.
        let s0 = reference.contacts[0].s;
        assert!(forces
            .iter()
            .all(|&(s, f)| (s - s0).abs() < 3e-4 && f > 0.0));
        let mut total = Vector3::from(x.base_wrench[..3].try_into().unwrap_or([0.0; 3]));
        for f in &sol.contact_force {
            total -= Vector3::from(*f);
        }
        assert!(
            total.norm() <= 1e-9 * 5.4,
            "{steps} steps: unbalanced by {total} N"
        );
        // Away from the patch the arcs between the nodes stay out of the plane (each cell with
        // the section's radius at its middle).
        for i in 1..x.s.len() {
            let (a, b) = (x.s[i - 1], x.s[i]);
            if (a - s0).abs() < 2e-3 || (b - s0).abs() < 2e-3 {
                continue;
            }
            let radius = r0 + (r1 - r0) * 0.5 * (a + b) / l;
            let cell = |v: &[[f64; 3]]| [v[i - 1], v[i]];
            let (least, h) = least_gap_on_arcs(
                &[a, b],
                &cell(&x.position),
                &[x.rotation[i - 1], x.rotation[i]],
                &plane,
                radius,
            );
            let bound = (10.0 * 1e-10 * l).max(1e-3 * h);
            assert!(
                least >= -bound,
                "{steps} steps: {least:e} m into the plane at {a} m"
            );
        }
    }
}
