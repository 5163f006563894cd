//! Inverse statics with obstacles: the contact solve as the forward model of the inverse
//! statics ([`crate::inverse`]), so that a target is reached with the arm resting on an
//! obstacle.
//!
//! The program and its iteration are those of the contact-free inverse (minimum weighted
//! norm of the actuation among those reaching the target, inside the bounds; SQP with the
//! curvature of the target manifold). Each evaluation is one contact solve from a straight
//! rod ([`solve_constrained`]: its active set found by the solve) and, when asked, its
//! actuation Jacobian with the active contacts as constraints
//! ([`ContactCompliance::actuation_jacobian`](super::ContactCompliance::actuation_jacobian)).
//! The forward map is smooth while the active set holds and only continuous where a contact
//! is made or released; the SQP steps across such a change with the Jacobian of the side it
//! stands on.

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};

use super::{solve_constrained, ContactSolution, Obstacle};
use crate::cosserat::mesh::rk4_position_error;
use crate::cosserat::statics::SolveOptions;
use crate::error::{Error, Result};
use crate::inverse::{
    resolved, solve_inverse, Evaluation, Forward, InverseOptions, InverseSolution,
    InverseWarmStart, Target,
};
use crate::model::{Actuation, RobotModel};

/// The contact solve of a robot among frictionless obstacles as a [`Forward`] model of the
/// inverse statics, observing the tip.
pub struct ContactForward {
    model: Arc<RobotModel>,
    options: SolveOptions,
    obstacles: Vec<Obstacle>,
    /// The last contact solution.
    pub solution: Option<ContactSolution>,
}

impl ContactForward {
    /// The forward model of `model` among `obstacles`, solved with `options`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `obstacles[i].friction` for an obstacle with
    /// friction (the actuation Jacobian with friction at contacts is not modelled), or the
    /// options'.
    pub fn new(
        model: &Arc<RobotModel>,
        options: &SolveOptions,
        obstacles: &[Obstacle],
    ) -> Result<Self> {
        options.validate()?;
        if let Some((i, o)) = obstacles
            .iter()
            .enumerate()
            .find(|(_, o)| o.friction() > 0.0)
        {
            return Err(Error::invalid(
                format!("obstacles[{i}].friction"),
                o.friction(),
                "0 for the inverse statics (friction at contacts is not modelled there)",
            ));
        }
        Ok(Self {
            model: Arc::clone(model),
            options: *options,
            obstacles: obstacles.to_vec(),
            solution: None,
        })
    }

    fn actuation(&self, a: &[f64]) -> Actuation {
        let nt = self.model.tendons().len();
        Actuation::tensions(&a[..nt]).with_pressures(&a[nt..])
    }

    /// The contact solution at the actuation `a` (tensions N, then pressures Pa).
    ///
    /// # Errors
    /// As [`solve_constrained`]; [`Error::NotConverged`] for an unconverged solve.
    pub fn solve(&self, a: &[f64]) -> Result<ContactSolution> {
        let mut options = self.options;
        options.newton.throw = true;
        let sol = solve_constrained(
            &self.model,
            &self.actuation(a),
            &options,
            None,
            &self.obstacles,
        )?;
        if !sol.solution.stats.converged {
            return Err(Error::NotConverged {
                what: "contact solve of the inverse statics".into(),
                iterations: sol.solution.stats.iterations,
                residual: sol.solution.stats.residual,
                load_factor: sol.solution.stats.load_factor,
            });
        }
        Ok(sol)
    }
}

impl Forward for ContactForward {
    fn dims(&self) -> (usize, usize) {
        (self.model.tendons().len(), self.model.chambers().len())
    }

    fn length(&self) -> f64 {
        self.model.length()
    }

    fn chamber_areas(&self) -> Vec<f64> {
        self.model.chamber_start_areas()
    }

