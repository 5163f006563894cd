//! Actuation sweeps (`softrod::sweep`): every sample equals a one-by-one solve under the
//! documented warm-start rule, bit for bit, whatever the parallel split; values between mesh
//! nodes against closed forms (Timoshenko cantilever, stress-free circular arc with
//! Castigliano's compliance) and their fourth-order convergence; pressures and tip loads swept
//! like tensions; failures recorded per sample; errors named.
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use std::f64::consts::PI;
use std::sync::Arc;

use common::{assert_blocks_close, castigliano_arc, timoshenko};
use softrod::nalgebra::{Matrix6, Vector3};
use softrod::{
    solve_statics, sweep, Actuation, ActuationTable, Error, Integrator, LinearElastic, Loads,
    Profile, RobotModel, Rod, SampleStatus, Section, SolveOptions, SweepJob, SweepRequest,
    SweepSample, Tendon,
};

const E: f64 = 2.0e9;
const NU: f64 = 0.3;
const RADIUS: f64 = 0.01;
const LENGTH: f64 = 0.5;

fn rk4(steps: usize) -> SolveOptions {
    SolveOptions {
        integrator: Integrator::Rk4 { steps },
        ..Default::default()
    }
}

/// A two-tendon NiTi rod with a lateral tip force: Newton iterates, so warm starts matter.
fn loaded_model() -> Arc<RobotModel> {
    let tendons = vec![
        Tendon::constant([0.01, 0.0], None).unwrap(),
        Tendon::constant([0.0, 0.01], Some(0.25)).unwrap(),
    ];
    let loads = Loads {
        tip_force: Vector3::new(0.0, 0.05, -0.1),
        ..Loads::default()
    };
    RobotModel::new(common::niti_rod(), tendons, Vec::new(), loads).unwrap()
}

/// Tensions along a path (rows of 2), N.
fn tension_rows(n: usize) -> Vec<f64> {
    (0..n)
        .flat_map(|i| {
            let t = i as f64 / n as f64;
            [2.0 * t, 1.0 + (5.0 * t).sin()]
        })
        .collect()
}

fn table<'a>(samples: usize, tensions: &'a [f64]) -> ActuationTable<'a> {
    ActuationTable {
        samples,
        tensions,
        pressures: &[],
        tip_force: None,
        tip_moment: None,
    }
}

fn job<'a>(
    model: &Arc<RobotModel>,
    options: SolveOptions,
    t: ActuationTable<'a>,
    s: &[f64],
) -> SweepJob<'a> {
    SweepJob {
        model: Arc::clone(model),
        options,
        actuations: t,
        arc_lengths: s.to_vec(),
        obstacles: Vec::new(),
        tip_constraint: None,
    }
}

fn all() -> SweepRequest {
    SweepRequest {
        tip_pose: true,
        tendon_lengths: true,
        backbone: true,
        compliance: true,
        stiffness: true,
        gamma_c: true,
        eigen_stiffness: true,
        translational_compliance: true,
        contacts: true,
    }
}

/// Bit-for-bit equality of two samples (NaN equal to NaN).
fn same(a: &SweepSample, b: &SweepSample) -> bool {
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let arcs = |s: &SweepSample| {
        s.arcs
            .iter()
            .flat_map(|a| {
                let mut v = a.position.to_vec();
                v.extend(a.quaternion);
                v.extend(a.compliance.iter());
                v.extend(a.stiffness.iter());
                v.extend(a.gamma_c);
                v.extend(a.eigen_stiffness);
                v.extend(a.translational_compliance);
                v
            })
            .collect::<Vec<f64>>()
    };
    a.status == b.status
        && a.stats.iterations == b.stats.iterations
        && a.stats.residual.to_bits() == b.stats.residual.to_bits()
        && bits(&a.tip_position) == bits(&b.tip_position)
        && bits(&a.tip_quaternion) == bits(&b.tip_quaternion)
        && bits(&a.tendon_lengths) == bits(&b.tendon_lengths)
        && bits(&arcs(a)) == bits(&arcs(b))
        && a.contact_count == b.contact_count
        && bits(&a.contact_force) == bits(&b.contact_force)
        && bits(&a.tip_reaction) == bits(&b.tip_reaction)
}

