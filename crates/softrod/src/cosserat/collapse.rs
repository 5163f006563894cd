//! The named cause of an actuated rod that cannot be integrated: tendons that compress an
//! extensible rod to zero length, or that bend it tighter than their own distance from the
//! backbone.
//!
//! Without external loads the rod carries the tendons' pull as compression: at a section
//! reached by the tendons `i` the axial force is about `Σ τ_i` (exactly for tendons parallel to
//! the backbone). A linear elastic rod's stretch there is `1 - Σ τ_i / (E A(s))`, zero or
//! negative once the tensions reach the axial stiffness `E A(s)`: no configuration exists, and
//! the solve says which tension and which stiffness instead of a bare non-convergence.

use nalgebra::Vector3;

use super::solution::StaticsSolution;
use crate::error::Error;
use crate::model::RobotModel;

/// Sections checked along the rod (uniformly, plus the tendon ends).
const SAMPLES: usize = 64;

/// The sections checked: [`SAMPLES`] uniform ones and the tendons' ends (m).
fn sections(model: &RobotModel) -> Vec<f64> {
    let length = model.length();
    let mut points: Vec<f64> = (0..=SAMPLES)
        .map(|k| length * k as f64 / SAMPLES as f64)
        .collect();
    points.extend(model.tendons().iter().filter_map(|t| t.end()));
    points
}

/// An [`Error::InvalidParameter`] naming the largest tendon tension if the tensions reach the
/// axial stiffness `E A(s)` of an extensible, linear elastic rod at some section (the rod would
/// be compressed to zero length: a stretch below [`LEAST_STRETCH`]); `None` otherwise.
pub(crate) fn compressed_to_zero(model: &RobotModel, tensions: &[f64]) -> Option<Error> {
    let rod = model.rod();
    if rod.inextensible() || !rod.material().is_linear() {
        return None;
    }
    let tendons = model.tendons();
    let points = sections(model);
    for s in points {
        let reach: f64 = tendons
            .iter()
            .zip(tensions)
            .filter(|(t, _)| t.end().is_none_or(|e| s <= e))
            .map(|(_, &tau)| tau.max(0.0))
            .sum();
        let c = rod
            .material()
            .compliance(&rod.section_at(s), rod.shear_coefficient(), false);
        let ea = 1.0 / c[2];
        // (The stretch `1 - Σ τ / (E A)` at or below the least accepted, not `Σ τ >= E A`:
        // tensions of exactly `E A` computed elsewhere differ from it in the last place.)
        if reach > 0.0 && 1.0 - reach * c[2] < LEAST_STRETCH {
            let (i, tau) = tensions
                .iter()
                .enumerate()
                .max_by(|a, b| a.1.total_cmp(b.1))?;
            return Some(Error::invalid(
                format!("tensions[{i}]"),
                tau,
                format!(
                    "tensions summing to less than the rod's axial stiffness E A = {ea:.4e} N at \
                     s = {s:.4} m (they total {reach:.4e} N there: the rod would be compressed \
                     to zero length; raise youngs_modulus or lower the tensions)"
                ),
            ));
        }
    }
    None
}

/// An [`Error::InvalidParameter`] naming the tension of a tendon whose path would turn back on
/// itself on the actuated rod of a linear elastic model without chambers: at a section, the
/// strains of straight tendons (the rod's wrench balancing the tendons' pull along the
/// backbone: `v = v* - C Σ τ e₃`, `u = u* - C Σ τ r × e₃`, exact for one straight tendon and
/// for any on a rod that cannot shear or twist) give the tendon's path a speed
/// `(v + u × r + r')·e₃ <= 0`: the rod is bent to a radius of curvature inside the tendon's
/// distance from the backbone, and no configuration exists. `None` otherwise.
pub(crate) fn bent_inside_a_tendon(model: &RobotModel, tensions: &[f64]) -> Option<Error> {
    let rod = model.rod();
    if !rod.material().is_linear() || !model.chambers().is_empty() {
        return None;
    }
    let tendons = model.tendons();
    let points = sections(model);
    for s in points {
        let props = rod.section_at(s);
        let reaching: Vec<(usize, Vector3<f64>, Vector3<f64>, f64)> = tendons
            .iter()
            .zip(tensions)
            .enumerate()
            .filter(|(_, (t, tau))| **tau > 0.0 && t.end().is_none_or(|e| s <= e))
            .map(|(i, (t, &tau))| {
                let (r, rp) = t.routing().offset(s, &props);
                (
                    i,
                    Vector3::new(r[0], r[1], 0.0),
                    Vector3::new(rp[0], rp[1], 0.0),
                    tau,
                )
            })
            .collect();
        let (mut force, mut moment) = (Vector3::zeros(), Vector3::zeros());
        for (_, r, _, tau) in &reaching {
            force.z += tau;
            moment += r.cross(&Vector3::z()) * *tau;
        }
        let c = rod
            .material()
            .compliance(&props, rod.shear_coefficient(), rod.inextensible());
        let v = rod.rest_strain().at(s) - Vector3::new(c[0], c[1], c[2]).component_mul(&force);
        let u = rod.rest_curvature().at(s) - Vector3::new(c[3], c[4], c[5]).component_mul(&moment);
        for (i, r, rp, tau) in &reaching {
            if (v + u.cross(r) + rp).z > 0.0 {
                continue;
            }
            // The deformed backbone's curvature: `|u⊥|` per unit of stretched length `v₃`.
            let bend = u.x.hypot(u.y) / v.z;
            return Some(Error::invalid(
                format!("tensions[{i}]"),
                tau,
                format!(
                    "tensions that bend the rod to a radius of curvature larger than the \
                     tendons' distance from the backbone (at s = {s:.4} m they bend it to a \
                     radius of curvature of {:.4e} m, inside tendon {i}'s distance {:.4e} m: its \
                     path would turn back on itself; lower the tensions or raise youngs_modulus)",
                    1.0 / bend,
                    r.norm()
                ),
            ));
        }
    }
    None
}

/// The least stretch `v₃` of a solution accepted: below it the rod is compressed to (or
/// through) zero length.
const LEAST_STRETCH: f64 = 1e-9;

/// An [`Error::InvalidParameter`] naming `name` (what loaded the rod: `loads`, or
/// `tip_constraint` for a held tip) if the stretch `v₃` of `sol` falls below [`LEAST_STRETCH`]
/// anywhere: a linear law solves a rod compressed through zero length (an inverted rod,
/// negative stretch) or held at zero length (the tip held at the base) without complaint, and
/// no rod is either. `None` otherwise.
pub(crate) fn compressed_through_zero(sol: &StaticsSolution, name: &str) -> Option<Error> {
    let (j, v3) = sol
        .v
        .iter()
        .enumerate()
        .map(|(j, v)| (j, v[2]))
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    if v3 >= LEAST_STRETCH {
        return None;
    }
    let rod = sol.model.rod();
    let s = sol.s[j];
    let c = rod
        .material()
        .compliance(&rod.section_at(s), rod.shear_coefficient(), false);
    Some(Error::invalid(
        name,
        format!(
            "an axial force of {:.4e} N at s = {s:.4} m",
            sol.n_body[j][2]
        ),
        format!(
            "loads that leave the rod a positive stretch (there its stretch v3 is {v3:.4e}: the \
             rod is compressed to or through zero length; its axial stiffness E A is {:.4e} N)",
            1.0 / c[2]
        ),
    ))
}
