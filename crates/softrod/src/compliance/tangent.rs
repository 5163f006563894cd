//! The exact tangent compliance of a loaded, actuated equilibrium, from the linearised
//! boundary-value problem (after Oliver-Butler, Till & Rucker 2019).
//!
//! The linearised boundary-value problem of `cosserat/sensitivity.rs` (the machinery of the
//! actuation Jacobians and parameter sensitivities): the six base-wrench columns, one column
//! per tendon held at fixed length (its tension), and six columns for a dead wrench applied at
//! the node (seeded there), with the path-length sensitivities
//! `δℓ_i = ∫ t_iᵀ (δv + δu × r_i) ds` of the held tendons integrated on the stages. The
//! unknowns (base wrench, held tensions) solve the linearised tip conditions and
//! `δℓ_i = -δτ_i / k_i` (`0` for an inextensible tendon). Columns are integrated
//! [`COLUMNS_PER_PASS`] at a time, so any number of tendons can be held.
//!
//! # References
//! K. Oliver-Butler, J. Till, C. Rucker, "Continuum robot stiffness under external loads and
//! prescribed tendon displacements", IEEE Trans. Robotics 35(2), 2019.

use nalgebra::{Matrix3, Matrix6};

use crate::cosserat::friction_linear::{frictional_tip_compliance, Direction};
use crate::cosserat::sensitivity::node_or_tip;
pub use crate::cosserat::sensitivity::COLUMNS_PER_PASS;
use crate::cosserat::sensitivity::{held_rows, linearise, HeldRow, Seed};
use crate::cosserat::statics::StaticsSolution;
use crate::error::{Error, Result};
use crate::math::linalg::invert_general;
use crate::math::se3::rotation_adjoint;
use crate::model::TendonInput;

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
    /// As the solution is actuated: tension-controlled tendons at fixed tension,
    /// displacement-controlled tendons held taut at fixed displacement (with their axial
    /// stiffness), slack ones free (the same as [`TendonControl::Tension`] for a solution
    /// without displacement control).
    Actuated,
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

/// The exact tangent compliance of the equilibrium `solution` at node `node` (default: the
/// tip): the derivative of the node's twist `[δp; δθ]` with respect to a dead wrench `[f; m]`
/// applied at the node's position, with the tendons held at fixed tension or at fixed length;
/// integrated with the solution's integrator and mesh.
///
/// # Errors
/// [`Error::InvalidParameter`] for a node out of range, or naming `solution` for a contact
/// solution with a belt (a contact interval on a curved obstacle: not linearised);
/// [`Error::NotConverged`] if the integration fails or the linear system is singular.
pub fn tangent_compliance(
    solution: &StaticsSolution,
    control: TendonControl,
    node: Option<usize>,
) -> Result<TangentCompliance> {
    let rows = match control {
        TendonControl::Tension => Vec::new(),
        TendonControl::Length => (0..solution.model.tendons().len())
            .map(|i| held_row(solution, i))
            .collect(),
        TendonControl::Actuated => held_rows(solution),
    };
    tangent_with_rows(solution, &rows, node)
}

/// Tendon `i` held at fixed length, with its stiffness if it is displacement-controlled.
fn held_row(solution: &StaticsSolution, i: usize) -> HeldRow {
    let compliance = match solution.actuation.tendons.get(i) {
        Some(TendonInput::Displacement { stiffness, .. }) => 1.0 / stiffness,
        _ => 0.0,
    };
    HeldRow {
        tendon: i,
        compliance,
    }
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
    let nt = solution.model.tendons().len();
    let node = node_or_tip(solution, node)?;
    for (k, &i) in held.iter().enumerate() {
        if i >= nt || held[..k].contains(&i) {
            return Err(Error::invalid(
                format!("held[{k}]"),
                i,
                format!("distinct tendon indices in [0, {nt})"),
            ));
        }
    }
    let rows: Vec<HeldRow> = held.iter().map(|&i| held_row(solution, i)).collect();
    tangent_with_rows(solution, &rows, Some(node))
}

/// The tangent compliance with the tendons of `rows` held at fixed length (with their
/// compliance), the others at fixed tension.
fn tangent_with_rows(
    solution: &StaticsSolution,
    rows: &[HeldRow],
    node: Option<usize>,
) -> Result<TangentCompliance> {
    let node = node_or_tip(solution, node)?;
    // A strongly curved RK4 solution: the derivative of a finer march (super::refine).
    if let Some((fine, map)) = super::refine::refined(solution) {
        let mut out = tangent_on_mesh(&fine, rows, Some(map[node]))?;
        out.node = node;
        return Ok(out);
    }
    tangent_on_mesh(solution, rows, Some(node))
}

/// [`tangent_with_rows`] on the solution's own mesh.
fn tangent_on_mesh(
    solution: &StaticsSolution,
    rows: &[HeldRow],
    node: Option<usize>,
) -> Result<TangentCompliance> {
    let nt = solution.model.tendons().len();
    let node = node_or_tip(solution, node)?;
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
    let seeds: Vec<Seed> = (0..6).map(Seed::Load).collect();
    let linear = linearise(solution, rows, &seeds, &[], &[node], &[], Some(node))?;
    let held = rows;
    let mut world = Matrix6::zeros();
    for (i, pose) in linear.pose.iter().enumerate() {
        world.set_column(i, &pose[0]);
        for (h, row) in held.iter().enumerate() {
            tension_rate[row.tendon][i] = linear.tensions[i][h];
        }
    }
    Ok(TangentCompliance::from_world(
        (node, target),
        world,
        &linear.rotations[0],
        tension_rate,
    ))
}

impl TangentCompliance {
    /// The compliance at `node` (arc length `s`, m) from its world-frame matrix: the body
    /// frame through the node's rotation `r` (body -> world), the stiffnesses, the condition
    /// number and the symmetry test (asymmetry ≤ 1e-6 of the largest entry).
    fn from_world(
        (node, s): (usize, f64),
        world: Matrix6<f64>,
        r: &Matrix3<f64>,
        tension_rate: Vec<[f64; 6]>,
    ) -> Self {
        let rt = rotation_adjoint(&r.transpose());
        let body = rt * world * rt.transpose();
        let asym = (world - world.transpose()).amax();
        let symmetric = asym <= 1e-6 * world.amax();
        let (stiffness_world, condition) = invert_general(&world);
        let (stiffness_body, _) = invert_general(&body);
        Self {
            node,
            s,
            world,
            body,
            stiffness_world,
            stiffness_body,
            condition,
            symmetric,
            tension_rate,
        }
    }
}

/// The one-sided tip compliance of a frictional equilibrium
/// ([`frictional_tip_compliance`](crate::frictional_tip_compliance): the tension profile
/// following the stick/slip rule, tendons at fixed base tension) as a [`TangentCompliance`]
/// at the tip; the tension rates are zero.
///
/// # Errors
/// As [`frictional_tip_compliance`](crate::frictional_tip_compliance).
pub fn frictional_tangent_compliance(
    solution: &StaticsSolution,
    direction: Direction,
) -> Result<TangentCompliance> {
    let world = frictional_tip_compliance(solution, direction)?;
    let node = solution.s.len() - 1;
    let r = Matrix3::from_fn(|i, j| solution.rotation[node][i][j]);
    let nt = solution.model.tendons().len();
    Ok(TangentCompliance::from_world(
        (node, solution.s[node]),
        world,
        &r,
        vec![[0.0; 6]; nt],
    ))
}
