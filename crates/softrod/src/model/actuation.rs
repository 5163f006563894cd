//! The actuation input: what the motors and the pumps do, separate from the robot model.
//!
//! A [`RobotModel`](crate::model::RobotModel) describes the robot (rod, tendon routings,
//! chambers, external loads); an [`Actuation`] says how it is driven for one solve: per tendon
//! a [`TendonInput`] (a tension, or a held displacement of its base end; friction joins as a
//! new variant), per chamber a gauge pressure. A sweep changes the actuation and keeps the
//! model.
//!
//! # Displacement control
//! A displacement-controlled tendon is held by its motor: its base end has been pulled in by
//! the displacement `δ` (m) from the motor's zero, the configuration at zero actuation (every
//! tension and pressure zero, the model's external loads applied), where the tendon is just
//! taut. With `ℓ_ref` its path length at zero actuation and `ℓ` the current one, the path
//! shortening is `d = ℓ_ref - ℓ`, and the tendon (of axial stiffness `k`, N/m; rigid when
//! infinite) carries the tension `τ` with
//!
//! ```text
//! τ >= 0,   g = d - δ + τ / k >= 0,   τ g = 0,
//! ```
//!
//! `g` (m) being the slack: a taut tendon (`g = 0`) stretches by `δ - d = τ / k`; a slack one
//! (`τ = 0`) has more length than its path needs. The statics solve this complementarity
//! exactly (see `cosserat/shooting.rs`).

use std::sync::Arc;

use crate::error::{Error, Result};
use crate::model::chamber::check_pressure;

/// How one tendon is driven.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum TendonInput {
    /// Pulled at the base with a given tension (N, >= 0): force control.
    Tension(f64),
    /// Held by its motor at a displacement of its base end (displacement control; see the
    /// module documentation): the tension is an unknown of the solve, zero if the tendon goes
    /// slack.
    Displacement {
        /// Pull-in `δ` of the base end from the motor's zero (m; negative: paid out).
        displacement: f64,
        /// Axial stiffness `k` of the tendon from the base to its termination (N/m, > 0;
        /// `f64::INFINITY` for an inextensible tendon).
        stiffness: f64,
    },
}

impl TendonInput {
    /// The tension (N) of a tension-controlled tendon; 0 for a displacement-controlled one
    /// (its tension is an output: [`crate::StaticsSolution::tendon_tensions`]).
    pub fn tension(&self) -> f64 {
        match self {
            TendonInput::Tension(t) => *t,
            TendonInput::Displacement { .. } => 0.0,
        }
    }

    /// An inextensible tendon held at the displacement `displacement` (m).
    pub fn displacement(displacement: f64) -> Self {
        TendonInput::Displacement {
            displacement,
            stiffness: f64::INFINITY,
        }
    }

    /// Whether the tendon is displacement-controlled.
    pub fn is_held(&self) -> bool {
        matches!(self, TendonInput::Displacement { .. })
    }
}

/// Tendon inputs and chamber pressures of one configuration.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Actuation {
    /// One input per tendon of the model, in the model's order.
    pub tendons: Vec<TendonInput>,
    /// One gauge pressure per chamber of the model (Pa), in the model's order.
    pub pressures: Vec<f64>,
    /// Path lengths `ℓ_ref` (m) of the tendons at zero actuation, the zero of the
    /// displacement-controlled tendons; `None`: computed by the solve (one more solve of the
    /// model at zero actuation, a single integration without external loads).
    pub reference_lengths: Option<Vec<f64>>,
    /// First guess of the tensions (N, one per tendon) of the displacement-controlled tendons,
    /// e.g. a previous solution's `tendon_tensions`; `None`: taut where the tendon would be
    /// stretched at zero tension, from zero tension.
    pub tension_guess: Option<Vec<f64>>,
    /// The tension along the tendons when it varies (friction): `None`, every tendon carries
    /// its base tension over its whole length. Set by the frictional solve
    /// (`cosserat::friction`), which finds it with the shape.
    pub profile: Option<Arc<TensionProfile>>,
}

/// The tension along each tendon (N) at the nodes of an arc-length mesh (m), interpolated
/// geometrically between them (`ln τ` linear in `s`: exact for the capstan law on an arc).
/// A tendon without a profile carries its base tension.
#[derive(Debug, Clone, PartialEq)]
pub struct TensionProfile {
    tendons: Vec<Option<Track>>,
}

/// The profile of one tendon: nodes (m), tensions (N) and their logarithms.
#[derive(Debug, Clone, PartialEq)]
struct Track {
    s: Vec<f64>,
    tau: Vec<f64>,
    log: Vec<f64>,
}

