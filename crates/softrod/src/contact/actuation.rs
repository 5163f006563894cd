//! The actuation Jacobian of a contact equilibrium with the active contacts and the tip
//! constraint as constraints.
//!
//! At a converged solution `x` of the constrained shooting problem `r(x, a) = 0` (base wrench,
//! and per contact its arc length and force; `a` the tensions then pressures), the active set
//! and the contact states held, the unknowns move with the actuation as `J δx = -∂r/∂a δa`:
//! a frictionless or sliding contact keeps its gap (and, inside the rod, the gap's slope) at
//! zero, a sticking one its point, a held tip its held directions. The twist of a node is then
//! `δq = T_x δx + T_a δa` with `T_x`, `T_a` its columns along the unknowns and the actuators
//! at fixed unknowns. `J`, `∂r/∂a`, `T_x` and `T_a` come from one march with the variational
//! columns of every unknown and one forced column per actuator
//! ([`Constrained::exact_actuated`]); the only differences are those of the algebraic contact
//! rows in the states at the contacts' nodes (no march is differenced).

use nalgebra::{DMatrix, Vector6};

use super::problem::Constrained;
use crate::math::linalg::DenseLu;
use crate::solve::Problem;

impl Constrained<'_> {
    /// `d[δp; δθ]/da` of the node of index `node` (m, rad; world) per tension (N) then
    /// pressure (Pa), 6 × (n_tendons + n_chambers), at the converged `x` with the active set
    /// held; with the node's position (m, world) in the march, to check it is the solution's.
    /// `None` if the march fails, the node is not on it, or the constrained problem is
    /// singular.
    pub(super) fn actuation_jacobian(
        &mut self,
        x: &[f64],
        node: usize,
    ) -> Option<(DMatrix<f64>, nalgebra::Vector3<f64>)> {
        let n = self.dim();
        let mut j = vec![0.0; n * n];
        let (_, act) = self.exact_actuated(x, &mut j, node)?;
        let mut lu = DenseLu::default();
        if !lu.factor(n, &j) {
            return None;
        }
        let mut out = DMatrix::zeros(6, act.rows.len());
        for (k, rows) in act.rows.iter().enumerate() {
            let mut dx: Vec<f64> = rows.iter().map(|v| -v).collect();
            if !lu.solve_in_place(&mut dx) {
                return None;
            }
            let moved: Vector6<f64> = act.node.iter().zip(&dx).map(|(t, v)| t * *v).sum();
            out.set_column(k, &(act.twist[k] + moved));
        }
        out.iter()
            .all(|v| v.is_finite())
            .then_some((out, act.position))
    }
}
