//! The limits on input sizes and magnitudes, in one place.
//!
//! Every count that sizes an allocation or a loop, and every load or actuation, is checked
//! against these before anything is allocated or solved; the error names the parameter, its
//! value and the limit (see `docs/conventions.md`, "The error model").
//!
//! - Sizes: outputs sampled along a rod ([`MAX_SAMPLES`]) and iteration caps
//!   ([`MAX_ITERATIONS`]).
//! - Loads: a load is measured by its *load number*, the load over the rod's own bending
//!   scale: a force `F` by `F L² / EI`, a moment `M` by `M L / EI`, a distributed force `f` by
//!   `f L³ / EI`, a distributed moment `l` by `l L² / EI`, with `L` the rod length and `EI` the
//!   bending stiffness at the base. A load number of 1 bends the rod by about a radian (a tip
//!   force at `F L² / EI = 1000` already winds an elastica into loops); [`MAX_LOAD_NUMBER`] is
//!   nine orders of magnitude above that, so no physical load is refused, while the scaled
//!   residual of the solvers (loads over `EI / L²` and `EI / L`), its square and its
//!   Jacobian stay far from overflow.
//! - Materials: [`MAX_MODULUS`], [`MAX_DENSITY`].
//! - Geometry: [`MAX_LENGTH`], [`MAX_BENDING_ANGLE`], and for tendon routings
//!   [`MAX_OFFSET_RATIO`].
//! - Friction: [`MAX_FRICTION`].
//! - Scenes: [`MAX_OBSTACLES`].

use crate::error::{Error, Result};

/// Largest number of samples one call returns or integrates over (`n_points`, `panels`,
/// `n_index`, ...): 100 000 samples space a 0.1 m rod at 1 µm.
pub const MAX_SAMPLES: usize = 100_000;

/// Largest iteration cap of an iterative solver (Newton iterations, load steps, adaptive
/// integration steps, fitting iterations).
pub const MAX_ITERATIONS: usize = 10_000_000;

/// Largest load number of any load or actuation (see the module documentation).
pub const MAX_LOAD_NUMBER: f64 = 1e12;

/// Largest length of a rod, an arm or a PCC segment (m): 1 000 km, far beyond any robot, and
/// small enough that the length's square, cube and fourth power (stiffness and load scales,
/// Jacobians) stay finite.
pub const MAX_LENGTH: f64 = 1e6;

/// Largest bending angle `|κ| ℓ` of one PCC arc given by the user (rad), about 160 000 turns:
/// beyond it an arc's pose is no longer a meaningful function of its parameters (the square of
/// the angle enters the arc series).
pub const MAX_BENDING_ANGLE: f64 = 1e6;

/// Largest elastic modulus or material parameter (Pa): ten times the Young's modulus of
/// diamond. Softer materials span nine orders of magnitude below it; the stiffness of a
/// section (a modulus times a fourth power of its radius) stays finite.
pub const MAX_MODULUS: f64 = 1e13;

/// Largest mass density of a rod (kg/m³): 44 times that of osmium, the densest element.
pub const MAX_DENSITY: f64 = 1e6;

/// Largest Coulomb friction coefficient (dimensionless) of a tendon in its channel, at its
/// guides, or at an obstacle. Measured tendon-sheath and contact coefficients lie between
/// about 0.05 and 1; at 10 the capstan factor `e^(μθ)` of one turn is 5e27, and far larger
/// values overflow it (a coefficient of 1e308 reported a normal force of 3e-309 N).
pub const MAX_FRICTION: f64 = 10.0;

