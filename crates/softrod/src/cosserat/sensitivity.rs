//! Exact sensitivities of an equilibrium: the linearised boundary-value problem.
//!
//! A solved configuration `y(s; x, a)` (state `(p, R, N, M)` along the rod, `x` the scaled base
//! wrench, `a` the inputs and parameters) meets the tip conditions `r(x, a) = 0` and, for every
//! displacement-controlled tendon held taut, `g_h = ℓ_ref - ℓ_h - δ_h + τ_h / k_h = 0`. For a
//! parameter `p` the derivative of the equilibrium solves
//!
//! ```text
//! [∂r/∂x  ∂r/∂τ_H] [δx  ]     [∂r/∂p]
//! [∂g/∂x  ∂g/∂τ_H] [δτ_H] = - [∂g/∂p],     δy = Σ_k y_{x_k} δx_k + Σ_h y_{τ_h} δτ_h + y_p,
//! ```
//!
//! where every column `y_c = ∂y/∂c` is a solution of the variational equations of
//! `cosserat/equations/` integrated with the state: the six base-wrench columns start from a
//! unit base wrench, a parameter's column from zero (or from its change of the base pose) and
//! is forced along the rod by the parameter's change of the constitutive balance at fixed
//! strains, `e -= ∂(T + W_c + n_el)/∂p` in the body wrench of the local solve (`T` the
//! tendons' share, `W_c` the chambers' fluid, `n_el` the rod's elastic wrench). The path-length
//! sensitivities `δℓ_i = ∫ t_iᵀ (δv + δu × r_i + u × δr_i + δr_i') ds` ride on the stages of the
//! same march. No finite differences: the derivatives are those of the discretised equations
//! (the same mesh and integrator as the solution), exact to round-off and the
//! re-orthonormalisation of the rotations.
//!
//! When the rod carries no internal force (no external force along it, a zero base force:
//! every unloaded actuated rod), the base wrench does not change with a parameter
//! (`∂r/∂p = 0` and `δx = 0` exactly) and its six columns are skipped.
//!
//! The forcings of the [`Parameter`]s (body frame, per unit of the parameter):
//! * tension of tendon `i`: `(t_i, r_i × t_i)` where the tendon passes;
//! * pressure of chamber `j`: its fluid wrench per Pa, `(-A e_z, -A r_c × e_z)`, where it is;
//! * a tension factor: `Σ τ_i (t_i, r_i × t_i)`; a chamber area factor: the fluid wrench;
//! * a stiffness factor `k` (elastic wrench `k F(e)`): `n_el`, linear or hyperelastic;
//! * an offset factor or shift of tendon `i` (`δr_i = r_i` or a constant vector):
//!   `τ_i (δt_i, δr_i × t_i + r_i × δt_i)`, `δt_i = (I - t tᵀ)(u × δr_i + δr_i') / |w_i|`;
//! * a base translation or rotation: no forcing, the column starts from `δp(0)` or
//!   `δR(0) = [e_k]× R(0)`;
//! * the displacement of a held tendon: no column, only `∂g_h/∂δ_h = -1`.
//!
//! The zero of the displacements (the reference lengths `ℓ_ref`) is held fixed.
//!
//! # References
//! K. Oliver-Butler, J. Till, C. Rucker, "Continuum robot stiffness under external loads and
//! prescribed tendon displacements", IEEE Trans. Robotics 35(2), 2019 (the linearised
//! boundary-value problem).

use nalgebra::{DMatrix, Matrix3, Vector3, Vector6};

use super::equations::{
    col_rot, rot, rotation_variation, v3, Column, Equations, Evaluator, Workspace, COLUMN, DM, DN,
    DR, STATE,
};
use super::friction_linear::{frictional_actuation_jacobians, Direction};
use super::shooting::Node;
use super::statics::{Integrator, StaticsSolution};
use crate::error::{Error, Result};
use crate::integrate::march::{march, rk4_plan, Scheme};
use crate::math::linalg::DenseLu;
use crate::math::so3::hat;
use crate::model::section::SectionProperties;
use crate::model::{RobotModel, TendonInput};

/// Most sensitivity columns integrated in one march (more are integrated in further marches
/// over the same state).
pub const COLUMNS_PER_PASS: usize = 24;

/// A scalar input or model parameter whose effect on an equilibrium [`sensitivities`]
/// computes (one column of the linearised problem each).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Parameter {
    /// Tension of tendon `i` (per N). For a displacement-controlled tendon held taut, the
    /// sensitivity is taken with the tendon at fixed tension (use
    /// [`Linearisation::Tension`]).
    Tension(usize),
    /// Displacement of tendon `i` (per m); the tendon must be displacement-controlled.
    Displacement(usize),
    /// Gauge pressure of chamber `j` (per Pa).
    Pressure(usize),
    /// A factor multiplying every tendon tension (per unit factor, at 1: `Σ τ_i ∂/∂τ_i`).
    TensionScale,
    /// A factor multiplying the rod's section stiffness (every component; the Young's modulus
    /// of a linear material at fixed Poisson's ratio, or the stress of a hyperelastic law),
    /// per unit factor at 1: `E ∂/∂E`.
    StiffnessScale,
    /// A factor multiplying the offset `r_i(s)` of tendon `i` from the backbone (its distance,
    /// ratio or helix radius), per unit factor at 1.
    TendonOffsetScale(usize),
    /// A shift of the offset of tendon `i` by the body-frame vector `direction` (per m along
    /// it).
    TendonOffsetShift {
        /// The tendon.
        tendon: usize,
        /// Body-frame `(x, y)` direction of the shift.
        direction: [f64; 2],
    },
    /// A factor multiplying the area of chamber `j` (per unit factor, at 1).
    ChamberAreaScale(usize),
    /// Translation of the base along world axis `k` (per m).
    BaseTranslation(usize),
    /// Rotation of the base about world axis `k` (per rad, `δR(0) = [e_k]× R(0)`).
    BaseRotation(usize),
}

