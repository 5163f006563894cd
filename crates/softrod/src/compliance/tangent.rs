//! The exact tangent compliance of a loaded, actuated equilibrium, from the linearised
//! boundary-value problem (after Oliver-Butler, Till & Rucker 2019).
//!
//! One march of the shooting equations with sensitivity columns: the six base-wrench columns,
//! one column per tendon held at fixed length (its tension), and six columns for a dead wrench
//! applied at the node (seeded there), with the path-length sensitivities
//! `δℓ_i = ∫ t_iᵀ (δv + δu × r_i) ds` of the held tendons integrated on the stages. The
//! unknowns (base wrench, held tensions) solve the linearised tip conditions and `δℓ_i = 0`.
//! Columns are integrated [`COLUMNS_PER_PASS`] at a time, so any number of tendons can be
//! held.
//!
//! # References
//! K. Oliver-Butler, J. Till, C. Rucker, "Continuum robot stiffness under external loads and
//! prescribed tendon displacements", IEEE Trans. Robotics 35(2), 2019.

use nalgebra::{Matrix3, Matrix6, Vector6};

use crate::cosserat::equations::{
    col_rot, rot, rotation_variation, v3, Column, Equations, Evaluator, Workspace, COLUMN, DM, DN,
    STATE,
};
use crate::cosserat::statics::{Integrator, StaticsSolution};
use crate::error::{Error, Result};
use crate::integrate::march::{march, rk4_plan, Scheme};
use crate::math::linalg::{invert_general, DenseLu};
use crate::math::se3::rotation_adjoint;

/// Most sensitivity columns integrated in one march (more are integrated in further marches
/// over the same state).
pub const COLUMNS_PER_PASS: usize = 24;

/// State length of a tangent pass with `c` columns.
const fn width(c: usize) -> usize {
    STATE + COLUMN * c
}

/// How the tendons behave under the extra wrench of [`tangent_compliance`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TendonControl {
    /// Tensions held fixed (force-controlled actuators).
    #[default]
    Tension,
    /// Path lengths of all tendons held fixed (displacement-controlled actuators): the
    /// tensions change; the linearisation treats the tendons as bilateral (a tension may go
    /// negative, i.e. slack, without the model noticing).
    Length,
}

/// The exact tangent compliance at one node.
#[derive(Debug, Clone, PartialEq)]
pub struct TangentCompliance {
    /// Index of the node in the solution.
    pub node: usize,
    /// Its undeformed arc length (m).
    pub s: f64,
    /// `d[δp; δθ]/d[f; m]`, world components, wrench applied at the node.
    pub world: Matrix6<f64>,
    /// The same in the node's body axes.
    pub body: Matrix6<f64>,
    /// `world⁻¹` (NaN if not positive definite).
    pub stiffness_world: Matrix6<f64>,
    /// `body⁻¹` (NaN if not positive definite).
    pub stiffness_body: Matrix6<f64>,
    /// 1-norm condition number (SI units).
    pub condition: f64,
    /// Whether the tangent is symmetric to 1e-6 relative (it is at equilibria of conservative
    /// loads; follower loads make it non-symmetric).
    pub symmetric: bool,
    /// `dτ_i/d[f; m]` (N/N, N/(N m)), one row per tendon; zero rows under
    /// [`TendonControl::Tension`].
    pub tension_rate: Vec<[f64; 6]>,
}

/// What a column of the linearised problem is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Seed {
    /// Component `k` of the scaled base wrench (seeded at the base).
    Base(usize),
    /// The tension of tendon `i` (forced along the rod).
    Tension(usize),
    /// Component `k` of the wrench applied at the node (seeded at the node).
    Load(usize),
}

/// Integrates `seeds` (at most `C` of them) in one march: per column its scaled residual
/// derivative, its path-length sensitivities of `held`, and its pose derivative `(δp, R w)` at
/// the node; and the node's rotation.
struct Pass {
    residual: Vec<Vector6<f64>>,
    lengths: Vec<Vec<f64>>,
    pose: Vec<Vector6<f64>>,
    rotation: Option<Matrix3<f64>>,
}

