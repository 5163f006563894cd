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
use crate::limits::{check_load, MAX_OFFSET_RATIO};
use crate::model::actuation::{Actuation, TendonInput};
use crate::model::chamber::{self, Chamber};
use crate::model::hold::Hold;
use crate::model::loads::{Frame, Loads};
use crate::model::material::TangentCompliance;
use crate::model::rod::{Profile, Rod, FUNCTION_CHECKS};
use crate::model::tendon::{Routing, Tendon};

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
    /// Largest distance of every tendon from the backbone (m), over its check points.
    tendon_reach: Vec<f64>,
    /// Largest cross-section area of every chamber (m²), over its check points.
    chamber_area_max: Vec<f64>,
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
    /// Whether the constitutive law at a given body wrench is the same at every `s` (uniform
    /// linear section, constant rest strains and tendon offsets, no chambers).
    uniform_along: bool,
    /// Intervals of the backbone held on a surface (a contact solve's intervals on curved
    /// obstacles; none for a user's model), and per integration interval the one it lies in.
    holds: Vec<Hold>,
    hold_of: Vec<Option<usize>>,
}

impl RobotModel {
    /// Validates and shares a robot model.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the offending field: `tendons[i].end` outside
    /// `(0, L]`, `tendons[i].offset(s)` not finite, `chambers[i].start`/`.end`/`.offset`/
    /// `.area(s)`, `loads.*`, `density` (gravity without it), `section(0).*` (a property
    /// not finite and positive: a radius of 1e100 m), `rod` (a force scale `E I(0) / L²` out of
    /// double precision).
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
    /// The rod, tendons and chambers were validated with this model: only the loads are
    /// checked, and what depends on them (breaks, `rho g`, force-free) is recomputed.
    pub fn with_loads(&self, loads: Loads) -> Result<Arc<Self>> {
        self.loaded(loads).map(Arc::new)
    }

    /// The same robot under `loads` with the backbone held on the surfaces of `holds` (their
    /// ends are breaks of the integration intervals: `loads` has a point load at each).
    ///
    /// # Errors
    /// As [`Self::with_loads`]; [`Error::InvalidParameter`] naming `holds` if an interval is
    /// not inside `(0, L]` or its ends are not breaks.
    pub(crate) fn with_loads_and_holds(&self, loads: Loads, holds: Vec<Hold>) -> Result<Arc<Self>> {
        let mut model = self.loaded(loads)?;
        let l = self.length();
        let mut hold_of = vec![None; model.breaks.len() - 1];
        for (i, h) in holds.iter().enumerate() {
            let ka = model.breaks.iter().position(|&b| b == h.a);
            let kb = model.breaks.iter().position(|&b| b == h.b);
            let (Some(ka), Some(kb)) = (ka, kb) else {
                return Err(Error::invalid(
                    "holds",
                    format!("[{}, {}]", h.a, h.b),
                    "breaks",
                ));
            };
            if !(h.a > 0.0 && h.a < h.b && h.b <= l) {
                return Err(Error::invalid(
                    "holds",
                    format!("[{}, {}]", h.a, h.b),
                    "in (0, L]",
                ));
            }
            for k in &mut hold_of[ka..kb] {
                *k = Some(i);
            }
        }
        model.holds = holds;
        model.hold_of = hold_of;
        Ok(Arc::new(model))
    }

    /// [`Self::with_loads`], not shared.
    fn loaded(&self, loads: Loads) -> Result<Self> {
        let l = self.length();
        loads.validate(l, self.rod.density())?;
        check_load_limits(&loads, &self.rod, self.force_scale)?;
        let mut breaks = vec![0.0, l];
        breaks.extend_from_slice(&self.tendon_ends);
        breaks.extend(loads.point_loads.iter().map(|p| p.s));
        for &(start, end) in &self.chamber_extents {
            breaks.extend([start, end]);
        }
        breaks.sort_by(f64::total_cmp);
        breaks.dedup();
        let mut model = Self {
            rod: self.rod.clone(),
            tendons: self.tendons.clone(),
            chambers: self.chambers.clone(),
            loads,
            tendon_ends: self.tendon_ends.clone(),
            tendon_reach: self.tendon_reach.clone(),
            chamber_area_max: self.chamber_area_max.clone(),
            chamber_extents: self.chamber_extents.clone(),
            breaks,
            force_scale: self.force_scale,
            rho_g: None,
            force_free: false,
            uniform_compliance: self.uniform_compliance,
            uniform_along: self.uniform_along,
            holds: Vec::new(),
            hold_of: Vec::new(),
        };
        model.rho_g = rho_g_of(&model.rod, &model.loads);
        model.force_free = force_free_of(&model.loads);
        Ok(model)
    }