impl TensionProfile {
    /// Per tendon: the nodes `s` (m, increasing) and the tensions there (N, >= 0), or `None`
    /// for a tendon that carries its base tension.
    pub fn new(tendons: Vec<Option<(Vec<f64>, Vec<f64>)>>) -> Self {
        Self {
            tendons: tendons
                .into_iter()
                .map(|t| {
                    t.map(|(s, tau)| {
                        let log = tau.iter().map(|t| t.ln()).collect();
                        Track { s, tau, log }
                    })
                })
                .collect(),
        }
    }

    /// Replaces the profile of tendon `i` (if it has one) by the single cell from `s[0]` to
    /// `s[1]` (m) with tensions `tau` (N) at its ends, in place (the frictional march sets
    /// one cell at a time).
    pub(crate) fn set_cell(&mut self, i: usize, s: [f64; 2], tau: [f64; 2]) {
        if let Some(Some(t)) = self.tendons.get_mut(i) {
            t.s.clear();
            t.s.extend_from_slice(&s);
            t.tau.clear();
            t.tau.extend_from_slice(&tau);
            t.log.clear();
            t.log.extend(tau.iter().map(|v| v.ln()));
        }
    }

    /// The nodes (m) and tensions (N) of tendon `i`, if it has a profile.
    pub fn tendon(&self, i: usize) -> Option<(&[f64], &[f64])> {
        let t = self.tendons.get(i)?.as_ref()?;
        Some((&t.s, &t.tau))
    }

    /// Tension (N) of tendon `i` at `s` (m): `None` if the tendon has no profile.
    #[inline]
    pub fn at(&self, i: usize, s: f64) -> Option<f64> {
        let t = self.tendons.get(i)?.as_ref()?;
        let (nodes, tau) = (&t.s, &t.tau);
        let n = nodes.len();
        if n == 1 || s <= nodes[0] {
            return Some(tau[0]);
        }
        if s >= nodes[n - 1] {
            return Some(tau[n - 1]);
        }
        let k = nodes.partition_point(|&x| x <= s).clamp(1, n - 1);
        let (a, b) = (nodes[k - 1], nodes[k]);
        let w = (s - a) / (b - a);
        let (ta, tb) = (tau[k - 1], tau[k]);
        Some(if ta > 0.0 && tb > 0.0 {
            (t.log[k - 1] + (t.log[k] - t.log[k - 1]) * w).exp()
        } else {
            ta + (tb - ta) * w
        })
    }
}

impl Actuation {
    /// Tension control of every tendon (N), no pressures.
    pub fn tensions(tensions: &[f64]) -> Self {
        Self {
            tendons: tensions.iter().map(|&t| TendonInput::Tension(t)).collect(),
            ..Self::default()
        }
    }

    /// Only chamber pressures (Pa).
    pub fn pressures(pressures: &[f64]) -> Self {
        Self {
            pressures: pressures.to_vec(),
            ..Self::default()
        }
    }

    /// Mixed tendon control: `displacements[i]` (m) holds tendon `i` at that displacement
    /// (inextensible), `NaN` leaves it tension-controlled at `tensions[i]` (N).
    pub fn mixed(tensions: &[f64], displacements: &[f64]) -> Self {
        Self {
            tendons: tensions
                .iter()
                .zip(displacements)
                .map(|(&t, &d)| {
                    if d.is_nan() {
                        TendonInput::Tension(t)
                    } else {
                        TendonInput::displacement(d)
                    }
                })
                .collect(),
            ..Self::default()
        }
    }

    /// Whether any tendon is displacement-controlled.
    pub fn has_held(&self) -> bool {
        self.tendons.iter().any(TendonInput::is_held)
    }

    /// Indices of the displacement-controlled tendons.
    pub fn held(&self) -> Vec<usize> {
        (0..self.tendons.len())
            .filter(|&i| self.tendons[i].is_held())
            .collect()
    }

    /// Zero tensions and pressures (the motors' zero).
    pub fn zero(n_tendons: usize, n_chambers: usize) -> Self {
        Self {
            tendons: vec![TendonInput::Tension(0.0); n_tendons],
            pressures: vec![0.0; n_chambers],
            ..Self::default()
        }
    }

    /// The same actuation with `pressures` (Pa).
    pub fn with_pressures(mut self, pressures: &[f64]) -> Self {
        self.pressures = pressures.to_vec();
        self
    }

