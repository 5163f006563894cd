//! The arc functions of constant-curvature kinematics and statics, with their derivatives.
//!
//! With `θ` the bending angle and `x = θ²`: `S = sin θ/θ`, `B = (1 - cos θ)/θ²`,
//! `C = (θ - sin θ)/θ³`, and their first (and for `S`, `B` second) derivatives in `x`. Below
//! [`SERIES_BOUND`] every function is summed from its Taylor series (no cancellation at a
//! straight segment); above it the closed forms lose at most `~1e-14` relative. The PCC
//! kinematics ([`crate::pcc`]) and the PCC statics use these functions and nothing else.

/// `θ²` (rad²) below which the arc functions are summed as series (13 terms: error below
/// `1e-20` for `θ² < 1`); above it the closed forms of the values lose at most `~1e-15`
/// relative, those of the second derivatives `~1e-13`. The series is also the cheaper way
/// below it (no sine and cosine, no division).
pub const SERIES_BOUND: f64 = 1.0;
/// Number of series terms.
pub const SERIES_TERMS: usize = 13;

// ---------------------------------------------------------------------------------------------

/// `S = sin θ/θ`, `B = (1 - cos θ)/θ²`, `C = (θ - sin θ)/θ³` and their derivatives in `x = θ²`.
#[derive(Debug, Clone, Copy)]
pub struct ArcFns {
    /// `S = sin θ/θ`.
    pub s: f64,
    /// `dS/dx`.
    pub s1: f64,
    /// `d²S/dx²`.
    pub s2: f64,
    /// `B = (1 - cos θ)/θ²`.
    pub b: f64,
    /// `dB/dx`.
    pub b1: f64,
    /// `d²B/dx²`.
    pub b2: f64,
    /// `C = (θ - sin θ)/θ³`.
    pub c: f64,
    /// `dC/dx`.
    pub c1: f64,
}

/// Coefficients `(-1)^k / (2k + n)!` of the series of `S` (`n = 1`), `B` (2) and `C` (3).
const fn series_coefficients(n: u32) -> [f64; SERIES_TERMS] {
    let mut c = [0.0; SERIES_TERMS];
    let mut fact = 1.0;
    let mut i = 2;
    while i <= n {
        fact *= i as f64;
        i += 1;
    }
    c[0] = 1.0 / fact;
    let mut k = 1;
    while k < SERIES_TERMS {
        let m = (2 * k as u32 + n) as f64;
        c[k] = -c[k - 1] / ((m - 1.0) * m);
        k += 1;
    }
    c
}

const SERIES_S: [f64; SERIES_TERMS] = series_coefficients(1);
const SERIES_B: [f64; SERIES_TERMS] = series_coefficients(2);
const SERIES_C: [f64; SERIES_TERMS] = series_coefficients(3);

/// `Σ_k c_k x^k` and its first two derivatives, by Horner's rule.
#[inline]
fn series(c: &[f64; SERIES_TERMS], x: f64) -> (f64, f64, f64) {
    let (mut f, mut f1, mut f2) = (0.0, 0.0, 0.0);
    for k in (0..SERIES_TERMS).rev() {
        let kf = k as f64;
        f = f * x + c[k];
        if k >= 1 {
            f1 = f1 * x + kf * c[k];
        }
        if k >= 2 {
            f2 = f2 * x + kf * (kf - 1.0) * c[k];
        }
    }
    (f, f1, f2)
}

/// `S`, `B`, `C` and their derivatives at `x = θ²`.
#[inline]
pub fn arc_fns(x: f64) -> ArcFns {
    if x < SERIES_BOUND {
        let (s, s1, s2) = series(&SERIES_S, x);
        let (b, b1, b2) = series(&SERIES_B, x);
        let (c, c1, _) = series(&SERIES_C, x);
        return ArcFns {
            s,
            s1,
            s2,
            b,
            b1,
            b2,
            c,
            c1,
        };
    }
    let th = x.sqrt();
    let (sh, ch) = (0.5 * th).sin_cos();
    let (sn, cs) = (2.0 * sh * ch, 1.0 - 2.0 * sh * sh);
    let ix = 1.0 / x;
    let s = sn / th;
    let s1 = 0.5 * (cs - s) * ix;
    let s2 = 0.5 * (-0.5 * s - 3.0 * s1) * ix;
    // 1 - cos θ = 2 sin²(θ/2): accurate also near full turns.
    let b = 2.0 * sh * sh * ix;
    let b1 = (0.5 * s - b) * ix;
    let b2 = (0.5 * s1 - 2.0 * b1) * ix;
    let c = (1.0 - s) * ix;
    let c1 = (-s1 - c) * ix;
    ArcFns {
        s,
        s1,
        s2,
        b,
        b1,
        b2,
        c,
        c1,
    }
}