/// How the tendons respond when an input or parameter changes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Linearisation {
    /// As the solution is actuated: tension-controlled tendons keep their tension,
    /// displacement-controlled tendons held taut keep their displacement (their tension is
    /// an unknown), slack ones stay slack.
    #[default]
    Actuated,
    /// Every tendon keeps its tension (the actuation Jacobian with respect to tensions).
    Tension,
}

/// Exact derivatives of an equilibrium with respect to [`Parameter`]s, at chosen nodes.
#[derive(Debug, Clone, PartialEq)]
pub struct Sensitivities {
    /// The parameters, one column each.
    pub parameters: Vec<Parameter>,
    /// Node indices (into the solution's samples).
    pub nodes: Vec<usize>,
    /// Their undeformed arc lengths (m).
    pub s: Vec<f64>,
    /// Per node, `d[δp; δθ]/dp` (6 × n_parameters): position (m) and rotation (rad, world
    /// frame, `δR = [δθ]× R`) per unit of each parameter.
    pub pose: Vec<DMatrix<f64>>,
    /// `d(base wrench)/dp` (6 × n_parameters; N, N m, world, total of rod and tendons).
    pub base_wrench: DMatrix<f64>,
    /// `dτ_i/dp` (n_tendons × n_parameters; N): nonzero for held tendons only (and the
    /// tension parameters themselves).
    pub tendon_tensions: DMatrix<f64>,
    /// `dℓ_i/dp` (n_tendons × n_parameters; m) of the tendon path lengths.
    pub tendon_lengths: DMatrix<f64>,
}

/// What a column of a pass is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Seed {
    /// Component `k` of the scaled base wrench (seeded at the base).
    Base(usize),
    /// Component `k` of a dead wrench applied at the load node (seeded there).
    Load(usize),
    /// A column forced along the rod, from zero at the base.
    Forced(Column),
    /// A translation of the base along world axis `k`.
    BaseTranslation(usize),
    /// A rotation of the base about world axis `k`.
    BaseRotation(usize),
}

/// What to integrate in one request.
pub(crate) struct Request<'r> {
    pub seeds: &'r [Seed],
    /// Tendons whose path-length sensitivities are integrated.
    pub lengths: &'r [usize],
    /// Node indices (increasing) whose pose derivatives are recorded.
    pub observe: &'r [usize],
    /// Node index where the [`Seed::Load`] columns are seeded.
    pub load_node: Option<usize>,
    /// Whether to record the nodes of the march.
    pub record_nodes: bool,
    /// Arc lengths inside the rod where the march puts a node (a solution's `s_out`).
    pub stops: &'r [f64],
}

/// The result of integrating the columns of a [`Request`].
pub(crate) struct Integrated {
    /// Scaled tip residual at the end of the march.
    pub residual: Vector6<f64>,
    /// Tendon path lengths (m, quadrature on the stages).
    pub lengths: Vec<f64>,
    /// Per column, the derivative of the scaled residual.
    pub d_residual: Vec<Vector6<f64>>,
    /// Per column, the path-length sensitivities of the requested tendons.
    pub d_lengths: Vec<Vec<f64>>,
    /// Per observed node, per column, `(δp, R w)` (world).
    pub poses: Vec<Vec<Vector6<f64>>>,
    /// Per observed node, its rotation.
    pub rotations: Vec<Matrix3<f64>>,
    /// The nodes (if recorded).
    pub nodes: Vec<Node>,
    /// Per column, `(δp, R w)` at the tip.
    pub tip: Vec<Vector6<f64>>,
    /// Tip position (m) and rotation.
    pub tip_pose: (Vector3<f64>, Matrix3<f64>),
    /// Right-hand-side evaluations.
    pub evaluations: usize,
}

/// The integration scheme of `integrator` on the breaks of `model` (`plan` keeps the RK4
/// plan alive).
pub(crate) fn scheme_of<'p>(
    integrator: &Integrator,
    model: &RobotModel,
    plan: &'p mut Vec<usize>,
) -> Scheme<'p> {
    match *integrator {
        Integrator::Rk4 { steps } => {
            *plan = rk4_plan(model.breaks(), steps);
            Scheme::Rk4(plan)
        }
        Integrator::Adaptive(options) => Scheme::Adaptive {
            options,
            controlled: STATE,
        },
    }
}