/// Checks a Coulomb friction coefficient: finite, `>= 0` and at most [`MAX_FRICTION`].
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name`.
pub fn check_friction(name: &str, mu: f64) -> Result<f64> {
    if mu.is_finite() && (0.0..=MAX_FRICTION).contains(&mu) {
        Ok(mu)
    } else {
        Err(Error::invalid(
            name,
            mu,
            format!("in [0, {MAX_FRICTION}] (a Coulomb coefficient, dimensionless)"),
        ))
    }
}

/// Most obstacles of one solve. Each is searched at every node of every march; a scene of
/// many shapes is one triangle mesh (a mesh counts once, whatever its triangles). 2,000 copies
/// of one sphere ran for minutes and gigabytes before this bound.
pub const MAX_OBSTACLES: usize = 256;

/// Largest distance of a tendon (or a PCC chamber) from the backbone, as a fraction of the rod
/// length.
///
/// A tendon may run outside the section (through spacer disks, as on a thin superelastic
/// backbone: 10 mm on a 0.7 mm rod); a rod model still needs the guides of its tendons smaller
/// than the rod is long. A tendon farther from the backbone than the whole length of the rod
/// (0.5 m on a 0.4 m robot) describes no slender robot.
pub const MAX_OFFSET_RATIO: f64 = 1.0;

/// Checks a count: `min <= value <= max`.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name` otherwise.
pub fn check_count(name: &str, value: usize, min: usize, max: usize) -> Result<usize> {
    if (min..=max).contains(&value) {
        Ok(value)
    } else {
        Err(Error::invalid(name, value, format!("in [{min}, {max}]")))
    }
}

/// Checks a length (m): finite, > 0 (or >= 0 with `allow_zero`) and at most [`MAX_LENGTH`].
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name` otherwise.
pub fn check_length(name: &str, value: f64, allow_zero: bool) -> Result<f64> {
    let low_ok = if allow_zero {
        value >= 0.0
    } else {
        value > 0.0
    };
    if value.is_finite() && low_ok && value <= MAX_LENGTH {
        Ok(value)
    } else {
        let low = if allow_zero { ">= 0" } else { "> 0" };
        Err(Error::invalid(
            name,
            value,
            format!("finite, {low} and <= {MAX_LENGTH:e} m"),
        ))
    }
}

/// Checks an elastic modulus (Pa): finite, > 0 and at most [`MAX_MODULUS`].
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name` otherwise.
pub fn check_modulus(name: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 && value <= MAX_MODULUS {
        Ok(value)
    } else {
        Err(Error::invalid(
            name,
            value,
            format!("finite, > 0 and <= {MAX_MODULUS:e} Pa"),
        ))
    }
}

/// Checks a material parameter that may have either sign (Pa): finite and of magnitude at
/// most [`MAX_MODULUS`].
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name` otherwise.
pub fn check_parameter(name: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value.abs() <= MAX_MODULUS {
        Ok(value)
    } else {
        Err(Error::invalid(
            name,
            value,
            format!("finite and of magnitude <= {MAX_MODULUS:e} Pa"),
        ))
    }
}

/// Checks a load magnitude against [`MAX_LOAD_NUMBER`]: `magnitude / scale` must not exceed
/// it, where `scale` is the load that has load number 1 (`EI / L²` for a force, ...).
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name`, with the largest magnitude in `unit`. The name
/// is formatted only on error (pass `format_args!` for an indexed one: no allocation on the
/// way of every solve).
#[inline]
pub fn check_load(
    name: impl std::fmt::Display,
    value: f64,
    magnitude: f64,
    scale: f64,
    unit: &str,
) -> Result<()> {
    let max = MAX_LOAD_NUMBER * scale;
    if magnitude.is_finite() && magnitude <= max {
        Ok(())
    } else {
        Err(load_error(&name, value, max, unit))
    }
}

/// The error of [`check_load`] (off the path of every solve).
#[cold]
fn load_error(name: &dyn std::fmt::Display, value: f64, max: f64, unit: &str) -> Error {
    Error::invalid(
        name.to_string(),
        value,
        format!(
            "finite and of magnitude <= {max:.3e} {unit} (load number <= {MAX_LOAD_NUMBER:e}, \
             see softrod's limits)"
        ),
    )
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn counts_and_loads_name_their_parameter() {
        assert_eq!(check_count("n", 5, 2, 10), Ok(5));
        let e = check_count("n_points", 1 << 40, 2, MAX_SAMPLES).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { ref name, .. } if name == "n_points"));
        assert!(check_load("t", 1.0, 1.0, 1.0, "N").is_ok());
        assert!(check_load("t", 1e308, 1e308, 1.0, "N").is_err());
        assert!(check_load("t", f64::NAN, f64::NAN, 1.0, "N").is_err());
    }
}
