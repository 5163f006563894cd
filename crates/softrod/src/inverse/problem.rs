//! The checked program of one inverse statics: the bounds, weights and centre of the
//! actuation, the rotation weight of the pose error, the phase thresholds; the checks of the
//! options and the target; the rows of the pose error and their Jacobian.

use nalgebra::{DMatrix, DVector};

use super::qp::Bounds;
use super::{Evaluation, Forward, InverseOptions, Target, NEAR_TARGET};
use crate::error::{Error, Result};
use crate::math::so3::log_so3;
use crate::model::chamber::ATMOSPHERIC_PRESSURE;

/// The pose error at one evaluation: its rows `e` (positions in m, rotations times the
/// rotation weight), their Jacobian in the actuation, the largest distance from a target
/// point (m) and the rotation to the target orientation (rad).
pub(super) struct PoseError {
    /// The scaled error rows.
    pub e: DVector<f64>,
    /// Their Jacobian in the actuation (rows × n), if the evaluation has one.
    pub jac: Option<DMatrix<f64>>,
    /// Largest distance from a target position (m).
    pub dist: f64,
    /// Rotation to the target orientation (rad; 0 without one).
    pub rot: f64,
}

/// What one inverse statics solves for, checked: the target and options, the box, weights
/// and centre of the actuation (tensions then pressures), and the scales of the iteration.
pub(super) struct Program<'a> {
    /// The target.
    pub target: &'a Target,
    /// The options.
    pub options: &'a InverseOptions,
    /// Bounds, weights `W` and centre `a_ref` of the actuation.
    pub bounds: Bounds,
    /// Number of tendons (the first actuators).
    pub nt: usize,
    /// The rod length (m).
    pub length: f64,
    /// Weight of the rotation rows (m/rad).
    pub rotation_weight: f64,
    /// Whether the target is a shape (points at arc lengths, fitted in least squares).
    pub shape: bool,
    /// Pose error (m) below which the iteration is in its near phase.
    pub near: f64,
    /// Tolerance of the quadratic programs' constraint (m).
    pub tol_qp: f64,
}

impl<'a> Program<'a> {
    /// The program of `target` under `options` for the actuators of `forward`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming a bad option or target, or a robot without actuators.
    pub fn new<F: Forward + ?Sized>(
        forward: &F,
        target: &'a Target,
        options: &'a InverseOptions,
    ) -> Result<Self> {
        let (nt, nc) = forward.dims();
        let n = nt + nc;
        let length = forward.length();
        check_options(options, nt, nc, length)?;
        check_target(target)?;
        if n == 0 {
            return Err(Error::invalid(
                "robot",
                "no tendons or chambers",
                "at least one actuator",
            ));
        }
        let areas = forward.chamber_areas();
        // (Only the ratios of given weights matter to the minimiser; scaled so that the
        // largest equals the largest default weight, the step and stopping tests, which
        // measure in the weighted norm, are those of the default weights.)
        let default: Vec<f64> = (0..n)
            .map(|i| if i < nt { 1.0 } else { areas[i - nt].powi(2) })
            .collect();
        let weights = match &options.weights {
            Some(w) => {
                let largest = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
                let k = largest(&default) / largest(w);
                w.iter().map(|v| v * k).collect()
            }
            None => default,
        };
        let mut lo = vec![options.tension_bounds.0; nt];
        lo.extend(vec![options.pressure_bounds.0; nc]);
        let mut hi = vec![options.tension_bounds.1; nt];
        hi.extend(vec![options.pressure_bounds.1; nc]);
        let centre = options.reference.clone().unwrap_or_else(|| vec![0.0; n]);
        let rotation_weight = options.rotation_weight.unwrap_or(length);
        Ok(Self {
            target,
            options,
            bounds: Bounds {
                lo,
                hi,
                weights,
                centre,
            },
            nt,
            length,
            rotation_weight,
            shape: target.s.is_some(),
            near: NEAR_TARGET * length,
            tol_qp: 1e-3
                * options
                    .tolerance
                    .min(options.rotation_tolerance * rotation_weight),
        })
    }

    /// Number of actuators.
    pub fn n(&self) -> usize {
        self.bounds.weights.len()
    }

    /// `a` clamped into the bounds.
    pub fn clamp(&self, a: &mut [f64]) {
        for (i, v) in a.iter_mut().enumerate() {
            *v = v.max(self.bounds.lo[i]).min(self.bounds.hi[i]);
        }
    }

    /// The scaled norm `|v|_W`.
    pub fn scaled_norm(&self, v: &[f64]) -> f64 {
        v.iter()
            .zip(&self.bounds.weights)
            .map(|(x, w)| x * x * w)
            .sum::<f64>()
            .sqrt()
    }

    /// The pose error of the evaluation `ev`.
    pub fn error(&self, ev: &Evaluation) -> PoseError {
        error_rows(self.target, ev, self.rotation_weight)
    }

    /// `|e|` of [`Program::error`] alone (the merit of a trial).
    pub fn error_norm(&self, ev: &Evaluation) -> f64 {
        let mut sq: f64 = (self.target.points.iter().zip(&ev.positions))
            .map(|(p, q)| (p - q).norm_squared())
            .sum();
        if let Some(rt) = &self.target.rotation {
            sq += (log_so3(&(rt * ev.rotation.transpose())) * self.rotation_weight).norm_squared();
        }
        sq.sqrt()
    }
}

/// Largest ratio of two actuators' weights: about the reciprocal of the machine epsilon,
/// beyond which a sum of weighted terms loses the smaller ones entirely.
pub(crate) const MAX_WEIGHT_RATIO: f64 = 1e15;