#[allow(clippy::too_many_lines)] // one sequential algorithm, documented above
fn pass<const N: usize>(
    eq: Equations<'_>,
    scheme: Scheme<'_>,
    x: &[f64; 6],
    req: &Request<'_>,
    seeds: &[Seed],
    record: bool,
) -> Result<Integrated> {
    let model = eq.model;
    let nt = model.tendons().len();
    let mut ws = Workspace::new(nt);
    let columns: Vec<Column> = seeds
        .iter()
        .map(|s| match s {
            Seed::Forced(c) => *c,
            _ => Column::Free,
        })
        .collect();
    ws.set_columns(&columns, req.lengths);
    ws.track_lengths = true;
    let mut y0: [f64; N] = eq.initial(x);
    y0[STATE..].fill(0.0);
    let f_ref = model.force_scale();
    let fm = f_ref * model.length();
    let r0 = model.rod().base_pose().rotation();
    for (c, s) in seeds.iter().enumerate() {
        let b = STATE + COLUMN * c;
        match *s {
            Seed::Base(k) if k < 3 => y0[b + DN + k] = f_ref,
            Seed::Base(k) => y0[b + DM + k - 3] = fm,
            Seed::BaseTranslation(k) => y0[b + k] = 1.0,
            Seed::BaseRotation(k) => {
                // δR(0) = δθ̂ R(0) for a world rotation δθ = e_k.
                let dr = hat(&Vector3::ith(k, 1.0)) * r0;
                y0[b + DR..b + DR + 9].copy_from_slice(dr.as_slice());
            }
            Seed::Load(_) | Seed::Forced(_) => {}
        }
    }
    let mut ev = Evaluator { eq, ws: &mut ws };
    let mut poses = Vec::with_capacity(req.observe.len());
    let mut rotations = Vec::with_capacity(req.observe.len());
    let mut nodes = Vec::new();
    let mut index = 0usize;
    let mut next = 0usize;
    let y = march(
        &mut ev,
        model.breaks(),
        req.stops,
        y0,
        scheme,
        |_, s, interval, y| {
            if record {
                let mut h = [0.0; STATE];
                h.copy_from_slice(&y[..STATE]);
                nodes.push(Node { s, interval, y: h });
            }
            if req.observe.get(next) == Some(&index) {
                let r = rot(y);
                poses.push(
                    (0..seeds.len())
                        .map(|c| {
                            let b = STATE + COLUMN * c;
                            let (dp, w) = (v3(y, b), rotation_variation(&r, &col_rot(y, b)));
                            Vector6::new(dp.x, dp.y, dp.z, w.x, w.y, w.z)
                        })
                        .collect(),
                );
                rotations.push(r);
                while req.observe.get(next) == Some(&index) {
                    next += 1;
                }
            }
            if req.load_node == Some(index) {
                for (c, seed) in seeds.iter().enumerate() {
                    if let Seed::Load(k) = seed {
                        let b = STATE + COLUMN * c + if *k < 3 { DN + k } else { DM + k - 3 };
                        y[b] = -1.0;
                    }
                }
            }
            index += 1;
        },
    )?;
    let evaluations = ws.evaluations;
    if !y[..STATE].iter().all(|v| v.is_finite()) {
        return Err(Error::NotConverged {
            what: "rod integration: non-finite state".into(),
            iterations: 0,
            residual: f64::INFINITY,
            load_factor: 1.0,
        });
    }
    if next < req.observe.len() {
        return Err(Error::invalid(
            "node",
            req.observe[next],
            format!("a node of the solution's mesh (< {index})"),
        ));
    }
    let (residual, d_residual) = eq.residual(&y, seeds.len());
    let r_tip = rot(&y);
    let tip = (0..seeds.len())
        .map(|c| {
            let b = STATE + COLUMN * c;
            let (dp, w) = (v3(&y, b), rotation_variation(&r_tip, &col_rot(&y, b)));
            Vector6::new(dp.x, dp.y, dp.z, w.x, w.y, w.z)
        })
        .collect();
    let nl = req.lengths.len();
    let d_lengths = (0..seeds.len())
        .map(|c| ws.integral[nt + c * nl..nt + (c + 1) * nl].to_vec())
        .collect();
    Ok(Integrated {
        residual,
        lengths: ws.integral[..nt].to_vec(),
        d_residual,
        d_lengths,
        poses,
        rotations,
        nodes,
        tip,
        tip_pose: (v3(&y, 0), r_tip),
        evaluations,
    })
}

/// State length of a pass with `c` columns.
const fn width(c: usize) -> usize {
    STATE + COLUMN * c
}

/// Integrates every column of `req` ([`COLUMNS_PER_PASS`] per march) with the state from the
/// scaled base wrench `x`.
///
/// # Errors
/// [`Error::NotConverged`] if the integration fails; [`Error::InvalidParameter`] naming `node`
/// for an observed node that is not on the mesh.
pub(crate) fn integrate(
    eq: Equations<'_>,
    scheme: Scheme<'_>,
    x: &[f64; 6],
    req: &Request<'_>,
) -> Result<Integrated> {
    if req.seeds.is_empty() {
        return pass::<STATE>(eq, scheme, x, req, &[], req.record_nodes);
    }
    let mut all: Option<Integrated> = None;
    for chunk in req.seeds.chunks(COLUMNS_PER_PASS) {
        let record = req.record_nodes && all.is_none();
        let p = match chunk.len() {
            0..=6 => pass::<{ width(6) }>(eq, scheme, x, req, chunk, record)?,
            7..=12 => pass::<{ width(12) }>(eq, scheme, x, req, chunk, record)?,
            13..=18 => pass::<{ width(18) }>(eq, scheme, x, req, chunk, record)?,
            _ => pass::<{ width(COLUMNS_PER_PASS) }>(eq, scheme, x, req, chunk, record)?,
        };
        match &mut all {
            None => all = Some(p),
            Some(a) => {
                a.d_residual.extend(p.d_residual);
                a.d_lengths.extend(p.d_lengths);
                for (mine, theirs) in a.poses.iter_mut().zip(p.poses) {
                    mine.extend(theirs);
                }
                a.tip.extend(p.tip);
                a.evaluations += p.evaluations;
            }
        }
    }
    all.ok_or_else(|| Error::invalid("seeds", 0, "at least one"))
}