    /// Tension of every tendon (N), given `n_tendons` in the model (missing inputs: 0).
    pub fn tension_values(&self, n_tendons: usize) -> Vec<f64> {
        (0..n_tendons)
            .map(|i| self.tendons.get(i).map_or(0.0, TendonInput::tension))
            .collect()
    }

    /// Pressure of every chamber (Pa), given `n_chambers` in the model (missing inputs: 0).
    pub fn pressure_values(&self, n_chambers: usize) -> Vec<f64> {
        (0..n_chambers)
            .map(|i| self.pressures.get(i).copied().unwrap_or(0.0))
            .collect()
    }

    /// Checks the inputs against a model with `n_tendons` tendons and `n_chambers` chambers:
    /// one input per actuator (or none at all: all zero), tensions finite and >= 0,
    /// displacements finite with a stiffness > 0, pressures finite and above vacuum.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `tensions.len()`, `tensions[i]`, `displacements[i]`,
    /// `tendon_stiffness[i]`, `reference_lengths[i]`, `pressures.len()` or `pressures[i]`.
    pub fn validate(&self, n_tendons: usize, n_chambers: usize) -> Result<()> {
        check_counts(
            self.tendons.len(),
            self.pressures.len(),
            n_tendons,
            n_chambers,
        )?;
        for (i, t) in self.tendons.iter().enumerate() {
            match t {
                TendonInput::Tension(v) => check_tension(i, *v)?,
                TendonInput::Displacement {
                    displacement,
                    stiffness,
                } => {
                    if !displacement.is_finite() {
                        return Err(Error::invalid(
                            format!("displacements[{i}]"),
                            displacement,
                            "finite (m)",
                        ));
                    }
                    if stiffness.is_nan() || *stiffness <= 0.0 {
                        return Err(Error::invalid(
                            format!("tendon_stiffness[{i}]"),
                            stiffness,
                            "> 0 N/m (inf: inextensible)",
                        ));
                    }
                }
            }
        }
        if let Some(g) = &self.tension_guess {
            if g.len() != n_tendons || g.iter().any(|v| !v.is_finite()) {
                return Err(Error::invalid(
                    "tension_guess",
                    format!("{g:?}"),
                    format!("{n_tendons} finite tensions (N)"),
                ));
            }
        }
        if let Some(r) = &self.reference_lengths {
            if r.len() != n_tendons {
                return Err(Error::invalid(
                    "reference_lengths.len()",
                    r.len(),
                    format!("the number of tendons, {n_tendons}"),
                ));
            }
            for (i, v) in r.iter().enumerate() {
                if !(v.is_finite() && *v > 0.0) {
                    return Err(Error::invalid(
                        format!("reference_lengths[{i}]"),
                        v,
                        "finite and > 0 m",
                    ));
                }
            }
        }
        for (i, &p) in self.pressures.iter().enumerate() {
            check_pressure(format_args!("pressures[{i}]"), p)?;
        }
        Ok(())
    }
}

/// [`Actuation::validate`] of tensions and pressures given as plain values (the PCC statics'
/// inputs), without building an [`Actuation`].
///
/// # Errors
/// [`Error::InvalidParameter`] naming `tensions.len()`, `tensions[i]`, `pressures.len()` or
/// `pressures[i]`.
pub(crate) fn validate_values(
    tensions: &[f64],
    pressures: &[f64],
    n_tendons: usize,
    n_chambers: usize,
) -> Result<()> {
    check_counts(tensions.len(), pressures.len(), n_tendons, n_chambers)?;
    for (i, &v) in tensions.iter().enumerate() {
        check_tension(i, v)?;
    }
    for (i, &p) in pressures.iter().enumerate() {
        check_pressure(format_args!("pressures[{i}]"), p)?;
    }
    Ok(())
}

/// One input per actuator, or none at all.
fn check_counts(
    tendons: usize,
    pressures: usize,
    n_tendons: usize,
    n_chambers: usize,
) -> Result<()> {
    if !(tendons == 0 || tendons == n_tendons) {
        return Err(Error::invalid(
            "tensions.len()",
            tendons,
            format!("the number of tendons, {n_tendons} (or 0 for none)"),
        ));
    }
    if !(pressures == 0 || pressures == n_chambers) {
        return Err(Error::invalid(
            "pressures.len()",
            pressures,
            format!("the number of chambers, {n_chambers} (or 0 for none)"),
        ));
    }
    Ok(())
}

/// A tension finite and >= 0 N.
#[inline]
fn check_tension(i: usize, v: f64) -> Result<()> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(
            format!("tensions[{i}]"),
            v,
            "finite and >= 0 N",
        ))
    }
}