#[test]
fn samples_follow_the_warm_start_rule_bit_for_bit() {
    let model = loaded_model();
    let n = 45;
    let block = 8;
    let rows = tension_rows(n);
    let opts = rk4(60);
    let out = sweep(
        &[job(
            &model,
            opts,
            table(n, &rows),
            &[0.2, LENGTH * 0.37, 0.4],
        )],
        &SweepRequest {
            tip_pose: true,
            tendon_lengths: true,
            ..SweepRequest::default()
        },
        block,
        true,
    )
    .unwrap();
    assert_eq!(out[0].len(), n);
    // The rule written out: cold at every block start, else from the previous converged row.
    let mut prev: Option<softrod::StaticsSolution> = None;
    for (i, got) in out[0].iter().enumerate() {
        let warm = if i % block == 0 {
            None
        } else {
            prev.as_ref().map(|p| p.warm_start())
        };
        let o = SolveOptions {
            warm_start: warm,
            ..opts
        };
        let sol = solve_statics(&model, &Actuation::tensions(&rows[2 * i..2 * i + 2]), &o).unwrap();
        assert_eq!(got.status, SampleStatus::Converged);
        assert_eq!(got.tip_position, sol.tip_position(), "row {i}");
        assert_eq!(got.tip_quaternion, *sol.quaternion.last().unwrap());
        assert_eq!(got.tendon_lengths, sol.tendon_lengths);
        assert_eq!(got.stats, sol.stats);
        prev = Some(sol);
    }
    // Warm starts pay: fewer iterations than starting every row cold.
    let cold = sweep(
        &[job(&model, opts, table(n, &rows), &[])],
        &SweepRequest::default(),
        1,
        true,
    )
    .unwrap();
    let its = |v: &[SweepSample]| v.iter().map(|s| s.stats.iterations).sum::<usize>();
    assert!(
        its(&out[0]) < its(&cold[0]),
        "{} vs {}",
        its(&out[0]),
        its(&cold[0])
    );
}

#[test]
fn results_do_not_depend_on_threads_or_splits_at_block_boundaries() {
    let model = loaded_model();
    let (n, block) = (40, 8);
    let rows = tension_rows(n);
    let s = [0.0, 0.1234, 0.2, LENGTH * 0.8, 0.4];
    let whole = [job(&model, rk4(40), table(n, &rows), &s)];
    let par = sweep(&whole, &all(), block, true).unwrap();
    let seq = sweep(&whole, &all(), block, false).unwrap();
    // The same rows as two jobs, split at a block boundary.
    let cut = 3 * block;
    let split = [
        job(&model, rk4(40), table(cut, &rows[..2 * cut]), &s),
        job(&model, rk4(40), table(n - cut, &rows[2 * cut..]), &s),
    ];
    let parts = sweep(&split, &all(), block, true).unwrap();
    let joined: Vec<&SweepSample> = parts[0].iter().chain(&parts[1]).collect();
    for i in 0..n {
        assert!(
            same(&par[0][i], &seq[0][i]),
            "row {i}: parallel vs sequential"
        );
        assert!(same(&par[0][i], joined[i]), "row {i}: split");
    }
    // Outputs are filled for converged samples.
    assert!(par[0].iter().all(|s| s.status == SampleStatus::Converged));
    assert!(par[0][5].arcs[1].compliance.iter().all(|v| v.is_finite()));
    // At s = 0 the compliance is zero and the stiffness undefined (NaN, not a number).
    assert_eq!(par[0][5].arcs[0].compliance, Matrix6::zeros());
    assert!(par[0][5].arcs[0].stiffness[(0, 0)].is_nan());
}

fn straight_rod() -> Rod {
    Rod::new(
        LENGTH,
        Section::circular(RADIUS).unwrap(),
        LinearElastic::new(E, NU).unwrap(),
    )
    .unwrap()
}

fn section_constants(k: f64) -> (f64, f64, f64, f64) {
    common::circular_constants(E, NU, RADIUS, k)
}