impl Evaluator<'_, '_> {
    /// The body-wrench forcing of `column` at `s` (strains `v`, `u`; rod's elastic wrench
    /// `n_el`), and the rate `(tendon, t·δw)` of the path length of the tendon whose offset it
    /// changes. The tendon directions of the evaluation are in `ws.dirs`.
    pub(crate) fn forcing(
        &self,
        column: Column,
        s: f64,
        props: &SectionProperties,
        v: &Vector3<f64>,
        u: &Vector3<f64>,
        n_el: &Vector6<f64>,
    ) -> ([f64; 6], Option<(usize, f64)>) {
        let model = self.eq.model;
        let breaks = model.breaks();
        let k = self.ws.interval;
        let fills = |j: usize| {
            let (start, end) = model.chamber_extents()[j];
            start <= breaks[k] && end >= breaks[k + 1]
        };
        let dirs = &self.ws.dirs;
        let z = [0.0; 6];
        match column {
            Column::Free => (z, None),
            Column::Tension(i) => (dirs[i].map_or(z, Into::into), None),
            Column::Pressure(j) if fills(j) => (model.chambers()[j].fluid_wrench(s, 1.0), None),
            Column::ChamberAreaScale(j) if fills(j) => (
                model.chambers()[j].fluid_wrench(s, self.eq.pressures[j]),
                None,
            ),
            Column::Pressure(_) | Column::ChamberAreaScale(_) => (z, None),
            Column::TensionScale => {
                let mut f = Vector6::zeros();
                for (i, d) in dirs.iter().enumerate() {
                    if let Some(d) = d {
                        f += d * self.eq.tensions[i];
                    }
                }
                (f.into(), None)
            }
            Column::StiffnessScale => ((*n_el).into(), None),
            Column::TendonOffsetScale(i) | Column::TendonOffsetShift(i, _) => {
                if dirs[i].is_none() {
                    return (z, None);
                }
                let (r, rp) = model.tendons()[i].routing().offset(s, props);
                let r = Vector3::new(r[0], r[1], 0.0);
                let rp = Vector3::new(rp[0], rp[1], 0.0);
                let (dr, drp) = match column {
                    Column::TendonOffsetShift(_, d) => {
                        (Vector3::new(d[0], d[1], 0.0), Vector3::zeros())
                    }
                    _ => (r, rp),
                };
                let w = v + u.cross(&r) + rp;
                let len = w.norm();
                let t = w / len;
                let dw = u.cross(&dr) + drp;
                let dt = (dw - t * t.dot(&dw)) / len;
                let dq = dr.cross(&t) + r.cross(&dt);
                let tau = self.eq.tensions[i];
                (
                    [
                        tau * dt.x,
                        tau * dt.y,
                        tau * dt.z,
                        tau * dq.x,
                        tau * dq.y,
                        tau * dq.z,
                    ],
                    Some((i, t.dot(&dw))),
                )
            }
        }
    }
}

/// A displacement-controlled tendon held taut, as a row and an unknown of the linearised
/// problem.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct HeldRow {
    /// The tendon.
    pub tendon: usize,
    /// Its compliance `1/k` (m/N; 0 when inextensible).
    pub compliance: f64,
}

/// The scaled base wrench of a solution.
pub(crate) fn scaled_base_wrench(model: &RobotModel, bw: &[f64; 6]) -> [f64; 6] {
    let f_ref = model.force_scale();
    let fm = f_ref * model.length();
    [
        bw[0] / f_ref,
        bw[1] / f_ref,
        bw[2] / f_ref,
        bw[3] / fm,
        bw[4] / fm,
        bw[5] / fm,
    ]
}

/// The taut displacement-controlled tendons of a solution.
pub(crate) fn held_rows(solution: &StaticsSolution) -> Vec<HeldRow> {
    solution
        .actuation
        .tendons
        .iter()
        .enumerate()
        .filter_map(|(i, t)| match t {
            TendonInput::Displacement { stiffness, .. } if solution.tendon_tensions[i] != 0.0 => {
                Some(HeldRow {
                    tendon: i,
                    compliance: 1.0 / stiffness,
                })
            }
            _ => None,
        })
        .collect()
}

/// Whether the rod of `solution` carries no internal force (then the base wrench does not
/// change with any parameter).
fn force_free_at(model: &RobotModel, x: &[f64; 6], load_factor: f64) -> bool {
    x[..3].iter().all(|v| *v == 0.0) && (model.force_free() || load_factor == 0.0)
}