    fn build(rod: Rod, tendons: Vec<Tendon>, chambers: Vec<Chamber>, loads: Loads) -> Result<Self> {
        let l = rod.length();
        loads.validate(l, rod.density())?;
        let mut breaks = vec![0.0, l];
        let mut tendon_ends = Vec::with_capacity(tendons.len());
        let mut tendon_reach = Vec::with_capacity(tendons.len());
        for (i, t) in tendons.iter().enumerate() {
            let end = t.end().unwrap_or(l);
            if !(end.is_finite() && end > 0.0 && end <= l) {
                return Err(Error::invalid(
                    format!("tendons[{i}].end"),
                    end,
                    format!("in (0, length] = (0, {l}] m"),
                ));
            }
            tendon_reach.push(check_routing(i, t, &rod, end)?);
            if let Some(g) = t.guides().iter().position(|&g| g >= end) {
                return Err(Error::invalid(
                    format!("tendons[{i}].guides[{g}]"),
                    t.guides()[g],
                    format!("in (0, end) = (0, {end}) m (the termination is the last anchor)"),
                ));
            }
            if t.is_guided() && t.friction() > 0.0 {
                return Err(Error::invalid(
                    format!("tendons[{i}].friction"),
                    t.friction(),
                    "0 for a tendon routed through guides (its chords touch only the guides: \
                     set guide_friction)",
                ));
            }
            breaks.extend_from_slice(t.guides());
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
        let force_scale = force_scale(&rod)?;
        let props0 = rod.section_at(0.0);
        check_load_limits(&loads, &rod, force_scale)?;
        let chamber_area_max = chambers
            .iter()
            .zip(&chamber_extents)
            .map(|(c, &(a, b))| {
                (0..=FUNCTION_CHECKS)
                    .map(|k| c.area_at(a + (b - a) * k as f64 / FUNCTION_CHECKS as f64))
                    .fold(0.0, f64::max)
            })
            .collect();
        let rho_g = rho_g_of(&rod, &loads);
        let force_free = force_free_of(&loads);
        let uniform_compliance =
            (rod.section().is_uniform() && rod.material().is_linear()).then(|| {
                rod.material()
                    .compliance(&props0, rod.shear_coefficient(), rod.inextensible())
            });
        let uniform_along = uniform_compliance.is_some()
            && chambers.is_empty()
            && matches!(rod.rest_strain(), Profile::Constant(_))
            && matches!(rod.rest_curvature(), Profile::Constant(_))
            && tendons.iter().all(|t| {
                t.guides().is_empty()
                    && matches!(
                        t.routing(),
                        Routing::Constant(_) | Routing::RadiusProportional { .. }
                    )
            });
        Ok(Self {
            rod,
            tendons,
            chambers,
            loads,
            tendon_ends,
            tendon_reach,
            chamber_extents,
            chamber_area_max,
            breaks,
            force_scale,
            rho_g,
            force_free,
            uniform_compliance,
            uniform_along,
            holds: Vec::new(),
            hold_of: Vec::new(),
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
    /// Area of every chamber at its start (m²): the area that turns its pressure into a force.
    pub fn chamber_start_areas(&self) -> Vec<f64> {
        self.chambers
            .iter()
            .zip(&self.chamber_extents)
            .map(|(c, (start, _))| c.area_at(*start))
            .collect()
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
    /// Checks an actuation for this model: one input per actuator (or none), tensions finite
    /// and >= 0, pressures finite and above vacuum (see [`Actuation::validate`]), and every
    /// input within [`MAX_LOAD_NUMBER`](crate::limits::MAX_LOAD_NUMBER): a tension `T` by `T (1 + d / L) L² / EI` with `d` the
    /// tendon's largest offset (its force and its moment `T d`), a pressure `p` by
    /// `p A (1 + |r| / L) L² / EI` with `A` the chamber's largest area and `r` its offset.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `tensions[i]`, `pressures[i]` or their counts.
    pub fn check_actuation(&self, actuation: &Actuation) -> Result<()> {
        actuation.validate(self.tendons.len(), self.chambers.len())?;
        let l = self.length();
        for (i, input) in actuation.tendons.iter().enumerate() {
            match input {
                TendonInput::Tension(t) => {
                    let scale = self.force_scale / (1.0 + self.tendon_reach[i] / l);
                    check_load(format_args!("tensions[{i}]"), *t, t.abs(), scale, "N")?;
                }
                TendonInput::Displacement { .. } => {}
            }
        }
        for (i, &p) in actuation.pressures.iter().enumerate() {
            let [x, y] = self.chambers[i].offset();
            let arm = 1.0 + x.hypot(y) / l;
            let scale = self.force_scale / (self.chamber_area_max[i] * arm);
            check_load(format_args!("pressures[{i}]"), p, p.abs(), scale, "Pa")?;
        }
        Ok(())
    }

    /// Checks a base wrench `[force; moment]` (N, N m) given by the user (a warm start)
    /// against [`MAX_LOAD_NUMBER`](crate::limits::MAX_LOAD_NUMBER).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `name[k]` for the first component that is not finite
    /// or too large.
    pub fn check_wrench(&self, name: &str, wrench: &[f64; 6]) -> Result<()> {
        for (k, &w) in wrench.iter().enumerate() {
            let (scale, unit) = if k < 3 {
                (self.force_scale, "N")
            } else {
                (self.force_scale * self.length(), "N m")
            };
            check_load(format_args!("{name}[{k}]"), w, w.abs(), scale, unit)?;
        }
        Ok(())
    }

    /// The section compliance if it is the same at every `s`.
    pub fn uniform_compliance(&self) -> Option<&TangentCompliance> {
        self.uniform_compliance.as_ref()
    }

    /// Whether the strains at a given body wrench are the same at every `s` (uniform linear
    /// section, constant rest strains and tendon offsets, no chambers).
    pub(crate) fn uniform_along(&self) -> bool {
        self.uniform_along
    }

    /// The held interval (see [`Hold`]) that integration interval `k` lies in, if any.
    #[inline]
    pub(crate) fn hold_on(&self, k: usize) -> Option<&Hold> {
        self.hold_of
            .get(k)
            .copied()
            .flatten()
            .map(|i| &self.holds[i])
    }

    /// The held intervals.
    pub(crate) fn holds(&self) -> &[Hold] {
        &self.holds
    }
}

/// `rho g` (N/m³) of the rod under the loads, if gravity acts.
fn rho_g_of(rod: &Rod, loads: &Loads) -> Option<Vector3<f64>> {
    rod.density()
        .filter(|_| loads.gravity != Vector3::zeros())
        .map(|rho| loads.gravity * rho)
}

/// Whether no force acts along the rod under the loads (only world-frame tip loads and
/// moments).
fn force_free_of(loads: &Loads) -> bool {
    loads.distributed_force.is_none()
        && loads.gravity == Vector3::zeros()
        && loads.point_loads.iter().all(|p| {
            p.force == Vector3::zeros() && (p.frame == Frame::World || p.moment == Vector3::zeros())
        })
        && (loads.tip_frame == Frame::World
            || (loads.tip_force == Vector3::zeros() && loads.tip_moment == Vector3::zeros()))
}

/// Checks tendon `i`'s routing on `[0, end]` at the check points: offset and derivative
/// finite, the distance from the backbone at most [`MAX_OFFSET_RATIO`] of the length (inside the
/// section, or through spacer disks outside it), and the tendon's path running forward in the
/// rest shape (`v*_z + u*_x y - u*_y x > 0`: on a precurved rod, a tendon beyond the centre of
/// the rest curvature would run backwards). Returns the largest distance (m).
///
/// A constant offset on a rod whose rest strains are constant has the same values at every
/// check point: it is checked once, at `s = 0` (the first point, so the same error), unless
/// the section is a user function (its calls at the check points are kept).
fn check_routing(i: usize, tendon: &Tendon, rod: &Rod, end: f64) -> Result<f64> {
    let l = rod.length();
    let max_offset = MAX_OFFSET_RATIO * l;
    let mut reach: f64 = 0.0;
    let uniform = matches!(tendon.routing(), Routing::Constant(_))
        && matches!(rod.rest_strain(), Profile::Constant(_))
        && matches!(rod.rest_curvature(), Profile::Constant(_))
        && !rod.section().is_function();
    let checks = if uniform { 0 } else { FUNCTION_CHECKS };
    for k in 0..=checks {
        let s = end * k as f64 / FUNCTION_CHECKS as f64;
        let (r, rp) = tendon.routing().offset(s, &rod.section_at(s));
        if !(r.iter().chain(rp.iter()).all(|v| v.is_finite())) {
            return Err(Error::invalid(
                format!("tendons[{i}].offset({s})"),
                format!("{r:?}, {rp:?}"),
                "finite",
            ));
        }
        let d = r[0].hypot(r[1]);
        if d > max_offset {
            return Err(Error::invalid(
                format!("tendons[{i}].offset({s})"),
                format!("{r:?}"),
                format!(
                    "at most {MAX_OFFSET_RATIO} x length = {max_offset} m from the backbone \
                     (distance {d:.6e} m; the section radius there is {:.6e} m)",
                    rod.section_at(s).radius
                ),
            ));
        }
        let (v, u) = (rod.rest_strain().at(s), rod.rest_curvature().at(s));
        let forward = v[2] + u[0] * r[1] - u[1] * r[0];
        if forward.is_nan() || forward <= 0.0 {
            return Err(Error::invalid(
                format!("tendons[{i}].offset({s})"),
                format!("{r:?}"),
                format!(
                    "on the inner side of the rest curvature closer to the backbone than its \
                     centre (v*_z + u*_x y - u*_y x = {forward:.3e} must be > 0)"
                ),
            ));
        }
        if let Routing::Function { offset, .. } = tendon.routing() {
            check_derivative(i, offset.as_ref(), (s, end), (r, rp))?;
        }
        reach = reach.max(d);
    }
    Ok(reach)
}

/// Step of the differences that check a user routing's derivative, relative to the length
/// it is checked on.
const DERIVATIVE_STEP: f64 = 1e-6;
/// Largest difference accepted between a user routing's derivative and the differences of its
/// offset, relative to `|r'| + |r| / end`: far above the differences' own error (round-off
/// `ε |r| / h`, truncation `h² |r'''|` inside and at the ends), far below a missing factor or
/// sign.
const DERIVATIVE_TOLERANCE: f64 = 1e-4;

/// Checks that the derivative `rp` a user routing gives at `s` (of `[0, end]`) is that of its
/// offset `r`: second-order differences of the offset (central inside, one-sided at the ends);
/// at a kink, the first-order difference of either side. Differences that disagree are made
/// again with steps 10, 100 and 1000 times smaller before the derivative is refused (an
/// offset that winds a turn within a few steps, e.g. a helix of pitch 1e-4 of the length, is
/// not differenced by the first).
fn check_derivative(
    i: usize,
    offset: &(dyn Fn(f64) -> [f64; 2] + Send + Sync),
    (s, end): (f64, f64),
    (r, rp): ([f64; 2], [f64; 2]),
) -> Result<()> {
    let tol =
        DERIVATIVE_TOLERANCE * (rp[0].hypot(rp[1]) + r[0].hypot(r[1]) / end) + f64::MIN_POSITIVE;
    let close = |d: [f64; 2]| (d[0] - rp[0]).hypot(d[1] - rp[1]) <= tol;
    let diff = |a: [f64; 2], b: [f64; 2], dt: f64| [(b[0] - a[0]) / dt, (b[1] - a[1]) / dt];
    let mut first = None;
    for shrink in [1.0, 0.1, 0.01, 0.001] {
        let h = shrink * DERIVATIVE_STEP * end;
        let below = (s - h >= 0.0).then(|| offset(s - h));
        let above = (s + h <= end).then(|| offset(s + h));
        // `(-3 r(s) + 4 r(s ± h) - r(s ± 2h)) / (± 2h)` at an end.
        let one_sided = |r1: [f64; 2], dir: f64| {
            let r2 = offset(s + 2.0 * dir * h);
            [0, 1].map(|k| (-3.0 * r[k] + 4.0 * r1[k] - r2[k]) / (2.0 * dir * h))
        };
        let second = match (below, above) {
            (Some(lo), Some(hi)) => diff(lo, hi, 2.0 * h),
            (None, Some(hi)) => one_sided(hi, 1.0),
            (Some(lo), None) => one_sided(lo, -1.0),
            (None, None) => return Ok(()),
        };
        if close(second)
            || below.is_some_and(|lo| close(diff(lo, r, h)))
            || above.is_some_and(|hi| close(diff(r, hi, h)))
        {
            return Ok(());
        }
        first.get_or_insert(second);
    }
    Err(Error::invalid(
        format!("tendons[{i}].derivative({s})"),
        format!("{rp:?}"),
        format!(
            "the derivative of the offset function (its differences there give {:?})",
            first.unwrap_or_default()
        ),
    ))
}

/// Checks every external load against [`MAX_LOAD_NUMBER`](crate::limits::MAX_LOAD_NUMBER) with the force scale `EI / L²`.
fn check_load_limits(loads: &Loads, rod: &Rod, force_scale: f64) -> Result<()> {
    let l = rod.length();
    let (f0, m0) = (force_scale, force_scale * l);
    // (Scaled by the largest component: the plain norm of [1e300, 0, 0] overflows to inf,
    // and an error would report that instead of the value given.)
    let norm = |v: &Vector3<f64>| {
        let largest = v.amax();
        if largest > 0.0 && largest.is_finite() {
            largest * (v / largest).norm()
        } else {
            largest
        }
    };
    check_load(
        "loads.tip_force",
        norm(&loads.tip_force),
        norm(&loads.tip_force),
        f0,
        "N",
    )?;
    check_load(
        "loads.tip_moment",
        norm(&loads.tip_moment),
        norm(&loads.tip_moment),
        m0,
        "N m",
    )?;
    for (i, p) in loads.point_loads.iter().enumerate() {
        let (f, m) = (norm(&p.force), norm(&p.moment));
        check_load(format_args!("loads.point_loads[{i}].force"), f, f, f0, "N")?;
        check_load(
            format_args!("loads.point_loads[{i}].moment"),
            m,
            m,
            m0,
            "N m",
        )?;
    }
    for (name, profile, scale, unit) in [
        (
            "loads.distributed_force",
            &loads.distributed_force,
            f0 / l,
            "N/m",
        ),
        (
            "loads.distributed_moment",
            &loads.distributed_moment,
            f0,
            "N m/m",
        ),
    ] {
        if let Some(p) = profile {
            for (at, v) in p.check_points(l) {
                check_load(format_args!("{name}{at}"), norm(&v), norm(&v), scale, unit)?;
            }
        }
    }
    if let (Some(rho), true) = (rod.density(), loads.gravity != Vector3::zeros()) {
        let area = (0..=FUNCTION_CHECKS)
            .map(|k| rod.section_at(l * k as f64 / FUNCTION_CHECKS as f64).area)
            .fold(0.0, f64::max);
        let g = norm(&loads.gravity);
        // The weight per length rho A g against f0 / L.
        check_load("loads.gravity", g, g, f0 / (l * rho * area), "m/s^2")?;
    }
    Ok(())
}

/// The force scale `E I(0) / L²` (N) of `rod`, checked.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `section(0).*` (a property not finite and positive) or
/// `rod` (a scale that is not a positive, normal double: each input was checked, but together
/// they leave double precision, as a modulus of 1e-300 Pa or a rod 1e-300 m long).
fn force_scale(rod: &Rod) -> Result<f64> {
    let l = rod.length();
    let props0 = rod.section_at(0.0).validated("section(0)")?;
    let bending = rod.material().bending_stiffness(&props0);
    let force_scale = bending / (l * l);
    if force_scale.is_normal() && force_scale > 0.0 {
        return Ok(force_scale);
    }
    Err(Error::invalid(
        "rod",
        format!("E I(0) / L^2 = {force_scale:e} N (E I(0) = {bending:e} N m^2, L = {l:e} m)"),
        "a force scale that is a positive, normal double-precision number (the length, \
         section and modulus together are out of range)",
    ))
}
