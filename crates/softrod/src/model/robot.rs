//! The validated, immutable robot model: rod, tendon routings, chambers and external loads.
//!
//! [`RobotModel::new`] checks everything once (tendon terminations in `(0, L]`, offsets
//! finite, chambers inside the section, loads finite, gravity with a density) and precomputes
//! what every solve needs: the breaks of the integration intervals (tendon terminations,
//! chamber ends, point loads) and the force scale of the shooting unknowns. It is shared by
//! [`Arc`]: a solution keeps the model it solves, a sweep solves one model for many
//! actuations. Nothing in it changes during a solve.

use std::sync::Arc;

use nalgebra::Vector3;

use crate::error::{Error, Result};
use crate::model::chamber::{self, Chamber};
use crate::model::loads::{Frame, Loads};
use crate::model::material::TangentCompliance;
use crate::model::rod::{Rod, FUNCTION_CHECKS};
use crate::model::tendon::Tendon;

/// A validated robot: rod, tendons (routing and termination), chambers (geometry) and external
/// loads, with the precomputed data of the solvers.
#[derive(Debug, Clone)]
pub struct RobotModel {
    rod: Rod,
    tendons: Vec<Tendon>,
    chambers: Vec<Chamber>,
    loads: Loads,
    /// Termination of every tendon (m).
    tendon_ends: Vec<f64>,
    /// Extent `(start, end)` of every chamber (m).
    chamber_extents: Vec<(f64, f64)>,
    /// Interval end points `0 = b_0 < b_1 < ... = L`.
    breaks: Vec<f64>,
    /// Force scale `E I(0) / L²` (N) of the shooting unknowns and residual.
    force_scale: f64,
    /// `rho g` (N/m³), if gravity is on.
    rho_g: Option<Vector3<f64>>,
    /// Whether no force acts along the rod (only world-frame tip loads and moments).
    force_free: bool,
    /// The section compliance when it does not depend on `s` (linear material, uniform
    /// section).
    uniform_compliance: Option<TangentCompliance>,
}

impl RobotModel {
    /// Validates and shares a robot model.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the offending field: `tendons[i].end` outside
    /// `(0, L]`, `tendons[i].offset(s)` not finite, `chambers[i].start`/`.end`/`.offset`/
    /// `.area(s)`, `loads.*`, `density` (gravity without it), `section(0)`.
    pub fn new(
        rod: Rod,
        tendons: Vec<Tendon>,
        chambers: Vec<Chamber>,
        loads: Loads,
    ) -> Result<Arc<Self>> {
        Self::build(rod, tendons, chambers, loads).map(Arc::new)
    }

    /// A rod without actuators under `loads`.
    ///
    /// # Errors
    /// As [`RobotModel::new`].
    pub fn rod_only(rod: Rod, loads: Loads) -> Result<Arc<Self>> {
        Self::new(rod, Vec::new(), Vec::new(), loads)
    }

    /// The same robot under other external loads.
    ///
    /// # Errors
    /// As [`RobotModel::new`] for the loads.
    pub fn with_loads(&self, loads: Loads) -> Result<Arc<Self>> {
        Self::new(
            self.rod.clone(),
            self.tendons.clone(),
            self.chambers.clone(),
            loads,
        )
    }