/// The linearised problem of a solution for a set of right-hand-side columns.
pub(crate) struct Linear {
    /// Per right-hand side, the pose derivative at each observed node.
    pub pose: Vec<Vec<Vector6<f64>>>,
    /// Per right-hand side, the scaled base-wrench change.
    pub base: Vec<[f64; 6]>,
    /// Per right-hand side, the change of each held tension (N).
    pub tensions: Vec<Vec<f64>>,
    /// Per right-hand side, the change of each requested tendon length (m).
    pub lengths: Vec<Vec<f64>>,
    /// Rotations at the observed nodes.
    pub rotations: Vec<Matrix3<f64>>,
}

/// Solves the linearised problem of `solution`, the tendons of `held` at fixed length (with
/// their compliance) and the others at fixed tension, for the columns `seeds` (and, for held
/// tendons' displacements, the unit right-hand sides in `displaced`: indices into `held`),
/// observing the nodes `observe` (increasing) and the path lengths of `lengths`.
/// Right-hand sides are ordered: `seeds`, then `displaced`.
#[allow(clippy::too_many_lines)] // one sequential algorithm, documented above
pub(crate) fn linearise(
    solution: &StaticsSolution,
    held: &[HeldRow],
    seeds: &[Seed],
    displaced: &[usize],
    observe: &[usize],
    lengths: &[usize],
    load_node: Option<usize>,
) -> Result<Linear> {
    let model = &*solution.model;
    let x = scaled_base_wrench(model, &solution.base_wrench);
    let lambda = solution.stats.load_factor;
    let tensions = &solution.tendon_tensions;
    let pressures = solution.pressures();
    let eq = Equations {
        model,
        tensions,
        pressures: &pressures,
        load_factor: lambda,
        profile: solution.actuation.profile.as_deref(),
    };
    let loads_seeded = seeds.iter().any(|s| matches!(s, Seed::Load(_)));
    let free = !loads_seeded && force_free_at(model, &x, lambda);
    let nb = if free { 0 } else { 6 };
    let nh = held.len();
    let mut all: Vec<Seed> = Vec::with_capacity(nb + nh + seeds.len());
    all.extend((0..nb).map(Seed::Base));
    all.extend(held.iter().map(|h| Seed::Forced(Column::Tension(h.tendon))));
    all.extend_from_slice(seeds);
    let mut len_tendons: Vec<usize> = held.iter().map(|h| h.tendon).collect();
    for &i in lengths {
        if !len_tendons.contains(&i) {
            len_tendons.push(i);
        }
    }
    let mut plan = Vec::new();
    let stops = super::statics::interior(&solution.s_out, model.length());
    let scheme = scheme_of(&solution.options.integrator, model, &mut plan);
    // A solution reported at `s_out` keeps some nodes of its march: map its node indices to
    // the march's (the last node at each arc length, as the solution reports).
    let (observe, load_node) = if solution.s_out.is_empty() {
        (observe.to_vec(), load_node)
    } else {
        let nodes = integrate(
            eq,
            scheme,
            &x,
            &Request {
                seeds: &[],
                lengths: &[],
                observe: &[],
                load_node: None,
                record_nodes: true,
                stops: &stops,
            },
        )?
        .nodes;
        let map = |i: usize| -> Result<usize> {
            let s = *solution
                .s
                .get(i)
                .ok_or_else(|| Error::invalid("node", i, "a node of the solution"))?;
            nodes
                .iter()
                .rposition(|n| n.s == s)
                .ok_or_else(|| Error::invalid("node", i, "a node of the solution"))
        };
        (
            observe
                .iter()
                .map(|&i| map(i))
                .collect::<Result<Vec<_>>>()?,
            load_node.map(map).transpose()?,
        )
    };
    let observe = &observe[..];
    let cols = integrate(
        eq,
        scheme,
        &x,
        &Request {
            seeds: &all,
            lengths: &len_tendons,
            observe,
            load_node,
            record_nodes: false,
            stops: &stops,
        },
    )?;
    // Unknowns z = [δx (nb); δτ_H / f_ref (nh)]; rows: tip residual (nb), held slack / scale.
    let f_ref = model.force_scale();
    let dim = nb + nh;
    let row_scale: Vec<f64> = held
        .iter()
        .map(|h| 1.0 / slack_scale(model, h.tendon, h.compliance))
        .collect();
    let entry = |c: usize, row: usize| -> f64 {
        if row < nb {
            cols.d_residual[c][row]
        } else {
            let h = row - nb;
            -cols.d_lengths[c][h] * row_scale[h]
        }
    };
    let mut a = vec![0.0; dim * dim];
    for c in 0..dim {
        let unit = if c < nb { 1.0 } else { f_ref };
        for row in 0..dim {
            a[c * dim + row] = entry(c, row) * unit;
        }
        if c >= nb {
            let h = c - nb;
            a[c * dim + c] += held[h].compliance * f_ref * row_scale[h];
        }
    }
    let mut lu = DenseLu::default();
    if dim > 0 && !lu.factor(dim, &a) {
        return Err(Error::NotConverged {
            what: "linearised equilibrium: singular problem".into(),
            iterations: 0,
            residual: f64::INFINITY,
            load_factor: 1.0,
        });
    }
    let nrhs = seeds.len() + displaced.len();
    let mut out = Linear {
        pose: Vec::with_capacity(nrhs),
        base: Vec::with_capacity(nrhs),
        tensions: Vec::with_capacity(nrhs),
        lengths: Vec::with_capacity(nrhs),
        rotations: cols.rotations.clone(),
    };
    let nl = len_tendons.len();
    for q in 0..nrhs {
        // Right-hand side: -(column's rows), or the unit displacement of a held tendon.
        let column = (q < seeds.len()).then_some(dim + q);
        let mut z = vec![0.0; dim];
        match column {
            Some(c) => {
                for row in 0..dim {
                    z[row] = -entry(c, row);
                }
            }
            None => {
                let h = displaced[q - seeds.len()];
                z[nb + h] = row_scale[h];
            }
        }
        if dim > 0 && !lu.solve_in_place(&mut z) {
            return Err(Error::NotConverged {
                what: "linearised equilibrium: singular problem".into(),
                iterations: 0,
                residual: f64::INFINITY,
                load_factor: 1.0,
            });
        }
        let combine = |get: &dyn Fn(usize) -> Vector6<f64>| -> Vector6<f64> {
            let mut t = column.map_or(Vector6::zeros(), get);
            for (k, zk) in z.iter().enumerate() {
                let unit = if k < nb { 1.0 } else { f_ref };
                t += get(k) * (zk * unit);
            }
            t
        };
        out.pose.push(
            (0..observe.len())
                .map(|o| combine(&|c| cols.poses[o][c]))
                .collect(),
        );
        let mut base = [0.0; 6];
        base[..nb.min(6)].copy_from_slice(&z[..nb]);
        out.base.push(base);
        out.tensions
            .push(z[nb..].iter().map(|v| v * f_ref).collect());
        out.lengths.push(
            (0..nl)
                .map(|h| {
                    let mut d = column.map_or(0.0, |c| cols.d_lengths[c][h]);
                    for (k, zk) in z.iter().enumerate() {
                        let unit = if k < nb { 1.0 } else { f_ref };
                        d += cols.d_lengths[k][h] * zk * unit;
                    }
                    d
                })
                .collect(),
        );
    }
    // Lengths ordered as `len_tendons`: reorder to `lengths`.
    for l in &mut out.lengths {
        let reordered = lengths
            .iter()
            .map(|i| {
                let h = len_tendons.iter().position(|j| j == i).unwrap_or(0);
                l[h]
            })
            .collect();
        *l = reordered;
    }
    Ok(out)
}