    fn evaluate(&mut self, a: &[f64], jacobian: bool) -> Result<Evaluation> {
        let sol = self.solve(a)?;
        let s = &sol.solution;
        let n = s.s.len();
        let r = s.rotation[n - 1];
        let rotation = Matrix3::from_fn(|i, j| r[i][j]);
        let jac = if jacobian {
            if !s.model.holds().is_empty() {
                // (Not a parameter of the inverse: this forward solution's step is refused.)
                return Err(crate::Error::not_converged(
                    "contact inverse statics: the forward solution lies along a curved \
                     obstacle (a belt), whose actuation Jacobian is not available",
                    0,
                    f64::INFINITY,
                ));
            }
            let j = if sol.contacts.is_empty() {
                crate::cosserat::sensitivity::actuation_jacobian(s, None)?
            } else {
                sol.compliance.actuation_jacobian(s, None)?
            };
            Some(vec![j])
        } else {
            None
        };
        let out = Evaluation {
            positions: vec![Vector3::from(s.position[n - 1])],
            rotation,
            jacobian: jac,
        };
        self.solution = Some(sol);
        Ok(out)
    }
}

/// The inverse statics on the contact forward model `fwd` (see [`solve_inverse`]), restarted
/// where the first iteration does not converge: from the contact-free inverse to the same
/// target (the arm's shape without the obstacles, a start on the other side of a fold of the
/// contact map), then from the last actuation with a fresh trust region and curvature. The
/// first converged answer is returned; else, if the target is reached from the closest
/// answer by the least change of its actuation, that (`reached`, not `converged`), else the
/// closest; the iterations are the total.
///
/// # Errors
/// As [`solve_inverse`] (with `options.throw`: [`Error::TargetUnreachable`] with the
/// remaining distance, or [`Error::NotConverged`] when the target was reached but the
/// minimum-norm actuation not certified).
pub fn solve_contact_inverse(
    fwd: &mut ContactForward,
    target: &Target,
    options: &InverseOptions,
    warm: Option<&InverseWarmStart>,
) -> Result<InverseSolution> {
    let quiet = InverseOptions {
        throw: false,
        ..options.clone()
    };
    let mut best = solve_inverse(fwd, target, &quiet, warm)?;
    let mut iterations = best.iterations;
    let mut starts: Vec<Option<InverseWarmStart>> = Vec::new();
    if !best.converged {
        let mut free = crate::inverse::CosseratForward::new(&fwd.model, &fwd.options, None)?;
        let start = warm.map(|w| InverseWarmStart::actuation(w.actuation.clone()));
        if let Ok(f) = solve_inverse(&mut free, target, &quiet, start.as_ref()) {
            iterations += f.iterations;
            starts.push(Some(InverseWarmStart::actuation(f.actuation)));
        }
        starts.push(None);
    }
    for start in starts {
        if best.converged {
            break;
        }
        let from = start.unwrap_or_else(|| InverseWarmStart::actuation(best.actuation.clone()));
        let Ok(next) = solve_inverse(fwd, target, &quiet, Some(&from)) else {
            continue;
        };
        iterations += next.iterations;
        if next.converged || next.position_error < best.position_error {
            best = next;
        }
    }
    if !best.converged && !best.reached {
        if let Some(r) = restore(fwd, target, &quiet, &best.actuation) {
            iterations += r.iterations;
            if r.position_error < best.position_error {
                best = r;
            }
        }
    }
    best.iterations = iterations;
    if options.throw && !best.converged {
        if best.reached {
            return Err(Error::NotConverged {
                what: "inverse statics with obstacles (SQP)".into(),
                iterations,
                residual: best.position_error,
                load_factor: 1.0,
            });
        }
        return Err(Error::TargetUnreachable {
            distance: best.position_error,
            rotation: best.rotation_error,
            iterations,
        });
    }
    Ok(best)
}

/// The target reached from `a` by the least weighted change of the actuation (the program of
/// `options` with `a` as its reference), when the minimum-norm iterations stop short of it:
/// typically where the least-norm actuations run into a fold of the contact branch (the rod
/// about to slide off a sphere), past which the forward solve lands on another side of the
/// obstacle and no minimum of the norm can be certified. `None` unless the target is
/// reached; the answer is then `reached` but not `converged` (its actuation is not the
/// minimum-norm one).
fn restore(
    fwd: &mut ContactForward,
    target: &Target,
    options: &InverseOptions,
    a: &[f64],
) -> Option<InverseSolution> {
    let nearest = InverseOptions {
        reference: Some(a.to_vec()),
        ..options.clone()
    };
    let from = InverseWarmStart::actuation(a.to_vec());
    let mut out = solve_inverse(fwd, target, &nearest, Some(&from)).ok()?;
    out.converged = false;
    out.reached.then_some(out)
}

