//! The one error type of the core crate.
//!
//! Every fallible public function returns [`Result<T>`]. The binding maps
//! [`Error::InvalidParameter`] to a `ValueError` subclass and
//! [`Error::NotConverged`] to a `RuntimeError` subclass (and [`Error::TargetUnreachable`] to a
//! subclass of that), in one place.

use thiserror::Error;

/// Errors raised by the softrod core.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum Error {
    /// A parameter is outside its valid range (or not finite).
    #[error("invalid parameter `{name}` = {value}: must be {expected}")]
    InvalidParameter {
        /// Name of the parameter, as the user spells it (e.g. `"tip_radius"`).
        name: String,
        /// The offending value, formatted for the message.
        value: String,
        /// The valid range, in words (e.g. `"finite and > 0 m"`).
        expected: String,
    },
    /// An iterative solver or an adaptive integrator did not reach its tolerance.
    #[error(
        "{what} did not converge after {iterations} iterations (residual {residual:.3e}{})",
        load_factor_note(*.load_factor)
    )]
    NotConverged {
        /// What did not converge, and why it stopped (e.g. `"shooting Newton (Cosserat rod
        /// statics): the load steps ran out"`).
        what: String,
        /// Iterations (or steps) taken before giving up.
        iterations: usize,
        /// Residual norm (or error estimate) at the last iterate.
        residual: f64,
        /// Fraction of the external loads carried by the last iterate: the last load factor
        /// reached by a load continuation, 1 where the full problem was attempted directly
        /// (and for solvers without load steps).
        load_factor: f64,
    },
    /// Inverse statics: the target cannot be reached within the actuation bounds; the closest
    /// reachable pose found is this far from it.
    #[error(
        "target out of reach: the closest pose found is {distance:.3e} m (and {rotation:.3e} rad) \
         from it after {iterations} iterations"
    )]
    TargetUnreachable {
        /// Remaining distance to the target position (m; the largest over the points of a
        /// shape target).
        distance: f64,
        /// Remaining rotation to the target orientation (rad; 0 without one).
        rotation: f64,
        /// Iterations taken.
        iterations: usize,
    },
}

/// The load factor in a convergence message, when it is not the full load.
fn load_factor_note(load_factor: f64) -> String {
    if load_factor < 1.0 {
        format!(" at load factor {load_factor:.4}, the last load carried")
    } else {
        String::new()
    }
}

/// Result alias used throughout the crate.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// An [`Error::NotConverged`] of a solver without load steps (load factor 1).
    pub fn not_converged(what: impl Into<String>, iterations: usize, residual: f64) -> Self {
        Error::NotConverged {
            what: what.into(),
            iterations,
            residual,
            load_factor: 1.0,
        }
    }

    /// The name, value and valid range of an [`Error::InvalidParameter`].
    pub fn parameter(&self) -> Option<(&str, &str, &str)> {
        match self {
            Error::InvalidParameter {
                name,
                value,
                expected,
            } => Some((name, value, expected)),
            _ => None,
        }
    }

    /// The same error with the parameter name of an [`Error::InvalidParameter`] mapped by `f`
    /// (an entry of an array argument, a prefix); other errors unchanged.
    #[must_use]
    pub fn map_name(self, f: impl FnOnce(String) -> String) -> Self {
        match self {
            Error::InvalidParameter {
                name,
                value,
                expected,
            } => Error::InvalidParameter {
                name: f(name),
                value,
                expected,
            },
            other => other,
        }
    }

    /// Whether this is an [`Error::InvalidParameter`] naming `parameter`.
    pub fn names(&self, parameter: &str) -> bool {
        self.parameter()
            .is_some_and(|(name, _, _)| name == parameter)
    }

    /// Builds an [`Error::InvalidParameter`] from any displayable value.
    pub fn invalid(
        name: impl Into<String>,
        value: impl std::fmt::Display,
        expected: impl Into<String>,
    ) -> Self {
        let mut value = value.to_string();
        // A huge or tiny float prints as hundreds of digits: show it in scientific notation.
        if value.len() > 24 {
            if let Ok(v) = value.parse::<f64>() {
                value = format!("{v:e}");
            }
        }
        Error::InvalidParameter {
            name: name.into(),
            value,
            expected: expected.into(),
        }
    }
}

/// Checks that `value` is finite and strictly positive.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name` otherwise.
pub fn check_positive(name: &str, value: f64, unit: &str) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::invalid(
            name,
            value,
            format!("finite and > 0 {unit}"),
        ))
    }
}

/// Checks that `value` is finite and non-negative.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name` otherwise.
pub fn check_non_negative(name: &str, value: f64, unit: &str) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(Error::invalid(
            name,
            value,
            format!("finite and >= 0 {unit}"),
        ))
    }
}

/// Checks that `value` is finite.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name` otherwise.
pub fn check_finite(name: &str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::invalid(name, value, "finite"))
    }
}

#[cfg(test)]
mod tests {
    use super::Error;

    /// Below full load, the residual is that of the last load carried (a continuation that
    /// carried none reads "residual 0 at load factor 0", not a residual of the full load).
    #[test]
    fn a_convergence_message_names_the_load_its_residual_is_at() {
        let at = |load_factor| {
            Error::NotConverged {
                what: "shooting Newton".into(),
                iterations: 6,
                residual: 0.0,
                load_factor,
            }
            .to_string()
        };
        assert_eq!(
            at(0.25),
            "shooting Newton did not converge after 6 iterations (residual 0.000e0 at load \
             factor 0.2500, the last load carried)"
        );
        assert_eq!(
            at(1.0),
            "shooting Newton did not converge after 6 iterations (residual 0.000e0)"
        );
    }
}