/// The length scale (m) of the slack of tendon `i` per force scale: `(|r_i(0)|² + I/A) / L`
/// plus the tendon's own stretch `F / k` (the path shortening a tension of `E I / L²` causes).
pub(crate) fn slack_scale(model: &RobotModel, i: usize, compliance: f64) -> f64 {
    let rod = model.rod();
    let props = rod.section_at(0.0);
    let (r, _) = model.tendons()[i].routing().offset(0.0, &props);
    let l = model.length();
    let gyration = props.ix.max(props.iy) / props.area;
    let scale = (r[0] * r[0] + r[1] * r[1] + gyration) / l + model.force_scale() * compliance;
    if scale.is_finite() && scale > 0.0 {
        scale
    } else {
        l
    }
}

fn check_parameter(model: &RobotModel, solution: &StaticsSolution, p: &Parameter) -> Result<()> {
    let (nt, nc) = (model.tendons().len(), model.chambers().len());
    let bad = |what: &str, i: usize, n: usize| {
        Err(Error::invalid(
            format!("parameters: {p:?}"),
            i,
            format!("a {what} index < {n}"),
        ))
    };
    match *p {
        Parameter::Tension(i)
        | Parameter::TendonOffsetScale(i)
        | Parameter::TendonOffsetShift { tendon: i, .. }
            if i >= nt =>
        {
            bad("tendon", i, nt)
        }
        Parameter::Displacement(i) if i >= nt => bad("tendon", i, nt),
        Parameter::Displacement(i) if !solution.actuation.tendons[i].is_held() => {
            Err(Error::invalid(
                format!("parameters: {p:?}"),
                i,
                "a displacement-controlled tendon",
            ))
        }
        Parameter::Pressure(j) | Parameter::ChamberAreaScale(j) if j >= nc => bad("chamber", j, nc),
        Parameter::BaseTranslation(k) | Parameter::BaseRotation(k) if k >= 3 => {
            bad("world axis", k, 3)
        }
        _ => Ok(()),
    }
}

fn seed_of(p: &Parameter) -> Option<Seed> {
    Some(match *p {
        Parameter::Tension(i) => Seed::Forced(Column::Tension(i)),
        Parameter::Displacement(_) => return None,
        Parameter::Pressure(j) => Seed::Forced(Column::Pressure(j)),
        Parameter::TensionScale => Seed::Forced(Column::TensionScale),
        Parameter::StiffnessScale => Seed::Forced(Column::StiffnessScale),
        Parameter::TendonOffsetScale(i) => Seed::Forced(Column::TendonOffsetScale(i)),
        Parameter::TendonOffsetShift { tendon, direction } => {
            Seed::Forced(Column::TendonOffsetShift(tendon, direction))
        }
        Parameter::ChamberAreaScale(j) => Seed::Forced(Column::ChamberAreaScale(j)),
        Parameter::BaseTranslation(k) => Seed::BaseTranslation(k),
        Parameter::BaseRotation(k) => Seed::BaseRotation(k),
    })
}