pub(crate) fn check_options(o: &InverseOptions, nt: usize, nc: usize, length: f64) -> Result<()> {
    let n = nt + nc;
    let (tl, th) = o.tension_bounds;
    if !(tl.is_finite() && tl >= 0.0 && !th.is_nan() && th >= tl) {
        return Err(Error::invalid(
            "tension_bounds",
            format!("({tl}, {th})"),
            "(lo, hi) with 0 <= lo <= hi (N; hi may be inf)",
        ));
    }
    let (pl, ph) = o.pressure_bounds;
    if !(pl.is_finite() && pl >= -ATMOSPHERIC_PRESSURE && !ph.is_nan() && ph >= pl) {
        return Err(Error::invalid(
            "pressure_bounds",
            format!("({pl}, {ph})"),
            format!("(lo, hi) with -{ATMOSPHERIC_PRESSURE} <= lo <= hi (Pa; hi may be inf)"),
        ));
    }
    if let Some(w) = &o.weights {
        if w.len() != n {
            return Err(Error::invalid(
                "weights.len()",
                w.len(),
                format!("one per tendon and chamber, {n}"),
            ));
        }
        for (i, v) in w.iter().enumerate() {
            if !(v.is_finite() && *v > 0.0) {
                return Err(Error::invalid(format!("weights[{i}]"), v, "finite and > 0"));
            }
        }
        // Only the ratios matter; beyond double precision the smaller weights vanish from
        // the objective's sums (1e20 : 1 on the NiTi robot: a reachable target was reported
        // out of reach).
        let (lo, hi) = w.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), v| {
            (lo.min(*v), hi.max(*v))
        });
        if hi > MAX_WEIGHT_RATIO * lo {
            return Err(Error::invalid(
                "weights",
                format!("from {lo:e} to {hi:e}"),
                format!("within a ratio of {MAX_WEIGHT_RATIO:e} (only the ratios matter)"),
            ));
        }
    }
    if let Some(r) = &o.reference {
        if r.len() != n {
            return Err(Error::invalid(
                "reference.len()",
                r.len(),
                format!("one per tendon and chamber, {n}"),
            ));
        }
        for (i, v) in r.iter().enumerate() {
            if !v.is_finite() {
                return Err(Error::invalid(format!("reference[{i}]"), v, "finite"));
            }
        }
    }
    for (name, v) in [
        ("tolerance", o.tolerance),
        ("rotation_tolerance", o.rotation_tolerance),
        ("optimality_tolerance", o.optimality_tolerance),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(Error::invalid(name, v, "finite and > 0"));
        }
    }
    if let Some(w) = o.rotation_weight {
        if !(w.is_finite() && w > 0.0) {
            return Err(Error::invalid("rotation_weight", w, "finite and > 0 m/rad"));
        }
    }
    if o.max_iterations == 0 {
        return Err(Error::invalid("max_iterations", 0, ">= 1"));
    }
    let _ = length;
    super::check_starts(&o.starts, n)
}

pub(crate) fn check_target(target: &Target) -> Result<()> {
    if target.points.is_empty() {
        return Err(Error::invalid(
            "target_position",
            "[]",
            "at least one point",
        ));
    }
    for (k, p) in target.points.iter().enumerate() {
        // Beyond MAX_LENGTH the distance to the target would not be a number worth reporting.
        if !p
            .iter()
            .all(|v| v.is_finite() && v.abs() <= crate::limits::MAX_LENGTH)
        {
            return Err(Error::invalid(
                format!("target_position[{k}]"),
                format!("{:?}", p.as_slice()),
                format!(
                    "finite, each coordinate within ±{:e} m",
                    crate::limits::MAX_LENGTH
                ),
            ));
        }
    }
    if let Some(s) = &target.s {
        if s.len() != target.points.len() {
            return Err(Error::invalid(
                "target_s.len()",
                s.len(),
                format!("one per target point, {}", target.points.len()),
            ));
        }
    }
    if let Some(r) = &target.rotation {
        if !r.iter().all(|v| v.is_finite()) || crate::math::so3::orthonormality_error(r) > 1e-6 {
            return Err(Error::invalid(
                "target_rotation",
                format!("{r:?}"),
                "a rotation matrix (orthonormal to 1e-6, det +1)",
            ));
        }
    }
    Ok(())
}

/// The rows of the pose error and its Jacobian (scaled: positions in m, rotations times the
/// rotation weight).
fn error_rows(target: &Target, ev: &Evaluation, rotation_weight: f64) -> PoseError {
    let np = target.points.len();
    let rows = 3 * np + if target.rotation.is_some() { 3 } else { 0 };
    let mut e = DVector::zeros(rows);
    let mut dist = 0.0f64;
    for (k, p) in target.points.iter().enumerate() {
        let d = p - ev.positions[k];
        dist = dist.max(d.norm());
        e.fixed_rows_mut::<3>(3 * k).copy_from(&d);
    }
    let mut rot = 0.0;
    if let Some(rt) = &target.rotation {
        let w = log_so3(&(rt * ev.rotation.transpose()));
        rot = w.norm();
        e.fixed_rows_mut::<3>(3 * np)
            .copy_from(&(w * rotation_weight));
    }
    let jac = ev.jacobian.as_ref().map(|js| {
        let n = js[0].ncols();
        let mut a = DMatrix::zeros(rows, n);
        for k in 0..np {
            a.view_mut((3 * k, 0), (3, n))
                .copy_from(&js[k].view((0, 0), (3, n)));
        }
        if target.rotation.is_some() {
            a.view_mut((3 * np, 0), (3, n))
                .copy_from(&(js[np - 1].view((3, 0), (3, n)) * rotation_weight));
        }
        a
    });
    PoseError { e, jac, dist, rot }
}
