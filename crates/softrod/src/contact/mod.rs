//! Contact with the environment and end constraints, through the shooting problem.
//!
//! [`solve_constrained`] solves the statics of a robot whose tip is held by a
//! [`TipConstraint`] (clamped at a pose, pinned at a point, sliding on a plane, or any held
//! directions of a frame) and whose surface touches rigid [`Obstacle`]s (planes, spheres,
//! capsules, cylinders, triangle meshes), with Coulomb friction at point contacts
//! ([`ContactState`]). The constraints are exact: the held tip directions
//! and the contact gaps are residual rows of the shooting problem, their reactions unknowns,
//! solved by the crate's Newton and continuation (see `docs/contact.md`). The solution
//! ([`ContactSolution`]) carries the reactions: the tip reaction wrench and, per contact, its
//! arc length, point, normal and force.

mod active_set;
mod actuation;
mod belt;
mod constraint;
mod finish;
mod friction;
mod inverse;
mod jacobian;
mod mesh;
mod newton;
mod obstacle;
mod problem;
mod ramp;
mod rows;
mod solve;
mod stability;
mod sweep;

use std::sync::Arc;

use nalgebra::Vector3;

pub use active_set::MAX_ACTIVE_SET_ROUNDS;
pub use constraint::TipConstraint;
pub use inverse::{
    contact_inverse_resolved, contact_inverse_statics, solve_contact_inverse, ContactForward,
};
pub use obstacle::{Obstacle, TriangleMesh};
pub use solve::solve_constrained;

use crate::cosserat::StaticsSolution;

/// Two unit vectors completing the unit `n` to a right-handed orthonormal basis `(t1, t2, n)`.
pub(crate) fn obstacle_normal_basis(n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let a = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let t1 = (a - n * n.dot(&a)).normalize();
    (t1, n.cross(&t1))
}

/// How a contact's tangential force is determined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ContactState {
    /// Frictionless obstacle: no tangential force.
    Frictionless,
    /// Coulomb friction, sticking: the contact point has not moved along the surface from
    /// where it first touched (under the proportional load path of the solve), and the
    /// tangential force is inside the cone, `|f_t| <= μ f_n`.
    Stick,
    /// Coulomb friction, sliding: the tangential force is on the cone, `|f_t| = μ f_n`,
    /// opposite to the slip (the displacement of the contact point along the surface from
    /// where it first touched).
    Slide,
}

/// One active contact of a solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// Index of the obstacle in the list solved with.
    pub obstacle: usize,
    /// Arc length of the contact (m): of the point, or where a contact interval starts.
    pub s: f64,
    /// Length of a contact interval (m; 0 for a point contact): the segment `[s, s + length]`
    /// lies on a plane under a distributed reaction, whose resultant is `normal_force` and
    /// whose `point` is the tip end of the segment.
    pub length: f64,
    /// Contact point on the rod's surface (m, world).
    pub point: [f64; 3],
    /// Outward unit normal of the obstacle at the contact (world): the direction of the
    /// force on the rod.
    pub normal: [f64; 3],
    /// Normal force on the rod (N, >= 0).
    pub normal_force: f64,
    /// Tangential (friction) force on the rod (N, world; normal to `normal`); zero without
    /// friction.
    pub tangential_force: [f64; 3],
    /// Frictionless, sticking or sliding.
    pub state: ContactState,
}

/// A solution of [`solve_constrained`].
#[derive(Debug, Clone)]
pub struct ContactSolution {
    /// The shape, internal wrenches and statistics. Its model is the robot with the contact
    /// forces added as world-frame point loads (so its tangent compliance is that of the
    /// contacts as dead loads). `stable` and `stability_margin` account for the tip
    /// constraint: with a held tip, `stable` is the absence of conjugate points on the rod
    /// and of negative stiffness in the free tip directions, and the margin is the smallest
    /// eigenvalue of the free directions' dimensionless stiffness (`+inf` for a clamp without
    /// conjugate points; minus the number of conjugate points when there are some).
    pub solution: StaticsSolution,
    /// Reaction wrench of the tip constraint on the rod, `[f; m]` (N, N m; world), if held.
    pub tip_reaction: Option<[f64; 6]>,
    /// The active contacts.
    pub contacts: Vec<Contact>,
    /// Contact force on the rod at every sample of `solution` (N, world), shape (N, 3): each
    /// contact's force at the sample of its arc length (after the jump at a break).
    pub contact_force: Vec<[f64; 3]>,
    /// Conjugate points of the doubly clamped rod on `(0, L)` (with a held tip).
    pub conjugate_points: Option<usize>,
    /// Tangent compliance of the tip with the active contacts and the tip constraint as
    /// constraints (frictionless contacts hold the normal only, the held tip directions
    /// hold): `compliance.get()` is `[δp; δθ]` of the tip (m, rad; world) per `[δF; δM]` of
    /// a dead tip load (N, N m; world), 6×6 (`None` when not converged or singular),
    /// computed on first read. The compliance of `solution` instead treats the contact
    /// forces as dead loads.
    pub compliance: ContactCompliance,
}

