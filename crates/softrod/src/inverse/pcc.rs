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