fn pass<const N: usize>(
    eq: Equations<'_>,
    scheme: Scheme<'_>,
    x: &[f64; 6],
    seeds: &[Seed],
    held: &[usize],
    target: f64,
) -> Result<Pass> {
    let model = eq.model;
    let mut ws = Workspace::new(model.tendons().len());
    let columns: Vec<Column> = seeds
        .iter()
        .map(|s| match s {
            Seed::Tension(i) => Column::Tension(*i),
            _ => Column::Free,
        })
        .collect();
    ws.set_columns(&columns, held);
    ws.track_lengths = true;
    let mut y0: [f64; N] = eq.initial(x);
    y0[STATE..].fill(0.0);
    let f_ref = model.force_scale();
    let fm = f_ref * model.length();
    for (c, s) in seeds.iter().enumerate() {
        if let Seed::Base(k) = s {
            let b = STATE + COLUMN * c;
            if *k < 3 {
                y0[b + DN + k] = f_ref;
            } else {
                y0[b + DM + k - 3] = fm;
            }
        }
    }
    let mut ev = Evaluator { eq, ws: &mut ws };
    let mut at_node: Option<(Vec<Vector6<f64>>, Matrix3<f64>)> = None;
    let y = march(
        &mut ev,
        model.breaks(),
        &[target],
        y0,
        scheme,
        |_, s, _, y| {
            if at_node.is_none() && s == target {
                let r = rot(y);
                let pose = (0..seeds.len())
                    .map(|c| {
                        let b = STATE + COLUMN * c;
                        let (dp, w) = (v3(y, b), rotation_variation(&r, &col_rot(y, b)));
                        Vector6::new(dp.x, dp.y, dp.z, w.x, w.y, w.z)
                    })
                    .collect();
                at_node = Some((pose, r));
                for (c, seed) in seeds.iter().enumerate() {
                    if let Seed::Load(k) = seed {
                        let b = STATE + COLUMN * c + if *k < 3 { DN + k } else { DM + k - 3 };
                        y[b] = -1.0;
                    }
                }
            }
        },
    )?;
    let (_, residual) = eq.residual(&y, seeds.len());
    let nt = model.tendons().len();
    let nl = held.len();
    let lengths = (0..seeds.len())
        .map(|c| ws.integral[nt + c * nl..nt + (c + 1) * nl].to_vec())
        .collect();
    let (pose, rotation) = match at_node {
        Some((p, r)) => (p, Some(r)),
        None => (Vec::new(), None),
    };
    Ok(Pass {
        residual,
        lengths,
        pose,
        rotation,
    })
}

/// The exact tangent compliance of the equilibrium `solution` at node `node` (default: the
/// tip): the derivative of the node's twist `[δp; δθ]` with respect to a dead wrench `[f; m]`
/// applied at the node's position, with the tendons held at fixed tension or at fixed length;
/// integrated with the solution's integrator and mesh.
///
/// # Errors
/// [`Error::InvalidParameter`] for a node out of range; [`Error::NotConverged`] if the
/// integration fails or the linear system is singular.
pub fn tangent_compliance(
    solution: &StaticsSolution,
    control: TendonControl,
    node: Option<usize>,
) -> Result<TangentCompliance> {
    let held: Vec<usize> = match control {
        TendonControl::Tension => Vec::new(),
        TendonControl::Length => (0..solution.model.tendons().len()).collect(),
    };
    tangent_compliance_held(solution, &held, node)
}

/// [`tangent_compliance`] with only the tendons `held` (indices) at fixed length, the others at
/// fixed tension (e.g. hold only the tensioned tendons: a slack tendon cannot push).
///
/// # Errors
/// As [`tangent_compliance`]; [`Error::InvalidParameter`] naming `held[k]` for an index out of
/// range or repeated.
pub fn tangent_compliance_held(
    solution: &StaticsSolution,
    held: &[usize],
    node: Option<usize>,
) -> Result<TangentCompliance> {
    let model = &*solution.model;
    let nt = model.tendons().len();
    let n = solution.s.len();
    let node = node.unwrap_or(n.saturating_sub(1));
    if node >= n {
        return Err(Error::invalid("node", node, format!("in [0, {n})")));
    }
    for (k, &i) in held.iter().enumerate() {
        if i >= nt || held[..k].contains(&i) {
            return Err(Error::invalid(
                format!("held[{k}]"),
                i,
                format!("distinct tendon indices in [0, {nt})"),
            ));
        }
    }
    let target = solution.s[node];
    let mut tension_rate = vec![[0.0; 6]; nt];
    if target <= 0.0 {
        let z = Matrix6::zeros();
        let nan = Matrix6::repeat(f64::NAN);
        return Ok(TangentCompliance {
            node,
            s: target,
            world: z,
            body: z,
            stiffness_world: nan,
            stiffness_body: nan,
            condition: f64::INFINITY,
            symmetric: true,
            tension_rate,
        });
    }
    let tensions = solution.tensions();
    let pressures = solution.pressures();
    let eq = Equations {
        model,
        tensions: &tensions,
        pressures: &pressures,
        load_factor: solution.stats.load_factor,
        profile: solution.actuation.profile.as_deref(),
    };
    let f_ref = model.force_scale();
    let fm = f_ref * model.length();
    let bw = solution.base_wrench;
    let x = [
        bw[0] / f_ref,
        bw[1] / f_ref,
        bw[2] / f_ref,
        bw[3] / fm,
        bw[4] / fm,
        bw[5] / fm,
    ];
    let plan;
    let scheme = match solution.options.integrator {
        Integrator::Rk4 { steps } => {
            plan = rk4_plan(model.breaks(), steps);
            Scheme::Rk4(&plan)
        }
        Integrator::Adaptive(options) => Scheme::Adaptive {
            options,
            controlled: STATE,
        },
    };
    let seeds: Vec<Seed> = (0..6)
        .map(Seed::Base)
        .chain(held.iter().map(|&i| Seed::Tension(i)))
        .chain((0..6).map(Seed::Load))
        .collect();
    let columns = integrate_columns(eq, scheme, &x, &seeds, held, target).map_err(|e| match e {
        Error::InvalidParameter { .. } => Error::invalid(
            "node",
            node,
            "a node of the solution's mesh (solve and tangent with the same integrator)",
        ),
        other => other,
    })?;
    let world = solve_linearised(&columns, held, &mut tension_rate)?;
    let r_node = columns.rotation.unwrap_or_else(Matrix3::identity);
    let rt = rotation_adjoint(&r_node.transpose());
    let body = rt * world * rt.transpose();
    let asym = (world - world.transpose()).amax();
    let symmetric = asym <= 1e-6 * world.amax();
    let (kw, condition) = invert_general(&world);
    let (kb, _) = invert_general(&body);
    Ok(TangentCompliance {
        node,
        s: target,
        world,
        body,
        stiffness_world: kw,
        stiffness_body: kb,
        condition,
        symmetric,
        tension_rate,
    })
}