/// The tip compliance of a contact solution with its active contacts and tip constraint as
/// constraints ([`ContactSolution::compliance`]), computed on first read (one march with the
/// variational columns of every unknown) and kept; clones share it.
#[derive(Debug, Clone, Default)]
pub struct ContactCompliance {
    inner: Option<Arc<finish::Frozen>>,
}

impl ContactCompliance {
    /// `[δp; δθ]` of the tip (m, rad; world) per `[δF; δM]` of a dead tip load (N, N m;
    /// world), 6×6; `None` when the solve did not converge, the constrained problem is
    /// singular there or a contact is a belt (its Jacobian is differenced: no tip columns).
    pub fn get(&self) -> Option<nalgebra::Matrix6<f64>> {
        self.inner.as_ref().and_then(|f| f.compliance())
    }

    /// The actuation Jacobian of the contact equilibrium with the active contacts and the
    /// tip constraint as constraints (frictionless and sliding contacts hold their gap,
    /// sticking ones their point, the held tip directions hold; the active set and the
    /// contact states fixed): `d[δp; δθ]/da` of node `node` of `solution` (m, rad; world; the
    /// tip for `None`) per tendon tension (N), then chamber pressure (Pa), shape
    /// (6, n_tendons + n_chambers). `solution` is the [`ContactSolution::solution`] this
    /// linearisation belongs to. Exact: from the linearised constrained shooting problem (see
    /// `contact/actuation.rs`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `node` off the mesh, or `solution` when it does not
    /// belong to this linearisation, has a sticking or sliding contact (friction at
    /// contacts: not modelled in this Jacobian) or a belt (a contact interval on a curved
    /// obstacle: not linearised);
    /// [`Error::NotConverged`] when the solve did not converge
    /// or the constrained problem is singular there.
    ///
    /// [`Error::InvalidParameter`]: crate::Error::InvalidParameter
    /// [`Error::NotConverged`]: crate::Error::NotConverged
    pub fn actuation_jacobian(
        &self,
        solution: &StaticsSolution,
        node: Option<usize>,
    ) -> crate::Result<nalgebra::DMatrix<f64>> {
        let n = solution.s.len();
        let node = node.unwrap_or(n.saturating_sub(1));
        if node >= n {
            return Err(crate::Error::invalid("node", node, format!("< {n}")));
        }
        let Some(frozen) = &self.inner else {
            return Err(crate::Error::not_converged(
                "actuation Jacobian under contact: the contact solve did not converge",
                0,
                f64::INFINITY,
            ));
        };
        if frozen.frictional() {
            // The slip of a frictional contact is measured from its first touch on the
            // proportional load path, which moves with the actuation: not the increment
            // from this equilibrium that holding the contact state would give.
            return Err(crate::Error::invalid(
                "solution",
                "a solution with a sticking or sliding contact",
                "a solution whose active contacts are frictionless (the actuation Jacobian \
                 with friction at contacts is not modelled)",
            ));
        }
        if !solution.model.holds().is_empty() {
            return Err(belt_refused("the actuation Jacobian"));
        }
        let (j, at) = frozen.actuation_jacobian(node).ok_or_else(|| {
            crate::Error::not_converged(
                "actuation Jacobian under contact: the constrained problem is singular or \
                 its march failed",
                0,
                f64::INFINITY,
            )
        })?;
        let p = Vector3::from(solution.position[node]);
        if (at - p).norm() > 1e-9 * (1.0 + solution.model.length()) {
            return Err(crate::Error::invalid(
                "solution",
                "another solution",
                "the solution of this contact linearisation",
            ));
        }
        Ok(j)
    }

    pub(crate) fn of(frozen: Option<finish::Frozen>) -> Self {
        Self {
            inner: frozen.map(Arc::new),
        }
    }
}

/// The error of a linearisation asked of a solution with a belt (a contact interval on a
/// curved obstacle): its march takes the belt's own mesh and holds the pressure that keeps
/// the gap zero, and neither is linearised; [`crate::Error::InvalidParameter`] naming
/// `solution`.
pub(crate) fn belt_refused(what: &str) -> crate::Error {
    crate::Error::invalid(
        "solution",
        "a contact solution with a belt (a contact interval on a curved obstacle)",
        format!(
            "one without a belt: {what} of a rod lying along a sphere, capsule or cylinder is \
             not available"
        ),
    )
}
