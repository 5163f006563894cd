//! Arc-length samples: uniform grids that end exactly at the length, and the one check of
//! user-given arc lengths against `[0, length]` (up to round-off).

use crate::error::{Error, Result};
use crate::limits::{check_count, MAX_SAMPLES};

/// Relative round-off (of the length) accepted at the ends of `[0, length]`: a user's arc
/// length computed from the same data in another order (a sum of segment lengths, `n` times a
/// spacing) may differ from the model's by a few units in the last place. Such a value is
/// clamped to the end, never extrapolated.
pub const ARC_LENGTH_ROUNDOFF: f64 = 8.0 * f64::EPSILON;

/// `n_points` uniformly spaced arc lengths over `[0, length]` (m); the first is exactly 0 and
/// the last exactly `length`.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `n_points` unless in `[2, MAX_SAMPLES]`.
pub fn uniform_samples(length: f64, n_points: usize) -> Result<Vec<f64>> {
    check_count("n_points", n_points, 2, MAX_SAMPLES)?;
    let last = (n_points - 1) as f64;
    Ok((0..n_points)
        .map(|i| {
            if i + 1 == n_points {
                length
            } else {
                length * i as f64 / last
            }
        })
        .collect())
}

/// The arc length `s` (m) of `name` checked against `[0, length]` and clamped into it when it
/// is outside by at most [`ARC_LENGTH_ROUNDOFF`] of the length.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name` if `s` is not finite or further outside.
#[inline]
pub fn in_range(name: impl FnOnce() -> String, s: f64, length: f64) -> Result<f64> {
    let slack = ARC_LENGTH_ROUNDOFF * length.abs();
    if s.is_finite() && s >= -slack && s <= length + slack {
        Ok(s.clamp(0.0, length))
    } else {
        Err(Error::invalid(
            name(),
            s,
            format!("finite and in [0, length] = [0, {length}] m"),
        ))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn uniform_samples_end_exactly_at_the_length() {
        for n in 2..300 {
            for &l in &[
                0.3999255676570448,
                0.18266621280548284,
                1.0 / 3.0,
                0.1 + 0.2,
            ] {
                let s = uniform_samples(l, n).unwrap();
                assert_eq!((s[0], s[n - 1], s.len()), (0.0, l, n));
                assert!(s.windows(2).all(|w| w[0] < w[1]));
            }
        }
        assert!(uniform_samples(1.0, 1).is_err());
        assert!(uniform_samples(1.0, MAX_SAMPLES + 1).is_err());
    }

    #[test]
    fn round_off_at_the_ends_is_clamped_and_anything_else_named() {
        let l = 0.3999255676570448;
        let above = 0.39992556765704484;
        assert_eq!(in_range(|| "s".into(), above, l), Ok(l));
        assert_eq!(in_range(|| "s".into(), -1e-18, l), Ok(0.0));
        assert_eq!(in_range(|| "s".into(), 0.2, l), Ok(0.2));
        for bad in [l * (1.0 + 1e-12), -1e-9, f64::NAN, f64::INFINITY] {
            let e = in_range(|| "s[3]".into(), bad, l).unwrap_err();
            assert!(matches!(e, Error::InvalidParameter { ref name, .. } if name == "s[3]"));
        }
    }
}
