//! Distance between two backbones at equal *arm index* (fraction of arm length), as the planar cable-arm paper
//! compared a photographed arm with the model.
//!
//! Each backbone is a polyline of points in 2-D or 3-D, of any length (e.g. digitised from a
//! photo). Each is parametrised by its own normalised chord length `u in [0, 1]`, resampled
//! linearly at common indices, and the Euclidean distance between matching points is taken.

use crate::error::{Error, Result};

/// Pointwise distance of two backbones at equal arm index.
#[derive(Debug, Clone, PartialEq)]
pub struct BackboneDistance {
    /// Largest distance (units of the input, e.g. m).
    pub max: f64,
    /// Mean distance over the indices (units of the input).
    pub mean: f64,
    /// Arm index of the largest distance, in `[0, 1]`.
    pub argmax_index: f64,
    /// Arm indices `u` at which the backbones were compared, uniform in `[0, 1]`.
    pub index: Vec<f64>,
    /// Distance at each index (units of the input).
    pub distance: Vec<f64>,
}

/// Normalised cumulative chord length of a polyline given as `n` points of `dim` coordinates.
fn arm_index(points: &[f64], dim: usize, name: &str) -> Result<Vec<f64>> {
    let n = points.len() / dim;
    if n < 2 {
        return Err(Error::invalid(format!("{name}.shape[0]"), n, ">= 2 points"));
    }
    let max = crate::limits::MAX_LENGTH;
    if let Some(i) = points
        .iter()
        .position(|v| !(v.is_finite() && v.abs() <= max))
    {
        return Err(Error::invalid(
            format!("{name}[{}, {}]", i / dim, i % dim),
            points[i],
            format!("finite and of magnitude <= {max:e} m"),
        ));
    }
    let mut u = Vec::with_capacity(n);
    u.push(0.0);
    for i in 1..n {
        let d2: f64 = (0..dim)
            .map(|j| (points[i * dim + j] - points[(i - 1) * dim + j]).powi(2))
            .sum();
        u.push(u[i - 1] + d2.sqrt());
    }
    let total = u[n - 1];
    if total <= 0.0 {
        return Err(Error::invalid(
            format!("{name} length"),
            total,
            "> 0 (the points must not all coincide)",
        ));
    }
    for v in &mut u {
        *v /= total;
    }
    Ok(u)
}

/// Linear interpolation of the polyline at arm indices `targets` (sorted).
fn resample(points: &[f64], dim: usize, u: &[f64], targets: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(targets.len() * dim);
    let mut seg = 0usize;
    let last = u.len() - 1;
    for &t in targets {
        while seg + 1 < last && u[seg + 1] < t {
            seg += 1;
        }
        let (u0, u1) = (u[seg], u[seg + 1]);
        let w = if u1 > u0 {
            ((t - u0) / (u1 - u0)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        for j in 0..dim {
            let a = points[seg * dim + j];
            let b = points[(seg + 1) * dim + j];
            out.push(a + w * (b - a));
        }
    }
    out
}

/// Distance between backbones `a` and `b`, row-major `(n_a, dim)` and `(n_b, dim)`, compared at
/// `n_index` uniform arm indices (`None`: the larger of `n_a`, `n_b`).
///
/// # Errors
/// [`Error::InvalidParameter`] if `dim` is not 2 or 3, a point list is not a whole number of
/// points, has fewer than two points, zero length or a non-finite coordinate, or
/// `n_index < 2`.
pub fn backbone_distance(
    a: &[f64],
    b: &[f64],
    dim: usize,
    n_index: Option<usize>,
) -> Result<BackboneDistance> {
    if dim != 2 && dim != 3 {
        return Err(Error::invalid("dim", dim, "2 or 3 coordinates per point"));
    }
    for (name, p) in [("a", a), ("b", b)] {
        if p.len() % dim != 0 {
            return Err(Error::invalid(
                format!("{name}.size"),
                p.len(),
                format!("a multiple of {dim}"),
            ));
        }
    }
    let ua = arm_index(a, dim, "a")?;
    let ub = arm_index(b, dim, "b")?;
    let n = n_index.unwrap_or(ua.len().max(ub.len()));
    if n < 2 {
        return Err(Error::invalid("n_index", n, ">= 2"));
    }
    let index: Vec<f64> = (0..n).map(|i| i as f64 / (n - 1) as f64).collect();
    let ra = resample(a, dim, &ua, &index);
    let rb = resample(b, dim, &ub, &index);
    let distance: Vec<f64> = (0..n)
        .map(|i| {
            (0..dim)
                .map(|j| (ra[i * dim + j] - rb[i * dim + j]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .collect();
    let (mut imax, mut max) = (0, distance[0]);
    for (i, &d) in distance.iter().enumerate() {
        if d > max {
            (imax, max) = (i, d);
        }
    }
    let mean = distance.iter().sum::<f64>() / n as f64;
    Ok(BackboneDistance {
        max,
        mean,
        argmax_index: index[imax],
        index,
        distance,
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn translated_copy_is_at_constant_distance() {
        let a: Vec<f64> = (0..11).flat_map(|i| [i as f64 * 0.1, 0.0]).collect();
        // b: same straight line, shifted by (0, 0.3), sampled with 4 points only.
        let b = vec![0.0, 0.3, 0.2, 0.3, 0.7, 0.3, 1.0, 0.3];
        let d = backbone_distance(&a, &b, 2, None).unwrap();
        assert!((d.max - 0.3).abs() < 1e-15 && (d.mean - 0.3).abs() < 1e-15);
    }

    #[test]
    fn quarter_circle_vs_chord_at_equal_index() {
        // A straight segment and a reversed copy: distance at index u is |1 - 2u| * length.
        let a = vec![0.0, 0.0, 1.0, 0.0];
        let b = vec![1.0, 0.0, 0.0, 0.0];
        let d = backbone_distance(&a, &b, 2, Some(5)).unwrap();
        let expect = [1.0, 0.5, 0.0, 0.5, 1.0];
        for (x, e) in d.distance.iter().zip(expect) {
            assert!((x - e).abs() < 1e-15);
        }
        assert_eq!(d.max, 1.0);
        assert!((d.mean - 0.6).abs() < 1e-15);
    }

    #[test]
    fn bad_inputs_are_named() {
        let e = backbone_distance(&[0.0, 0.0], &[0.0, 0.0, 1.0, 1.0], 2, None).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { ref name, .. } if name == "a.shape[0]"));
        let e =
            backbone_distance(&[0.0, 0.0, 0.0, 0.0], &[0.0, 0.0, 1.0, 1.0], 2, None).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { ref name, .. } if name == "a length"));
        let e = backbone_distance(&[0.0, f64::NAN, 1.0, 0.0], &[0.0, 0.0, 1.0, 1.0], 2, None)
            .unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { ref name, .. } if name == "a[0, 1]"));
    }
}