fn check_nodes(solution: &StaticsSolution, nodes: &[usize]) -> Result<Vec<usize>> {
    let n = solution.s.len();
    for (k, &i) in nodes.iter().enumerate() {
        if i >= n {
            return Err(Error::invalid(
                format!("nodes[{k}]"),
                i,
                format!("a node index in [0, {n})"),
            ));
        }
    }
    let mut sorted = nodes.to_vec();
    sorted.sort_unstable();
    sorted.dedup();
    Ok(sorted)
}

/// Where the derivative with respect to a parameter comes from.
#[derive(Clone, Copy)]
enum Rhs {
    /// Right-hand side `q` of the linearised solve.
    Solve(usize),
    /// No effect (the displacement of a slack tendon).
    Zero,
}

/// The right-hand sides of `parameters`: the seeds, the held rows displaced, and per
/// parameter its right-hand side (seeds first, then the displacements).
fn right_hand_sides(
    parameters: &[Parameter],
    held: &[HeldRow],
) -> (Vec<Seed>, Vec<usize>, Vec<Rhs>) {
    let mut seeds = Vec::new();
    let mut displaced = Vec::new();
    let mut order = Vec::new();
    for p in parameters {
        match (seed_of(p), p) {
            (Some(s), _) => {
                order.push(Rhs::Solve(seeds.len()));
                seeds.push(s);
            }
            (None, Parameter::Displacement(i)) => {
                match held.iter().position(|h| h.tendon == *i) {
                    Some(h) => {
                        order.push(Rhs::Solve(usize::MAX)); // fixed below
                        displaced.push(h);
                    }
                    None => order.push(Rhs::Zero),
                }
            }
            (None, _) => order.push(Rhs::Zero),
        }
    }
    let mut k = 0;
    for o in &mut order {
        if let Rhs::Solve(q) = o {
            if *q == usize::MAX {
                *q = seeds.len() + k;
                k += 1;
            }
        }
    }
    (seeds, displaced, order)
}

fn held_for(solution: &StaticsSolution, lin: Linearisation) -> Vec<HeldRow> {
    match lin {
        Linearisation::Actuated => held_rows(solution),
        Linearisation::Tension => Vec::new(),
    }
}

/// The exact derivatives of the equilibrium `solution` with respect to `parameters`: the
/// poses at the nodes `nodes` (indices into the solution's samples), the base wrench, the
/// held tensions and the tendon path lengths, with the tendons responding as `lin` says. See
/// the module documentation for the linearised problem and the parameters.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `nodes[k]` or the parameter (an index out of range, a
/// displacement of a tendon that is not displacement-controlled); [`Error::NotConverged`] if
/// the integration fails or the linearised problem is singular.
pub fn sensitivities(
    solution: &StaticsSolution,
    parameters: &[Parameter],
    nodes: &[usize],
    lin: Linearisation,
) -> Result<Sensitivities> {
    let model = &*solution.model;
    for p in parameters {
        check_parameter(model, solution, p)?;
    }
    let observe = check_nodes(solution, nodes)?;
    let (seeds, displaced, order) = right_hand_sides(parameters, &held_for(solution, lin));
    let nt = model.tendons().len();
    let all_tendons: Vec<usize> = (0..nt).collect();
    let held = held_for(solution, lin);
    let linear = linearise(
        solution,
        &held,
        &seeds,
        &displaced,
        &observe,
        &all_tendons,
        None,
    )?;
    let np = parameters.len();
    let f_ref = model.force_scale();
    let fm = f_ref * model.length();
    let mut pose = vec![DMatrix::zeros(6, np); observe.len()];
    let mut base_wrench = DMatrix::zeros(6, np);
    let mut tendon_tensions = DMatrix::zeros(nt, np);
    let mut tendon_lengths = DMatrix::zeros(nt, np);
    for (j, o) in order.iter().enumerate() {
        let Rhs::Solve(q) = *o else { continue };
        for (k, pk) in pose.iter_mut().enumerate() {
            pk.set_column(j, &linear.pose[q][k]);
        }
        for r in 0..6 {
            base_wrench[(r, j)] = linear.base[q][r] * if r < 3 { f_ref } else { fm };
        }
        for (h, row) in held.iter().enumerate() {
            tendon_tensions[(row.tendon, j)] = linear.tensions[q][h];
        }
        if let Parameter::Tension(i) = parameters[j] {
            if !held.iter().any(|h| h.tendon == i) {
                tendon_tensions[(i, j)] = 1.0;
            }
        }
        for i in 0..nt {
            tendon_lengths[(i, j)] = linear.lengths[q][i];
        }
    }
    Ok(Sensitivities {
        parameters: parameters.to_vec(),
        s: observe.iter().map(|&i| solution.s[i]).collect(),
        nodes: observe,
        pose,
        base_wrench,
        tendon_tensions,
        tendon_lengths,
    })
}

