//! The PCC model as a [`Forward`] model of the inverse statics: closed-form equilibria without
//! a tip load (Newton with the exact Jacobian otherwise) and the exact actuation Jacobian of
//! `pcc/sensitivity.rs`. Tip targets only.

use nalgebra::{Matrix3, Vector3};

use super::{Evaluation, Forward};
use crate::error::Result;
use crate::pcc::sensitivity::pcc_actuation_jacobian;
use crate::pcc::statics::{
    solve_pcc_statics, PccLoads, PccRobot, PccSolveOptions, PccStaticsSolution,
};

/// A PCC robot under a tip wrench as a forward model, warm-started from its last solve.
pub struct PccForward<'r> {
    robot: &'r PccRobot,
    loads: PccLoads,
    options: PccSolveOptions,
    /// The last solution.
    pub solution: Option<PccStaticsSolution>,
}

impl<'r> PccForward<'r> {
    /// The forward model of `robot` under the tip wrench of `loads` (its tensions and
    /// pressures are replaced by the actuation), solved with `options`.
    pub fn new(robot: &'r PccRobot, loads: &PccLoads, options: &PccSolveOptions) -> Self {
        Self {
            robot,
            loads: loads.clone(),
            options: options.clone(),
            solution: None,
        }
    }

    /// The loads at the actuation `a` (tensions then pressures).
    pub fn loads_at(&self, a: &[f64]) -> PccLoads {
        let nt = self.robot.n_tendons();
        PccLoads {
            tensions: a[..nt].to_vec(),
            pressures: a[nt..].to_vec(),
            ..self.loads.clone()
        }
    }
}

impl Forward for PccForward<'_> {
    fn forget(&mut self) {
        self.solution = None;
    }

    fn dims(&self) -> (usize, usize) {
        (self.robot.n_tendons(), self.robot.n_chambers())
    }

    fn length(&self) -> f64 {
        self.robot.segments().iter().map(|s| s.rest_length()).sum()
    }

    fn chamber_areas(&self) -> Vec<f64> {
        self.robot
            .chambers()
            .iter()
            .flat_map(|(_, c)| c.areas().to_vec())
            .collect()
    }

    fn evaluate(&mut self, a: &[f64], jacobian: bool) -> Result<Evaluation> {
        let loads = self.loads_at(a);
        let loaded = loads.tip_force != Vector3::zeros() || loads.tip_moment != Vector3::zeros();
        let opts = PccSolveOptions {
            // The unloaded equilibrium is closed form; a loaded one starts from the last.
            warm_start: if loaded {
                self.solution.as_ref().map(PccStaticsSolution::warm_start)
            } else {
                None
            },
            ..self.options.clone()
        };
        let sol = solve_pcc_statics(self.robot, &loads, &opts)?;
        let t = sol.tip_pose;
        let positions = vec![Vector3::new(t[(0, 3)], t[(1, 3)], t[(2, 3)])];
        let rotation: Matrix3<f64> = t.fixed_view::<3, 3>(0, 0).into_owned();
        let jac = if jacobian {
            Some(vec![pcc_actuation_jacobian(self.robot, &loads, &sol)?])
        } else {
            None
        };
        self.solution = Some(sol);
        Ok(Evaluation {
            positions,
            rotation,
            jacobian: jac,
        })
    }
}

use super::pcc_closed::closed_form;
use super::{
    check_options, check_target, later_starts, over_starts, solve_inverse, InverseOptions,
    InverseSolution, InverseWarmStart, Target,
};

/// The inverse statics of the PCC robot `robot` under the tip wrench of `loads` (its
/// tensions and pressures are ignored) for `target`, the equilibria solved with `solve`: the
/// same objective, iteration and result as [`solve_inverse`] on a [`PccForward`]. For an
/// unloaded, tendon-driven robot and a tip position target it runs in closed form
/// (`pcc_closed.rs`);
/// otherwise, and whenever that iteration cannot decide, it is [`solve_inverse`]. From each
/// start of `options.starts`, the best answer (see [`Starts`](super::Starts)).
///
/// # Errors
/// As [`solve_inverse`].
pub fn pcc_inverse_statics(
    robot: &PccRobot,
    loads: &PccLoads,
    target: &Target,
    options: &InverseOptions,
    solve: &PccSolveOptions,
    warm: Option<&InverseWarmStart>,
) -> Result<InverseSolution> {
    let (nt, nc) = (robot.n_tendons(), robot.n_chambers());
    let length: f64 = robot.segments().iter().map(|s| s.rest_length()).sum();
    check_options(options, nt, nc, length)?;
    check_target(target)?;
    let unloaded = loads.tip_force == Vector3::zeros() && loads.tip_moment == Vector3::zeros();
    // Tendons only: with chambers the norm can be nearly flat along the target (pressure
    // against tension), where the generic iteration's answer is kept.
    let closed = unloaded
        && nt > 0
        && nc == 0
        && target.s.is_none()
        && target.rotation.is_none()
        && target.points.len() == 1;
    let later = later_starts(target, options, || Ok(PccForward::new(robot, loads, solve)))?;
    over_starts(options, warm, later, |io, w| {
        if closed {
            if let Some(out) = closed_form(robot, &target.points[0], io, w) {
                return Ok((out, ()));
            }
        }
        let mut fwd = PccForward::new(robot, loads, solve);
        solve_inverse(&mut fwd, target, io, w).map(|out| (out, ()))
    })
    .map(|(out, ())| out)
}
