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

use nalgebra::{DMatrix, Matrix3, Vector6};

pub(crate) use super::columns::{integrate, scheme_of, Integrated, Request, Seed};
use super::equations::{Column, Equations};
use super::friction_linear::{frictional_actuation_jacobians, Direction};
use super::statics::StaticsSolution;
use crate::error::{Error, Result};
use crate::integrate::march::Scheme;
use crate::math::linalg::DenseLu;
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

/// A displacement-controlled tendon held taut, as a row and an unknown of the linearised
/// problem.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct HeldRow {
    /// The tendon.
    pub tendon: usize,
    /// Its compliance `1/k` (m/N; 0 when inextensible).
    pub compliance: f64,
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
    if !model.holds().is_empty() {
        return Err(crate::contact::belt_refused("the linearisation"));
    }
    let x = super::statics::scaled(model, &solution.base_wrench);
    let lambda = solution.stats.load_factor;
    let pressures = solution.pressures();
    let eq = solution.equations(&pressures, lambda);
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
    let march = Request {
        seeds: &[],
        lengths: &[],
        observe,
        load_node,
        record_nodes: true,
        stops: &stops,
    };
    let (observe, load_node) = march_indices(solution, eq, scheme, &x, &march)?;
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
    let system = System::new(model, held, &cols, nb);
    let mut lu = system.factor(held)?;
    let nrhs = seeds.len() + displaced.len();
    let mut out = Linear {
        pose: Vec::with_capacity(nrhs),
        base: Vec::with_capacity(nrhs),
        tensions: Vec::with_capacity(nrhs),
        lengths: Vec::with_capacity(nrhs),
        rotations: cols.rotations.clone(),
    };
    for q in 0..nrhs {
        // Right-hand side: -(column's rows), or the unit displacement of a held tendon.
        let column = (q < seeds.len()).then_some(system.dim + q);
        let moved = column.is_none().then(|| displaced[q - seeds.len()]);
        let z = system.solve(&mut lu, column, moved)?;
        system.record(&mut out, column, &z, (observe.len(), len_tendons.len()));
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

/// The march's node indices of the solution's nodes `req.observe` and `req.load_node`: the
/// same without `s_out`; a solution reported at `s_out` keeps some nodes of its march, so
/// its indices are mapped to the march's (the last node at each arc length, as the solution
/// reports) by one march of the state recording its nodes (`req`, no columns).
fn march_indices(
    solution: &StaticsSolution,
    eq: Equations<'_>,
    scheme: Scheme<'_>,
    x: &[f64; 6],
    req: &Request<'_>,
) -> Result<(Vec<usize>, Option<usize>)> {
    if solution.s_out.is_empty() {
        return Ok((req.observe.to_vec(), req.load_node));
    }
    let nodes = integrate(
        eq,
        scheme,
        x,
        &Request {
            observe: &[],
            load_node: None,
            ..*req
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
    Ok((
        req.observe
            .iter()
            .map(|&i| map(i))
            .collect::<Result<Vec<_>>>()?,
        req.load_node.map(map).transpose()?,
    ))
}

/// The linear system of the linearised problem: unknowns `z = [δx (nb); δτ_H / f_ref
/// (nh)]`, rows the tip residual (nb) and the held tendons' slack over its scale.
struct System<'c> {
    cols: &'c Integrated,
    nb: usize,
    dim: usize,
    f_ref: f64,
    row_scale: Vec<f64>,
}

/// The error of a singular linearised problem.
fn singular() -> Error {
    Error::NotConverged {
        what: "linearised equilibrium: singular problem".into(),
        iterations: 0,
        residual: f64::INFINITY,
        load_factor: 1.0,
    }
}

impl<'c> System<'c> {
    fn new(model: &RobotModel, held: &[HeldRow], cols: &'c Integrated, nb: usize) -> Self {
        Self {
            cols,
            nb,
            dim: nb + held.len(),
            f_ref: model.force_scale(),
            row_scale: held
                .iter()
                .map(|h| 1.0 / slack_scale(model, h.tendon, h.compliance))
                .collect(),
        }
    }

    /// Row `row` of march column `c`.
    fn entry(&self, c: usize, row: usize) -> f64 {
        if row < self.nb {
            self.cols.d_residual[c][row]
        } else {
            let h = row - self.nb;
            -self.cols.d_lengths[c][h] * self.row_scale[h]
        }
    }

    /// The factored matrix (the held tendons' compliance on the diagonal of their rows).
    fn factor(&self, held: &[HeldRow]) -> Result<DenseLu> {
        let (nb, dim, f_ref) = (self.nb, self.dim, self.f_ref);
        let mut a = vec![0.0; dim * dim];
        for c in 0..dim {
            let unit = if c < nb { 1.0 } else { f_ref };
            for row in 0..dim {
                a[c * dim + row] = self.entry(c, row) * unit;
            }
            if c >= nb {
                let h = c - nb;
                a[c * dim + c] += held[h].compliance * f_ref * self.row_scale[h];
            }
        }
        let mut lu = DenseLu::default();
        if dim > 0 && !lu.factor(dim, &a) {
            return Err(singular());
        }
        Ok(lu)
    }

    /// The unknowns for the right-hand side of march column `column`, or else of the unit
    /// displacement of the held tendon `displaced` (an index into the held rows).
    fn solve(
        &self,
        lu: &mut DenseLu,
        column: Option<usize>,
        displaced: Option<usize>,
    ) -> Result<Vec<f64>> {
        let dim = self.dim;
        let mut z = vec![0.0; dim];
        if let Some(c) = column {
            for row in 0..dim {
                z[row] = -self.entry(c, row);
            }
        } else if let Some(h) = displaced {
            z[self.nb + h] = self.row_scale[h];
        }
        if dim > 0 && !lu.solve_in_place(&mut z) {
            return Err(singular());
        }
        Ok(z)
    }

    /// Appends to `out` the pose derivatives at the `observed` nodes, the base-wrench and
    /// held-tension changes and the changes of the `nl` tendon lengths of the unknowns `z` of
    /// march column `column` (none: a held tendon's displacement).
    fn record(
        &self,
        out: &mut Linear,
        column: Option<usize>,
        z: &[f64],
        (observed, nl): (usize, usize),
    ) {
        let (nb, f_ref, cols) = (self.nb, self.f_ref, self.cols);
        let combine = |get: &dyn Fn(usize) -> Vector6<f64>| -> Vector6<f64> {
            let mut t = column.map_or(Vector6::zeros(), get);
            for (k, zk) in z.iter().enumerate() {
                let unit = if k < nb { 1.0 } else { f_ref };
                t += get(k) * (zk * unit);
            }
            t
        };
        out.pose.push(
            (0..observed)
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
/// As [`sensitivities`] (`node` out of range); [`Error::InvalidParameter`] naming `solution`
/// for a contact solution with a belt (a contact interval on a curved obstacle: not
/// linearised).
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