/// The actuation Jacobian of `solution` at node `node` (default: the tip): the derivative of
/// the node's pose twist `[δp; δθ]` (world frame; m and rad) with respect to each tendon
/// tension (per N, every tendon at fixed tension), then each chamber pressure (per Pa);
/// shape 6 × (n_tendons + n_chambers). For a frictional equilibrium, the one-sided
/// derivative for increasing inputs ([`directional_actuation_jacobian`] with
/// [`Direction::Pull`]).
///
/// # Errors
/// As [`sensitivities`] (`node` out of range).
pub fn actuation_jacobian(solution: &StaticsSolution, node: Option<usize>) -> Result<DMatrix<f64>> {
    let node = node_or_tip(solution, node)?;
    let mut jac = actuation_jacobians(solution, &[node], Linearisation::Tension)?;
    Ok(jac.pop().unwrap_or_else(|| DMatrix::zeros(6, 0)))
}

/// The one-sided actuation Jacobian of `solution` at node `node` (default: the tip) in
/// `direction`: for a frictional equilibrium (a [`crate::FrictionalSolution`]'s `statics`)
/// the derivative for increasing inputs ([`Direction::Pull`], continued from the solution:
/// sliding elements slide on when pushed further, the others stick) or for decreasing ones
/// ([`Direction::Release`]), see `cosserat::friction_linear`; for any other solution
/// [`actuation_jacobian`] (the two directions agree). Shape 6 × (n_tendons + n_chambers),
/// per N and per Pa.
///
/// # Errors
/// As [`sensitivities`] (`node` out of range); [`Error::NotConverged`] if the slip branches
/// of the frictional linearisation do not settle.
pub fn directional_actuation_jacobian(
    solution: &StaticsSolution,
    node: Option<usize>,
    direction: Direction,
) -> Result<DMatrix<f64>> {
    let node = node_or_tip(solution, node)?;
    let mut jac = match frictional(solution, &[node], Linearisation::Tension, direction) {
        Some(j) => j?,
        None => actuation_jacobians(solution, &[node], Linearisation::Tension)?,
    };
    Ok(jac.pop().unwrap_or_else(|| DMatrix::zeros(6, 0)))
}

/// The actuation Jacobians of a frictional equilibrium (`None` for any other solution).
fn frictional(
    solution: &StaticsSolution,
    nodes: &[usize],
    lin: Linearisation,
    direction: Direction,
) -> Option<Result<Vec<DMatrix<f64>>>> {
    solution.actuation.profile.as_ref()?;
    let model = &*solution.model;
    model.tendons().iter().position(|t| t.friction() > 0.0)?;
    // A frictional solve at fixed displacement reports the tension-controlled equilibrium
    // it found (its actuation holds the base tensions): the derivative is at fixed base
    // tensions either way.
    let _ = lin;
    Some(
        check_nodes(solution, nodes)
            .and_then(|observe| frictional_actuation_jacobians(solution, &observe, direction)),
    )
}

/// The node index `node` or the tip.
pub(crate) fn node_or_tip(solution: &StaticsSolution, node: Option<usize>) -> Result<usize> {
    let n = solution.s.len();
    match node {
        Some(i) if i < n => Ok(i),
        Some(i) => Err(Error::invalid("node", i, format!("in [0, {n})"))),
        None => Ok(n.saturating_sub(1)),
    }
}

/// The actuation parameters of a solution: per tendon its tension (or, under
/// [`Linearisation::Actuated`], its displacement if it is displacement-controlled), then per
/// chamber its pressure.
pub fn actuation_parameters(solution: &StaticsSolution, lin: Linearisation) -> Vec<Parameter> {
    let model = &*solution.model;
    let (nt, nc) = (model.tendons().len(), model.chambers().len());
    (0..nt)
        .map(|i| match (lin, solution.actuation.tendons.get(i)) {
            (Linearisation::Actuated, Some(t)) if t.is_held() => Parameter::Displacement(i),
            _ => Parameter::Tension(i),
        })
        .chain((0..nc).map(Parameter::Pressure))
        .collect()
}

/// [`actuation_jacobian`] at several nodes in one march (one matrix per distinct node, in
/// increasing order), with the tendons as `lin` says: [`Linearisation::Tension`]
/// differentiates with respect to every tension; [`Linearisation::Actuated`] with respect to
/// each tendon's input (its tension, or its displacement, per m, if it is
/// displacement-controlled).
///
/// # Errors
/// As [`sensitivities`].
pub fn actuation_jacobians(
    solution: &StaticsSolution,
    nodes: &[usize],
    lin: Linearisation,
) -> Result<Vec<DMatrix<f64>>> {
    // A frictional equilibrium: the one-sided derivative for increasing inputs.
    if let Some(j) = frictional(solution, nodes, lin, Direction::Pull) {
        return j;
    }
    let params = actuation_parameters(solution, lin);
    let observe = check_nodes(solution, nodes)?;
    let held = held_for(solution, lin);
    let (seeds, displaced, order) = right_hand_sides(&params, &held);
    let linear = linearise(solution, &held, &seeds, &displaced, &observe, &[], None)?;
    let mut out = vec![DMatrix::zeros(6, params.len()); observe.len()];
    for (j, o) in order.iter().enumerate() {
        let Rhs::Solve(q) = *o else { continue };
        for (k, m) in out.iter_mut().enumerate() {
            m.set_column(j, &linear.pose[q][k]);
        }
    }
    Ok(out)
}