#[test]
fn compliance_between_nodes_of_a_straight_rod_is_the_timoshenko_cantilever() {
    // Q(s) of a straight rod is a cubic in s: the Hermite interpolation is exact, even on a
    // mesh of four steps.
    let rod = straight_rod();
    let (ei, gj, ea, gas) = section_constants(rod.shear_coefficient());
    let model = RobotModel::rod_only(rod, Loads::default()).unwrap();
    let s = [0.037, 0.1, 0.2001, 0.31, LENGTH];
    let out = sweep(&[job(&model, rk4(4), table(1, &[]), &s)], &all(), 4, false).unwrap();
    for (arc, &l) in out[0][0].arcs.iter().zip(&s) {
        let lat = l.powi(3) / (3.0 * ei) + l / gas;
        let c = timoshenko(l, ei, gj, ea, Some(gas));
        assert_blocks_close(&arc.compliance, &c, 1e-11, &format!("C_world({l})"));
        assert!((arc.position[2] - l).abs() < 1e-15 && arc.position[0] == 0.0);
        // γ_c = (s/L)³ + shear part, laterally.
        let g = lat * 3.0 * ei / LENGTH.powi(3);
        assert!((arc.gamma_c[0] - g).abs() < 1e-11 * g.max(1e-3));
        assert!((arc.translational_compliance[0] - lat).abs() < 1e-11 * lat);
        let kc = arc.stiffness * arc.compliance;
        assert!((kc - Matrix6::identity()).amax() < 1e-8);
        // Eigenstiffnesses: three positive, three negative (Patterson & Lipkin).
        assert!(arc.eigen_stiffness[2] > 0.0 && arc.eigen_stiffness[3] < 0.0);
    }
}

/// Largest errors of the pose and the compliance between the nodes of a stress-free arc
/// (rest curvature about body y) against its closed form and Castigliano.
fn arc_errors(steps: usize) -> (f64, f64, f64) {
    let angle = PI;
    let kappa = angle / LENGTH;
    let rod = straight_rod()
        .with_rest_curvature(Profile::Constant(Vector3::new(0.0, kappa, 0.0)))
        .unwrap();
    let (ei, gj, ea, gas) = section_constants(rod.shear_coefficient());
    let model = RobotModel::rod_only(rod, Loads::default()).unwrap();
    // Points between the nodes of every mesh tested (at thirds of the coarsest steps).
    let s: Vec<f64> = (0..8).map(|k| LENGTH * (3 * k + 1) as f64 / 24.0).collect();
    let out = sweep(
        &[job(&model, rk4(steps), table(1, &[]), &s)],
        &all(),
        1,
        false,
    )
    .unwrap();
    let (mut ep, mut eq, mut ec) = (0.0f64, 0.0f64, 0.0f64);
    for (arc, &l) in out[0][0].arcs.iter().zip(&s) {
        let t = kappa * l;
        let p = [(1.0 - t.cos()) / kappa, 0.0, t.sin() / kappa];
        for k in 0..3 {
            ep = ep.max((arc.position[k] - p[k]).abs() / LENGTH);
        }
        // Rotation about y by t: q = [0, sin(t/2), 0, cos(t/2)].
        let q = [0.0, (t / 2.0).sin(), 0.0, (t / 2.0).cos()];
        for k in 0..4 {
            eq = eq.max((arc.quaternion[k] - q[k]).abs());
        }
        let exact = castigliano_arc(kappa, l, [gas, gas, ea, ei, ei, gj]);
        let scale = exact.amax();
        ec = ec.max((arc.compliance - exact).amax() / scale);
    }
    (ep, eq, ec)
}

#[test]
fn values_between_nodes_converge_at_fourth_order_on_a_circular_arc() {
    // Measured: 6.3e-7, 1.1e-6, 2.4e-6 with 32 steps (a half-circle, 1/32 of it per step).
    let (p1, q1, c1) = arc_errors(32);
    let (p2, q2, c2) = arc_errors(64);
    assert!(p1 < 1e-6 && q1 < 2e-6 && c1 < 4e-6, "{p1:e} {q1:e} {c1:e}");
    for (a, b, what) in [
        (p1, p2, "position"),
        (q1, q2, "quaternion"),
        (c1, c2, "compliance"),
    ] {
        // Halving h divides a fourth-order error by 16 (allow 11: a mix of terms).
        assert!(a / b > 11.0, "{what}: {a:e} -> {b:e} (ratio {})", a / b);
    }
}

