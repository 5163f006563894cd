//! The friction mesh of the adaptive integrator, chosen by the shape's turning.
//!
//! The capstan rule of a cell is exact on an arc whose tangent turns by less than π; where
//! the curvature varies along the cell (a tapered curl) the tension inside the cell errs by
//! the square of the cell's length, and the turning taken between its end tangents (their
//! angle, which cannot exceed π) aliases once the cell turns further. With RK4 the friction
//! mesh is the integrator's nodes, and the mesh control refines both together; with the
//! adaptive integrator the friction mesh starts at
//! [`ADAPTIVE_FRICTION_NODES`](super::friction::ADAPTIVE_FRICTION_NODES) cells per interval
//! and every cell a frictional tendon runs through that turns by more than
//! [`ADAPTIVE_FRICTION_TURN`] on the solved shape is divided, and the robot solved again on
//! the finer mesh, until none does. A previous state's history, its tension profile read
//! between its nodes as the solve reads it, is carried onto another mesh ([`history_on`]):
//! exactly onto a finer adaptive one, which keeps every node of the coarser.

use nalgebra::{Matrix3, Vector3};

use super::friction::{node_tangents, FrictionalSolution};
use super::statics::StaticsSolution;
use crate::model::actuation::TensionProfile;
use crate::model::RobotModel;

/// Largest turn (rad) of the backbone's frame, plus that of a frictional tendon's path in
/// it, over one cell of the adaptive integrator's friction mesh. On a tapered Neo-Hookean
/// arm with one frictional tendon (μ = 0.05) curled 0.4 to 3.7 turns, 32 cells per interval
/// turning up to 9.3 rad put the tip 1.5e-3 L from RK4 on 10,240 steps; cells of at most this
/// turn 3.8e-6 to 4.2e-6 L, the second-order error of the straighter part
/// (`docs/friction.md`).
pub const ADAPTIVE_FRICTION_TURN: f64 = 0.25;

/// Refinements of the adaptive friction mesh tried before a solve is refused.
pub const MAX_FRICTION_MESH_ROUNDS: usize = 6;

/// The turn (rad) of each cell of the mesh of `sol` (its nodes) that a frictional tendon of
/// `model` runs through: the cell's length times the larger curvature `|u|` at its ends, plus
/// the largest angle between a frictional tendon's path directions in the body frame at its
/// ends; 0 for a cell without a frictional tendon.
pub fn cell_turns(model: &RobotModel, sol: &StaticsSolution) -> Vec<f64> {
    let frictional: Vec<usize> = (0..model.tendons().len())
        .filter(|&i| model.tendons()[i].friction() > 0.0)
        .collect();
    let body_dirs: Vec<Vec<Option<Vector3<f64>>>> = (0..sol.s.len())
        .map(|j| {
            let r = Matrix3::from_fn(|a, b| sol.rotation[j][a][b]);
            let (v, u) = (Vector3::from(sol.v[j]), Vector3::from(sol.u[j]));
            let world = node_tangents(model, sol.s[j], &r, &v, &u);
            frictional
                .iter()
                .map(|&i| world[i].map(|t| r.tr_mul(&t)))
                .collect()
        })
        .collect();
    (0..sol.s.len().saturating_sub(1))
        .map(|j| {
            let path = (0..frictional.len())
                .filter_map(|k| match (body_dirs[j][k], body_dirs[j + 1][k]) {
                    (Some(a), Some(b)) => Some(super::friction::angle(&a, &b)),
                    _ => None,
                })
                .reduce(f64::max);
            path.map_or(0.0, |p| {
                let rate = Vector3::from(sol.u[j])
                    .norm()
                    .max(Vector3::from(sol.u[j + 1]).norm());
                (sol.s[j + 1] - sol.s[j]) * rate + p
            })
        })
        .collect()
}

/// The mesh `mesh` (m, the nodes of `sol`) with every cell that turns by more than
/// [`ADAPTIVE_FRICTION_TURN`] on `sol` divided into equal cells that turn by at most that
/// ([`cell_turns`]); `None` if no cell does. The largest turn is returned with it.
pub fn finer_mesh(
    model: &RobotModel,
    sol: &StaticsSolution,
    mesh: &[f64],
) -> (Option<Vec<f64>>, f64) {
    let turns = cell_turns(model, sol);
    let largest = turns.iter().copied().fold(0.0, f64::max);
    if largest <= ADAPTIVE_FRICTION_TURN {
        return (None, largest);
    }
    let mut finer = Vec::with_capacity(mesh.len());
    for (j, w) in mesh.windows(2).enumerate() {
        // (A non-finite turn leaves the cell as it is: the solve has reported it.)
        let parts = if turns[j].is_finite() {
            (turns[j] / ADAPTIVE_FRICTION_TURN).ceil().max(1.0) as usize
        } else {
            1
        };
        for k in 0..parts {
            finer.push(w[0] + (w[1] - w[0]) * k as f64 / parts as f64);
        }
    }
    finer.push(mesh[mesh.len() - 1]);
    (Some(finer), largest)
}

/// Whether `mesh` (m) can carry a frictional state of `model`: increasing from 0 to its
/// length through every break.
pub fn is_friction_mesh(model: &RobotModel, mesh: &[f64]) -> bool {
    let l = model.length();
    mesh.first() == Some(&0.0)
        && mesh.last() == Some(&l)
        && mesh.windows(2).all(|w| w[0] < w[1])
        && model
            .breaks()
            .iter()
            .all(|b| mesh.binary_search_by(|m| m.total_cmp(b)).is_ok())
}

/// The tension profile of `previous` (on its own mesh) at the nodes of `mesh`: read between
/// its nodes as the solve reads a profile ([`TensionProfile::at`]: geometrically, linearly
/// next to a zero tension where a tendon ends); the same profile where `mesh` holds all of
/// its nodes.
pub fn history_on(previous: &FrictionalSolution, mesh: &[f64]) -> Vec<Vec<f64>> {
    let s = &previous.statics.s;
    let nt = previous.tension.first().map_or(0, Vec::len);
    let profile = TensionProfile::new(
        (0..nt)
            .map(|i| Some((s.clone(), previous.tension.iter().map(|r| r[i]).collect())))
            .collect(),
    );
    mesh.iter()
        .map(|&x| (0..nt).map(|i| profile.at(i, x).unwrap_or(0.0)).collect())
        .collect()
}