/// Every column of the linearised problem, integrated [`COLUMNS_PER_PASS`] at a time.
fn integrate_columns(
    eq: Equations<'_>,
    scheme: Scheme<'_>,
    x: &[f64; 6],
    seeds: &[Seed],
    held: &[usize],
    target: f64,
) -> Result<Pass> {
    let mut all = Pass {
        residual: Vec::new(),
        lengths: Vec::new(),
        pose: Vec::new(),
        rotation: None,
    };
    for chunk in seeds.chunks(COLUMNS_PER_PASS) {
        let p = if chunk.len() <= 12 {
            pass::<{ width(12) }>(eq, scheme, x, chunk, held, target)?
        } else if chunk.len() <= 18 {
            pass::<{ width(18) }>(eq, scheme, x, chunk, held, target)?
        } else {
            pass::<{ width(COLUMNS_PER_PASS) }>(eq, scheme, x, chunk, held, target)?
        };
        if p.rotation.is_none() {
            return Err(Error::invalid("node", target, "a node of the mesh"));
        }
        all.rotation = p.rotation;
        all.residual.extend(p.residual);
        all.lengths.extend(p.lengths);
        all.pose.extend(p.pose);
    }
    Ok(all)
}

/// Solves the linearised tip conditions and held lengths for the base wrench and the held
/// tensions, per applied wrench component: the world compliance at the node, and the tension
/// rates of the held tendons into `tension_rate`.
fn solve_linearised(
    columns: &Pass,
    held: &[usize],
    tension_rate: &mut [[f64; 6]],
) -> Result<Matrix6<f64>> {
    let fail =
        |what: &str| Error::not_converged(format!("tangent compliance: {what}"), 0, f64::INFINITY);
    let (residual, lengths, pose) = (&columns.residual, &columns.lengths, &columns.pose);
    // Linear system in z = [δx (scaled base wrench); δτ (held)], column-major.
    let dim = 6 + held.len();
    let mut a = vec![0.0; dim * dim];
    for c in 0..dim {
        a[c * dim..c * dim + 6].copy_from_slice(residual[c].as_slice());
        a[c * dim + 6..(c + 1) * dim].copy_from_slice(&lengths[c]);
    }
    let mut lu = DenseLu::default();
    if !lu.factor(dim, &a) {
        return Err(fail("singular linearised problem"));
    }
    let mut world = Matrix6::zeros();
    for i in 0..6 {
        let c = dim + i;
        let mut z: Vec<f64> = residual[c].iter().chain(&lengths[c]).map(|v| -v).collect();
        if !lu.solve_in_place(&mut z) {
            return Err(fail("singular linearised problem"));
        }
        let mut t = Vector6::zeros();
        for (k, p) in pose.iter().take(dim).enumerate() {
            t += p * z[k];
        }
        world.set_column(i, &t);
        for (h, &ti) in held.iter().enumerate() {
            tension_rate[ti][i] = z[6 + h];
        }
    }
    Ok(world)
}