#[test]
fn pressures_and_tip_loads_are_swept_like_tensions() {
    let rod = Rod::new(
        0.16,
        Section::circular(0.012).unwrap(),
        LinearElastic::new(1.3e5, 0.5).unwrap(),
    )
    .unwrap();
    let chambers: Vec<softrod::Chamber> = [65.0f64, 185.0, 305.0]
        .iter()
        .map(|a| {
            let a = a.to_radians();
            softrod::Chamber::new(
                softrod::ChamberArea::Constant(2e-5),
                [0.0072 * a.cos(), 0.0072 * a.sin()],
                0.0,
                None,
            )
            .unwrap()
        })
        .collect();
    let model = RobotModel::new(rod, Vec::new(), chambers, Loads::default()).unwrap();
    let n = 6;
    let pressures: Vec<f64> = (0..n)
        .flat_map(|i| [5e3 * i as f64, 2e3, 1e3 * (n - i) as f64])
        .collect();
    let forces: Vec<f64> = (0..n).flat_map(|i| [0.0, 0.01 * i as f64, 0.0]).collect();
    let t = ActuationTable {
        samples: n,
        tensions: &[],
        pressures: &pressures,
        tip_force: Some(&forces),
        tip_moment: None,
    };
    let out = sweep(
        &[job(&model, rk4(50), t, &[])],
        &SweepRequest {
            tip_pose: true,
            ..SweepRequest::default()
        },
        1,
        true,
    )
    .unwrap();
    for i in 0..n {
        let loaded = model
            .with_loads(Loads {
                tip_force: Vector3::new(forces[3 * i], forces[3 * i + 1], forces[3 * i + 2]),
                ..Loads::default()
            })
            .unwrap();
        let act = Actuation::pressures(&pressures[3 * i..3 * i + 3]);
        let sol = solve_statics(&loaded, &act, &rk4(50)).unwrap();
        assert_eq!(out[0][i].tip_position, sol.tip_position(), "row {i}");
    }
    // The pressures bend the arm: the samples differ.
    assert!(out[0][0].tip_position != out[0][n - 1].tip_position);
}

