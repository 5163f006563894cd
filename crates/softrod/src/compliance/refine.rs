//! The compliance of an RK4 solution under error control: an a-posteriori estimate of the
//! mesh's truncation error, and a finer mesh (nested in the solution's) only where it exceeds
//! the target.
//!
//! Both the integrated compliance (a quadrature of `Ad c Adᵀ` over the solved poses) and the
//! tangent compliance (the derivative of the discrete march) inherit the truncation error of
//! the RK4 mesh in the rotations: on a stress-free arc of `2π` with the default 40 steps it is
//! `3e-5` relative. Classical RK4 applied to `R' = R û` replaces `exp(h û)` by its Taylor
//! polynomial of degree four, so a step that turns by `θ = h |u|` errs by `θ⁵ / 120` rad;
//! [`rk4_rotation_error`] sums this over the solved mesh (with the larger curvature of the two
//! ends of each step). When it exceeds [`MESH_ROTATION_TARGET`], the problem is re-solved on a
//! mesh `m` times finer (`m` the smallest integer with `error / m⁴` below the target whose
//! plan nests the solution's nodes), warm-started from the solution (one or two Newton
//! iterations), and the compliance is evaluated there at the solution's own nodes. The
//! refinement costs a solve on the finer mesh, only for strongly curved rods, and applies to
//! solutions at the default mesh ([`DEFAULT_RK4_STEPS`]): a mesh chosen with other `steps` is
//! kept (the integrated compliance is the quadrature on it, the tangent compliance the exact
//! derivative of its discrete march, as a finite difference of solves on it gives).

use crate::cosserat::mesh::{rk4_rotation_error, MAX_REFINEMENT};
use crate::cosserat::statics::{
    solve_statics_at, Integrator, StaticsSolution, DEFAULT_RK4_STEPS, MAX_RK4_STEPS,
};
use crate::integrate::march::rk4_plan;

/// Target of [`rk4_rotation_error`] (rad) above which the compliance of an RK4 solution is
/// evaluated on a finer mesh: the compliance then errs by about this much relative (measured
/// against Castigliano on stress-free arcs up to `2π`, docs/compliance.md).
pub const MESH_ROTATION_TARGET: f64 = 1e-7;

/// Largest shape change between a solution and its re-solve on the finer mesh, relative to the
/// rod's length (more means another equilibrium: the refinement is not used).
const SAME_BRANCH: f64 = 1e-3;
/// The solution re-solved on a finer RK4 mesh that contains its nodes, with, for each node of
/// `solution`, its index in the finer one; `None` where no refinement is needed (an adaptive
/// solution, an estimate below [`MESH_ROTATION_TARGET`]), wanted (RK4 steps other than
/// [`DEFAULT_RK4_STEPS`]) or possible (a solution at `s_out`,
/// one that did not converge, no nested plan within [`MAX_REFINEMENT`], a re-solve that fails
/// or lands elsewhere).
pub(crate) fn refined(solution: &StaticsSolution) -> Option<(StaticsSolution, Vec<usize>)> {
    let Integrator::Rk4 { steps } = solution.options.integrator else {
        return None;
    };
    if steps != DEFAULT_RK4_STEPS || !solution.s_out.is_empty() || !solution.stats.converged {
        return None;
    }
    let error = rk4_rotation_error(solution);
    if error.is_nan() || error <= MESH_ROTATION_TARGET {
        return None;
    }
    let model = &solution.model;
    let breaks = model.breaks();
    let coarse = rk4_plan(breaks, steps);
    let first = (error / MESH_ROTATION_TARGET).powf(0.25).ceil() as usize;
    let m = (first.max(2)..=MAX_REFINEMENT).find(|&m| {
        m * steps <= MAX_RK4_STEPS
            && rk4_plan(breaks, m * steps)
                .iter()
                .zip(&coarse)
                .all(|(&f, &c)| f == m * c)
    })?;
    let mut options = solution.options;
    options.integrator = Integrator::Rk4 { steps: m * steps };
    options.warm_start = Some(solution.warm_start());
    options.seek_stable = false;
    options.newton.throw = true;
    let fine = solve_statics_at(model, &solution.actuation, &options, &[]).ok()?;
    if !fine.stats.converged {
        return None;
    }
    // The nodes of the coarse mesh, in order, among the fine ones (equal up to round-off).
    let length = model.length();
    let mut map = Vec::with_capacity(solution.s.len());
    let mut j = 0;
    for (i, &s) in solution.s.iter().enumerate() {
        while j < fine.s.len() && (fine.s[j] - s).abs() > 1e-12 * length {
            j += 1;
        }
        if j == fine.s.len() {
            return None;
        }
        let (a, b) = (solution.position[i], fine.position[j]);
        let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
        if d.is_nan() || d > SAME_BRANCH * length {
            return None;
        }
        map.push(j);
        j += 1;
    }
    Some((fine, map))
}