/// `dS/dx` alone (the tip Jacobian of an arc needs nothing else), from the same series and
/// closed forms.
#[inline]
pub fn arc_s1(x: f64) -> f64 {
    if x < SERIES_BOUND {
        let c = &SERIES_S[1..POSE_TERMS + 1];
        // d/dx Σ c_k x^k = Σ k c_k x^(k-1).
        return c
            .iter()
            .enumerate()
            .rev()
            .fold(0.0, |f, (k, ck)| f * x + (k + 1) as f64 * ck);
    }
    let th = x.sqrt();
    let (sn, cs) = th.sin_cos();
    0.5 * (cs - sn / th) / x
}

/// Terms of the `S` and `B` series of [`arc_sb`] and [`arc_s1`]: the first neglected one is
/// below `3e-19` relative for `x < 1`.
const POSE_TERMS: usize = 10;

/// `Σ_k c_k x^k` by Horner's rule.
#[inline]
fn poly(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |f, ck| f * x + ck)
}

/// `(S, B)` only (poses need nothing else), from the same series and closed forms.
#[inline]
pub fn arc_sb(x: f64) -> (f64, f64) {
    if x < SERIES_BOUND {
        return (
            poly(&SERIES_S[..POSE_TERMS], x),
            poly(&SERIES_B[..POSE_TERMS], x),
        );
    }
    let th = x.sqrt();
    let (sh, ch) = (0.5 * th).sin_cos();
    (2.0 * sh * ch / th, 2.0 * sh * sh / x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn series_and_closed_forms_agree_at_the_bound_and_derivatives_are_consistent() {
        // The series at the bound against the closed forms there.
        let x = SERIES_BOUND;
        let th = x.sqrt();
        assert!((series(&SERIES_S, x).0 - th.sin() / th).abs() < 1e-15);
        let half = (0.5 * th).sin();
        assert!((series(&SERIES_B, x).0 - 2.0 * half * half / x).abs() < 1e-15);
        // θ - sin θ cancels: the closed form of C is good to ~1e-13 at the bound.
        assert!((series(&SERIES_C, x).0 - (th - th.sin()) / (th * x)).abs() < 1e-12);
        // Central differences of S, B, C in x at a few points on both sides of the bound.
        for x in [0.001f64, 0.005, 0.3, 2.0, 9.0] {
            let h = 1e-5 * x.max(1e-3);
            let (p, m, f) = (arc_fns(x + h), arc_fns(x - h), arc_fns(x));
            assert!(((p.s - m.s) / (2.0 * h) - f.s1).abs() < 1e-8);
            assert!(((p.b - m.b) / (2.0 * h) - f.b1).abs() < 1e-8);
            assert!(((p.c - m.c) / (2.0 * h) - f.c1).abs() < 1e-8);
            assert!(((p.s1 - m.s1) / (2.0 * h) - f.s2).abs() < 1e-7);
            assert!(((p.b1 - m.b1) / (2.0 * h) - f.b2).abs() < 1e-7);
            let th = x.sqrt();
            assert!((f.s - th.sin() / th).abs() < 1e-15);
            let half = (0.5 * th).sin();
            assert!((f.b - 2.0 * half * half / x).abs() < 1e-15);
            let (s, b) = arc_sb(x);
            assert!((s - f.s).abs() < 1e-16 && (b - f.b).abs() < 1e-16);
            assert!((arc_s1(x) - f.s1).abs() < 1e-15);
        }
    }
}