    fn build(rod: Rod, tendons: Vec<Tendon>, chambers: Vec<Chamber>, loads: Loads) -> Result<Self> {
        let l = rod.length();
        loads.validate(l, rod.density())?;
        let mut breaks = vec![0.0, l];
        let mut tendon_ends = Vec::with_capacity(tendons.len());
        for (i, t) in tendons.iter().enumerate() {
            let end = t.end().unwrap_or(l);
            if !(end.is_finite() && end > 0.0 && end <= l) {
                return Err(Error::invalid(
                    format!("tendons[{i}].end"),
                    end,
                    format!("in (0, length] = (0, {l}] m"),
                ));
            }
            for k in 0..=FUNCTION_CHECKS {
                let s = end * k as f64 / FUNCTION_CHECKS as f64;
                let (r, rp) = t.routing().offset(s, &rod.section_at(s));
                if !(r.iter().chain(rp.iter()).all(|v| v.is_finite())) {
                    return Err(Error::invalid(
                        format!("tendons[{i}].offset({s})"),
                        format!("{r:?}, {rp:?}"),
                        "finite",
                    ));
                }
            }
            breaks.push(end);
            tendon_ends.push(end);
        }
        for p in &loads.point_loads {
            breaks.push(p.s);
        }
        let chamber_extents = chamber::validate(&chambers, &rod)?;
        for &(start, end) in &chamber_extents {
            breaks.extend([start, end]);
        }
        breaks.sort_by(f64::total_cmp);
        breaks.dedup();
        let props0 = rod.section_at(0.0);
        let force_scale = rod.material().bending_stiffness(&props0) / (l * l);
        if !(force_scale.is_finite() && force_scale > 0.0) {
            return Err(Error::invalid(
                "section(0)",
                format!("{props0:?}"),
                "positive and finite",
            ));
        }
        let rho_g = rod
            .density()
            .filter(|_| loads.gravity != Vector3::zeros())
            .map(|rho| loads.gravity * rho);
        let force_free = loads.distributed_force.is_none()
            && loads.gravity == Vector3::zeros()
            && loads.point_loads.iter().all(|p| {
                p.force == Vector3::zeros()
                    && (p.frame == Frame::World || p.moment == Vector3::zeros())
            })
            && (loads.tip_frame == Frame::World
                || (loads.tip_force == Vector3::zeros() && loads.tip_moment == Vector3::zeros()));
        let uniform_compliance =
            (rod.section().is_uniform() && rod.material().is_linear()).then(|| {
                rod.material()
                    .compliance(&props0, rod.shear_coefficient(), rod.inextensible())
            });
        Ok(Self {
            rod,
            tendons,
            chambers,
            loads,
            tendon_ends,
            chamber_extents,
            breaks,
            force_scale,
            rho_g,
            force_free,
            uniform_compliance,
        })
    }

    /// The rod.
    pub fn rod(&self) -> &Rod {
        &self.rod
    }
    /// The tendons (routing and termination), in the order of their inputs.
    pub fn tendons(&self) -> &[Tendon] {
        &self.tendons
    }
    /// The chambers, in the order of their pressures.
    pub fn chambers(&self) -> &[Chamber] {
        &self.chambers
    }
    /// The external loads.
    pub fn loads(&self) -> &Loads {
        &self.loads
    }
    /// Rod length `L` (m).
    pub fn length(&self) -> f64 {
        self.rod.length()
    }
    /// Termination of every tendon (m).
    pub fn tendon_ends(&self) -> &[f64] {
        &self.tendon_ends
    }
    /// Extent `(start, end)` of every chamber (m).
    pub fn chamber_extents(&self) -> &[(f64, f64)] {
        &self.chamber_extents
    }
    /// Interval end points `0 = b_0 < b_1 < ... = L` (m): tendon terminations, chamber ends,
    /// point loads.
    pub fn breaks(&self) -> &[f64] {
        &self.breaks
    }
    /// Force scale `E I(0) / L²` (N) of the shooting unknowns (moments: times `L`).
    pub fn force_scale(&self) -> f64 {
        self.force_scale
    }
    /// `rho g` (N/m³) if gravity acts.
    pub fn rho_g(&self) -> Option<Vector3<f64>> {
        self.rho_g
    }
    /// Whether no force acts along the rod (only world-frame tip loads and moments): then the
    /// internal force is constant along the rod.
    pub fn force_free(&self) -> bool {
        self.force_free
    }
    /// The section compliance if it is the same at every `s`.
    pub fn uniform_compliance(&self) -> Option<&TangentCompliance> {
        self.uniform_compliance.as_ref()
    }
}