/// [`solve_contact_inverse`] on a new [`ContactForward`] of `model` among `obstacles`, under
/// the mesh control of a forward solve at its answer (as
/// [`inverse_actuation`](crate::inverse::inverse_actuation): on the default RK4 mesh, an
/// answer whose contact solution's estimated tip error exceeds
/// [`DEFAULT_MESH_POSITION_LIMIT`](crate::cosserat::mesh::DEFAULT_MESH_POSITION_LIMIT) is sought
/// again on a finer mesh from the answer; on a chosen mesh, one above
/// [`CHOSEN_MESH_POSITION_LIMIT`](crate::cosserat::mesh::CHOSEN_MESH_POSITION_LIMIT) is an error
/// naming `steps`), from each start of `options.starts` (the best answer); returns the result
/// and the forward model on the mesh of the answer (its `solution` the last contact solve).
///
/// # Errors
/// As [`solve_contact_inverse`] and [`ContactForward::new`]; `steps` as above.
pub fn contact_inverse_resolved(
    model: &Arc<RobotModel>,
    obstacles: &[Obstacle],
    target: &Target,
    options: &InverseOptions,
    solve: &SolveOptions,
    warm: Option<&InverseWarmStart>,
) -> Result<(InverseSolution, ContactForward)> {
    resolved(
        target,
        options,
        solve,
        warm,
        |so| ContactForward::new(model, so, obstacles),
        |fwd, io, w| solve_contact_inverse(fwd, target, io, w),
        ContactForward::mesh_error,
    )
}

impl ContactForward {
    /// The estimated tip error of the RK4 mesh at the actuation `a`, relative to the length
    /// ([`rk4_position_error`] of the contact solution there: the last one, else solved and
    /// kept); NaN where it cannot be solved.
    pub fn mesh_error(&mut self, a: &[f64]) -> f64 {
        let at_a = |s: &&ContactSolution| {
            let nt = s.solution.tensions().len();
            s.solution.tensions() == a[..nt] && s.solution.pressures() == a[nt..]
        };
        if let Some(s) = self.solution.as_ref().filter(at_a) {
            return rk4_position_error(&s.solution);
        }
        match self.solve(a) {
            Ok(s) => {
                let e = rk4_position_error(&s.solution);
                self.solution = Some(s);
                e
            }
            Err(_) => f64::NAN,
        }
    }
}

/// The inverse statics of `model` among the frictionless `obstacles` for a tip `target` (the
/// objective, options and result of [`crate::inverse`]) under the mesh control of
/// [`contact_inverse_resolved`], and the contact solution at the actuation found.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `target_s` for a shape target (the contact inverse aims
/// at the tip) or an obstacle with friction; as [`contact_inverse_resolved`]; the contact
/// solve's.
pub fn contact_inverse_statics(
    model: &Arc<RobotModel>,
    obstacles: &[Obstacle],
    target: &Target,
    options: &InverseOptions,
    solve: &SolveOptions,
    warm: Option<&InverseWarmStart>,
) -> Result<(InverseSolution, ContactSolution)> {
    if target.s.is_some() {
        return Err(Error::invalid(
            "target_s",
            "given",
            "None with obstacles (the contact inverse aims at the tip)",
        ));
    }
    let (out, mut fwd) = contact_inverse_resolved(model, obstacles, target, options, solve, warm)?;
    let sol = match fwd.solution.take() {
        Some(s)
            if s.solution.tensions() == out.tensions()
                && s.solution.pressures() == out.pressures() =>
        {
            s
        }
        _ => fwd.solve(&out.actuation)?,
    };
    Ok((out, sol))
}