#[test]
fn failures_are_recorded_and_the_next_row_starts_cold() {
    let model = RobotModel::new(
        common::niti_rod(),
        vec![Tendon::constant([0.01, 0.0], None).unwrap()],
        Vec::new(),
        Loads::default(),
    )
    .unwrap();
    let n = 4;
    let tensions = [0.5, 0.5, 0.5, 0.6];
    // Row 1 carries a tip force that one Newton iteration without continuation cannot meet.
    let forces = [0.0, 0.0, 0.0, 30.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let mut opts = rk4(40);
    opts.newton.max_iterations = 1;
    opts.newton.continuation = false;
    let t = ActuationTable {
        samples: n,
        tensions: &tensions,
        pressures: &[],
        tip_force: Some(&forces),
        tip_moment: None,
    };
    let out = sweep(&[job(&model, opts, t, &[0.2])], &all(), 4, true).unwrap();
    let s = &out[0];
    assert_eq!(s.len(), n);
    assert_eq!(s[1].status, SampleStatus::NotConverged);
    assert!(matches!(s[1].error, Some(Error::NotConverged { .. })));
    assert!(s[1].tip_position[0].is_nan() && s[1].arcs[0].compliance[(0, 0)].is_nan());
    assert!(s[1].stats.residual > opts.newton.tolerance);
    for k in [0, 2, 3] {
        assert_eq!(s[k].status, SampleStatus::Converged, "row {k}");
    }
    // Row 2 follows a failed row: it starts cold.
    let cold = solve_statics(&model, &Actuation::tensions(&[0.5]), &opts).unwrap();
    assert_eq!(s[2].tip_position, cold.tip_position());
}

#[test]
fn bad_tables_are_named_before_any_solve() {
    let model = loaded_model();
    let rows = [0.1, 0.2, -0.3, 0.0];
    let e = sweep(
        &[job(&model, rk4(20), table(2, &rows), &[])],
        &SweepRequest::default(),
        4,
        true,
    )
    .unwrap_err();
    assert!(matches!(e, Error::InvalidParameter { ref name, .. } if name == "tensions[1, 0]"));
    let e = sweep(
        &[job(&model, rk4(20), table(3, &rows), &[])],
        &SweepRequest::default(),
        4,
        true,
    )
    .unwrap_err();
    assert!(matches!(e, Error::InvalidParameter { ref name, .. } if name == "tensions.len()"));
    let ok = [0.1, 0.2];
    let e = sweep(
        &[
            job(&model, rk4(20), table(1, &ok), &[]),
            job(&model, rk4(20), table(1, &ok), &[f64::NAN]),
        ],
        &SweepRequest::default(),
        4,
        true,
    )
    .unwrap_err();
    assert!(
        matches!(e, Error::InvalidParameter { ref name, .. } if name == "jobs[1].arc_lengths[0]")
    );
    let e = sweep(
        &[job(&model, rk4(20), table(1, &ok), &[])],
        &SweepRequest::default(),
        0,
        true,
    )
    .unwrap_err();
    assert!(matches!(e, Error::InvalidParameter { ref name, .. } if name == "block"));
    // Arc lengths outside the rod are NaN, not an error.
    let out = sweep(
        &[job(&model, rk4(20), table(1, &ok), &[0.5])],
        &all(),
        4,
        true,
    )
    .unwrap();
    assert!(out[0][0].arcs[0].position[0].is_nan());
}

/// An arc length beyond a job's rod (a design shorter than the arc lengths asked) fails every
/// sample of that job by name (`arc_lengths[i]`), no solve made; it returned status converged
/// with NaN outputs. The other job, whose rod reaches it, measures there as a sweep of it alone.
#[test]
fn an_arc_length_beyond_a_jobs_rod_fails_its_samples_by_name() {
    let long = loaded_model();
    let rod = Rod::new(
        0.3,
        Section::circular(0.7e-3).unwrap(),
        LinearElastic::new(54e9, 0.3).unwrap(),
    )
    .unwrap();
    let short = RobotModel::new(
        rod,
        long.tendons().to_vec(),
        Vec::new(),
        long.loads().clone(),
    )
    .unwrap();
    let rows = tension_rows(3);
    let s = [0.1, 0.35];
    let jobs = [
        job(&long, rk4(40), table(3, &rows), &s),
        job(&short, rk4(40), table(3, &rows), &s),
    ];
    let out = sweep(&jobs, &all(), 2, false).unwrap();
    let alone = sweep(&jobs[..1], &all(), 2, false).unwrap();
    for (a, b) in out[0].iter().zip(&alone[0]) {
        assert!(same(a, b));
        assert_eq!(a.status, SampleStatus::Converged);
    }
    for sample in &out[1] {
        assert_eq!(sample.status, SampleStatus::Failed);
        match &sample.error {
            Some(Error::InvalidParameter { name, .. }) => assert_eq!(name, "arc_lengths[1]"),
            other => panic!("{other:?}"),
        }
    }
}

#[test]
fn a_job_with_an_obstacle_solves_its_contacts_and_balances_their_force() {
    // The NiTi robot bent towards +y onto a wall at y = 0.1 m: every sample is the contact
    // solve of that actuation (bit for bit, each row cold), no node passes the wall, and the
    // base carries the contacts' force (the only external load): N(0) = sum of contact forces.
    use softrod::{solve_constrained, Obstacle};
    let model = common::niti_model(Loads::default(), None, 0.0);
    let wall = Obstacle::plane([0.0, 0.1, 0.0], [0.0, -1.0, 0.0]).unwrap();
    let n = 6;
    let rows: Vec<f64> = (0..n)
        .flat_map(|i| [0.5 + 0.7 * i as f64, 0.0, 0.0, 0.0, 0.0, 0.0])
        .collect();
    let mut j = job(&model, SolveOptions::default(), table(n, &rows), &[0.2]);
    j.obstacles = vec![wall.clone()];
    let out = sweep(&[j], &all(), 4, true).unwrap();
    let mut touching = 0;
    for (i, sample) in out[0].iter().enumerate() {
        assert_eq!(
            sample.status,
            SampleStatus::Converged,
            "{i}: {:?}",
            sample.error
        );
        let act = Actuation::tensions(&rows[6 * i..6 * i + 6]);
        let direct = solve_constrained(
            &model,
            &act,
            &SolveOptions::default(),
            None,
            std::slice::from_ref(&wall),
        )
        .unwrap();
        assert_eq!(sample.tip_position, direct.solution.tip_position(), "{i}");
        assert_eq!(sample.contact_count, direct.contacts.len(), "{i}");
        // Out of the wall (to the rod's radius and the contact tolerance).
        let radius = 0.7e-3;
        for p in &direct.solution.position {
            assert!(p[1] <= 0.1 - radius + 1e-9, "{i}: y = {}", p[1]);
        }
        let f = sample.contact_force;
        let n0 = &direct.solution.base_wrench;
        let scale = f.iter().map(|v| v.abs()).fold(1e-12, f64::max);
        for k in 0..3 {
            assert!(
                (n0[k] - f[k]).abs() <= 1e-9 * scale,
                "{i}: N(0) {n0:?} vs contacts {f:?}"
            );
        }
        assert!(sample.tip_reaction.iter().all(|v| v.is_nan()));
        touching += usize::from(sample.contact_count > 0);
    }
    assert!(
        touching >= 3,
        "only {touching} of {n} samples touch the wall"
    );
}
