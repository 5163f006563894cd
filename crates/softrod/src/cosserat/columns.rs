//! The variational columns of an equilibrium integrated with its state: the seeds of the
//! columns (base wrench, dead loads, forced parameter columns, base pose), one march per
//! [`COLUMNS_PER_PASS`] columns with the observed node poses and path-length sensitivities,
//! and the body-wrench forcing of each parameter column (see [`super::sensitivity`]).

use nalgebra::{Matrix3, Vector3, Vector6};

use super::equations::{
    col_rot, rot, rotation_variation, v3, Column, Equations, Evaluator, Workspace, COLUMN, DM, DN,
    DR, STATE,
};
use super::sensitivity::COLUMNS_PER_PASS;
use super::shooting::Node;
use super::statics::Integrator;
use crate::error::{Error, Result};
use crate::integrate::march::{march, rk4_plan, Scheme};
use crate::math::so3::hat;
use crate::model::section::SectionProperties;
use crate::model::RobotModel;

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

/// One march of the state with the columns `seeds` (the nodes recorded if `record`).
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
    let y0: [f64; N] = seeded(eq, x, seeds);
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

/// The initial state of a pass from the scaled base wrench `x`, its columns seeded: a unit
/// scaled base wrench component, a base translation or rotation; zero for a forced column
/// and a load column (seeded at its node).
fn seeded<const N: usize>(eq: Equations<'_>, x: &[f64; 6], seeds: &[Seed]) -> [f64; N] {
    let model = eq.model;
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
    y0
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
