//! Fitting uniaxial material laws to tensile (or compression) test data.
//!
//! Neo-Hookean, Mooney–Rivlin, Yeoh and the linearised law are linear in their coefficients at
//! a given stretch, so their least-squares fit is solved exactly (SVD of the column-scaled
//! design matrix); with [`FitOptions::nonnegative`] it becomes a non-negative least-squares
//! problem, solved exactly by enumerating the active sets (at most 2³ for three coefficients).
//! Ogden laws are nonlinear in their exponents: they start from the best point of a grid of
//! exponents (moduli solved linearly at each) and are polished by Levenberg–Marquardt with the
//! analytic Jacobian and Marquardt's diagonal scaling.
//!
//! Residuals are `model(λ_i) − stress_i` in the stress measure of the data (Pa), unweighted.
//!
//! # References
//! * D. W. Marquardt, "An algorithm for least-squares estimation of nonlinear parameters",
//!   SIAM J. Appl. Math. 11(2), 1963.
//! * C. L. Lawson, R. J. Hanson, *Solving Least Squares Problems*, Prentice-Hall 1974, ch. 23
//!   (non-negative least squares: the solution is the unconstrained solution on its passive set).
//! * R. W. Ogden, G. Saccomandi, I. Sgura, "Fitting hyperelastic models to experimental data",
//!   Comput. Mech. 34, 2004 (non-uniqueness of Ogden fits).

use nalgebra::{DMatrix, DVector};

use crate::error::{check_positive, Error, Result};
use crate::model::material::hyperelastic::{
    check_stretch, ogden_term, Linearised, MooneyRivlin, NeoHookean, Ogden, UniaxialLaw,
    UniaxialModel, Yeoh,
};

/// How the strain column of a data set is expressed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StrainMeasure {
    /// Stretch `λ = l / l0`.
    Stretch,
    /// Engineering strain `ε = λ − 1` (a fraction, not %).
    Engineering,
    /// Logarithmic ("true", Hencky) strain `ln λ`.
    Logarithmic,
}

/// How the stress column of a data set is expressed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StressMeasure {
    /// Nominal (engineering) stress: force / undeformed area (Pa).
    Nominal,
    /// True (Cauchy) stress: force / deformed area (Pa).
    True,
}

/// Uniaxial test data: stretches and stresses (validated, stretches > 0, all finite).
#[derive(Debug, Clone, PartialEq)]
pub struct UniaxialData {
    stretch: Vec<f64>,
    stress: Vec<f64>,
    measure: StressMeasure,
}

impl UniaxialData {
    /// Data from a strain column `strain` (in `strain_measure`) and a stress column `stress`
    /// (Pa, in `stress_measure`), both of shape `[n]`, `n >= 1`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `stress` if the lengths differ or are zero, or
    /// `strain[i]` / `stress[i]` if a value is not finite or gives a stretch `<= 0`.
    pub fn new(
        strain: &[f64],
        strain_measure: StrainMeasure,
        stress: &[f64],
        stress_measure: StressMeasure,
    ) -> Result<Self> {
        if strain.is_empty() || strain.len() != stress.len() {
            return Err(Error::invalid(
                "stress",
                format!("{} values (strain has {})", stress.len(), strain.len()),
                "as many values as strain, at least one",
            ));
        }
        let mut stretch = Vec::with_capacity(strain.len());
        for (i, (&e, &s)) in strain.iter().zip(stress).enumerate() {
            let l = match strain_measure {
                StrainMeasure::Stretch => e,
                StrainMeasure::Engineering => 1.0 + e,
                StrainMeasure::Logarithmic => e.exp(),
            };
            if !(e.is_finite() && l.is_finite() && l > 0.0) {
                return Err(Error::invalid(
                    format!("strain[{i}]"),
                    e,
                    format!("finite, giving a stretch > 0 ({strain_measure:?} measure)"),
                ));
            }
            if !(s.is_finite() && s.abs() <= crate::limits::MAX_MODULUS) {
                return Err(Error::invalid(
                    format!("stress[{i}]"),
                    s,
                    format!(
                        "finite and of magnitude <= {:e} Pa",
                        crate::limits::MAX_MODULUS
                    ),
                ));
            }
            if l.is_nan() || l > crate::model::material::hyperelastic::INVERSE_STRETCH_MAX {
                return Err(Error::invalid(
                    format!("strain[{i}]"),
                    e,
                    format!(
                        "giving a stretch <= {:e} ({strain_measure:?} measure)",
                        crate::model::material::hyperelastic::INVERSE_STRETCH_MAX
                    ),
                ));
            }
            stretch.push(l);
        }
        Ok(Self {
            stretch,
            stress: stress.to_vec(),
            measure: stress_measure,
        })
    }

    /// The points with `stretch_min <= λ <= stretch_max`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `stretch_min` / `stretch_max` if not finite and `> 0`,
    /// or `stretch_max` if no point is left.
    pub fn within(&self, stretch_min: f64, stretch_max: f64) -> Result<Self> {
        let lo = check_stretch("stretch_min", stretch_min)?;
        let hi = check_stretch("stretch_max", stretch_max)?;
        let (stretch, stress): (Vec<f64>, Vec<f64>) = self
            .stretch
            .iter()
            .zip(&self.stress)
            .filter(|(&l, _)| l >= lo && l <= hi)
            .map(|(&l, &s)| (l, s))
            .unzip();
        if stretch.is_empty() {
            return Err(Error::invalid(
                "stretch_max",
                hi,
                format!("a range [{lo}, {hi}] containing data points"),
            ));
        }
        Ok(Self {
            stretch,
            stress,
            measure: self.measure,
        })
    }

    /// Stretches `λ_i` (shape `[n]`).
    pub fn stretch(&self) -> &[f64] {
        &self.stretch
    }

    /// Stresses (Pa, shape `[n]`), in [`measure`](Self::measure).
    pub fn stress(&self) -> &[f64] {
        &self.stress
    }

    /// Stress measure of [`stress`](Self::stress).
    pub fn measure(&self) -> StressMeasure {
        self.measure
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.stretch.len()
    }

    /// Whether there are no points (never true for a constructed data set).
    pub fn is_empty(&self) -> bool {
        self.stretch.is_empty()
    }

    /// Largest stretch of the data.
    pub fn stretch_max(&self) -> f64 {
        self.stretch
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Smallest stretch of the data.
    pub fn stretch_min(&self) -> f64 {
        self.stretch.iter().copied().fold(f64::INFINITY, f64::min)
    }
}

/// Which law to fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelKind {
    /// A line through the origin, `P = E_l (λ − 1)`; returns a [`Linearised`] law whose
    /// reference strain is the data's largest `|ε|`.
    Linearised,
    /// [`NeoHookean`] (`mu`).
    NeoHookean,
    /// [`MooneyRivlin`] (`c10`, `c01`).
    MooneyRivlin,
    /// [`Yeoh`] with `terms` = 1, 2 or 3 coefficients (the others are zero).
    Yeoh {
        /// Number of coefficients, 1 to 3.
        terms: usize,
    },
    /// [`Ogden`] with `terms` = 1 to [`MAX_OGDEN_TERMS`] pairs `(μ_p, α_p)`. The fit is a local
    /// minimum from several starts and is not unique: without `nonnegative`, two terms may
    /// merge into nearly equal exponents with huge opposite moduli (a good fit that
    /// extrapolates badly); check the result with [`UniaxialLaw::check_stable`].
    Ogden {
        /// Number of terms.
        terms: usize,
    },
}

/// Largest number of Ogden terms [`fit_uniaxial`] accepts.
pub const MAX_OGDEN_TERMS: usize = 3;

/// Exponents tried for each Ogden term to start Levenberg–Marquardt.
pub const OGDEN_ALPHA_GRID: [f64; 18] = [
    -10.0, -8.0, -6.0, -4.0, -3.0, -2.0, -1.0, -0.5, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0,
    10.0,
];

/// Residual norm, relative to the data norm, below which an Ogden fit is taken as exact.
const EXACT_FIT: f64 = 1e-13;

/// Range of the Levenberg–Marquardt damping (relative to the diagonal of `JᵀJ`); no acceptable
/// step at the largest damping means a minimum to round-off.
const LM_DAMPING_MIN: f64 = 1e-9;
const LM_DAMPING_MAX: f64 = 1e12;

/// Smallest `|α|` an Ogden exponent may take during Levenberg–Marquardt.
const OGDEN_ALPHA_MIN: f64 = 1e-6;

/// Relative singular-value cut-off of the linear least-squares solve.
const SVD_RCOND: f64 = 1e-13;

/// Options of [`fit_uniaxial`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitOptions {
    /// Constrain the coefficients: every coefficient `>= 0` (for Ogden the moduli `μ_p >= 0`,
    /// Ogden's condition `μ_p α_p > 0` in his original convention). Default `false`. An Ogden
    /// term whose modulus ends at zero is inactive (its exponent is then meaningless).
    pub nonnegative: bool,
    /// Levenberg–Marquardt iteration cap per start (Ogden only). Default 200.
    pub max_iterations: usize,
    /// Levenberg–Marquardt stops at a stationary point: when the cosine between the residual
    /// vector and every Jacobian column is below this, or a lightly damped step changes every
    /// exponent by less than this fraction or the sum of squares by less than 1 % of it
    /// (Ogden only). Default 1e-10.
    pub tolerance: f64,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            nonnegative: false,
            max_iterations: 200,
            tolerance: 1e-10,
        }
    }
}

/// Goodness of fit of a law on a data set (residuals in Pa, in the data's stress measure).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitStats {
    /// Root-mean-square residual (Pa).
    pub rms: f64,
    /// Coefficient of determination `1 − SS_res / SS_tot`.
    pub r_squared: f64,
    /// Largest absolute residual (Pa).
    pub max_abs_residual: f64,
    /// Number of points.
    pub points: usize,
}

/// A fitted law and its error.
#[derive(Debug, Clone, PartialEq)]
pub struct UniaxialFit {
    /// The fitted law.
    pub model: UniaxialModel,
    /// Its error on the data.
    pub stats: FitStats,
    /// Levenberg–Marquardt iterations (0 for the exact linear solves).
    pub iterations: usize,
}

/// Goodness of fit of `law` on `data`.
pub fn fit_stats(law: &dyn UniaxialLaw, data: &UniaxialData) -> FitStats {
    let n = data.len();
    let mean = data.stress.iter().sum::<f64>() / n as f64;
    let (mut ss_res, mut ss_tot, mut max_abs) = (0.0, 0.0, 0.0_f64);
    for (&l, &s) in data.stretch.iter().zip(&data.stress) {
        let r = model_stress(law, l, data.measure) - s;
        ss_res += r * r;
        ss_tot += (s - mean) * (s - mean);
        max_abs = max_abs.max(r.abs());
    }
    FitStats {
        rms: (ss_res / n as f64).sqrt(),
        r_squared: if ss_tot > 0.0 {
            1.0 - ss_res / ss_tot
        } else {
            f64::NAN
        },
        max_abs_residual: max_abs,
        points: n,
    }
}

fn model_stress(law: &dyn UniaxialLaw, stretch: f64, measure: StressMeasure) -> f64 {
    match measure {
        StressMeasure::Nominal => law.nominal_stress_unchecked(stretch),
        StressMeasure::True => law.true_stress_unchecked(stretch),
    }
}

/// Fits a law of kind `kind` to `data` by least squares.
///
/// # Errors
/// * [`Error::InvalidParameter`] naming `terms` if out of range, `data` if it has fewer points
///   than the law has parameters or if the best fit is not a valid law (the message names the
///   fitted coefficient, e.g. `c10`, and its value: data that soften so much that the initial
///   modulus comes out negative; try `nonnegative`), `options.max_iterations` /
///   `options.tolerance` if invalid.
/// * [`Error::NotConverged`] if Levenberg–Marquardt reaches `max_iterations`, or a linear
///   solve fails.
pub fn fit_uniaxial(
    data: &UniaxialData,
    kind: ModelKind,
    options: &FitOptions,
) -> Result<UniaxialFit> {
    if options.max_iterations == 0 {
        return Err(Error::invalid("options.max_iterations", 0, ">= 1"));
    }
    check_positive("options.tolerance", options.tolerance, "")?;
    let n_params = match kind {
        ModelKind::Linearised | ModelKind::NeoHookean => 1,
        ModelKind::MooneyRivlin => 2,
        ModelKind::Yeoh { terms } => {
            if !(1..=3).contains(&terms) {
                return Err(Error::invalid("terms", terms, "1, 2 or 3 for Yeoh"));
            }
            terms
        }
        ModelKind::Ogden { terms } => {
            if !(1..=MAX_OGDEN_TERMS).contains(&terms) {
                return Err(Error::invalid(
                    "terms",
                    terms,
                    format!("1 to {MAX_OGDEN_TERMS} for Ogden"),
                ));
            }
            2 * terms
        }
    };
    if data.len() < n_params {
        return Err(Error::invalid(
            "data",
            format!("{} points", data.len()),
            format!("at least {n_params} points for {kind:?}"),
        ));
    }
    let measure_factor = |l: f64| match data.measure {
        StressMeasure::Nominal => 1.0,
        StressMeasure::True => l,
    };
    // Nominal-stress basis functions of the linear-in-parameter laws.
    let g = |l: f64| 2.0 * (l - 1.0 / (l * l)); // 2 (λ − 1/λ²)
    let fitted: Result<(UniaxialModel, usize)> = (|| {
        Ok(match kind {
            ModelKind::Linearised => {
                let c = linear_fit(data, 1, options.nonnegative, |i, _| {
                    let l = data.stretch[i];
                    (l - 1.0) * measure_factor(l)
                })?;
                let reference = data.stretch.iter().map(|l| l - 1.0).fold(0.0_f64, |a, e| {
                    if e.abs() > a.abs() {
                        e
                    } else {
                        a
                    }
                });
                (Linearised::new(c[0], reference)?.into(), 0)
            }
            ModelKind::NeoHookean => {
                let c = linear_fit(data, 1, options.nonnegative, |i, _| {
                    let l = data.stretch[i];
                    0.5 * g(l) * measure_factor(l)
                })?;
                (NeoHookean::new(c[0])?.into(), 0)
            }
            ModelKind::MooneyRivlin => {
                let c = linear_fit(data, 2, options.nonnegative, |i, k| {
                    let l = data.stretch[i];
                    g(l) * if k == 0 { 1.0 } else { 1.0 / l } * measure_factor(l)
                })?;
                (MooneyRivlin::new(c[0], c[1])?.into(), 0)
            }
            ModelKind::Yeoh { terms } => {
                let c = linear_fit(data, terms, options.nonnegative, |i, k| {
                    let l = data.stretch[i];
                    let x = (l - 1.0) * (l - 1.0) * (l + 2.0) / l;
                    g(l) * (k as f64 + 1.0) * x.powi(k as i32) * measure_factor(l)
                })?;
                let coef = |k: usize| c.get(k).copied().unwrap_or(0.0);
                (Yeoh::new(coef(0), coef(1), coef(2))?.into(), 0)
            }
            ModelKind::Ogden { terms } => {
                let (law, it) = fit_ogden(data, terms, options)?;
                (law.into(), it)
            }
        })
    })();
    let (model, iterations) = fitted.map_err(|e| not_physical(e, data, kind))?;
    let stats = fit_stats(model.as_law(), data);
    Ok(UniaxialFit {
        model,
        stats,
        iterations,
    })
}

/// The law's name as the Python API spells it (`"yeoh"`, `"mooney-rivlin"`, ...).
fn law_name(kind: ModelKind) -> &'static str {
    match kind {
        ModelKind::Linearised => "linearised",
        ModelKind::NeoHookean => "neo-hookean",
        ModelKind::MooneyRivlin => "mooney-rivlin",
        ModelKind::Yeoh { .. } => "yeoh",
        ModelKind::Ogden { .. } => "ogden",
    }
}

/// A law's refusal of its fitted coefficient (`InvalidParameter` naming e.g. `c10`) said as
/// what it is: data this law cannot fit, naming `data` (the coefficient is a result, not an
/// input); any other error unchanged.
fn not_physical(e: Error, data: &UniaxialData, kind: ModelKind) -> Error {
    let Some((name, value, expected)) = e.parameter() else {
        return e;
    };
    let (lo, hi) = data
        .stretch
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &l| {
            (a.min(l), b.max(l))
        });
    let law = law_name(kind);
    let other = if law == "neo-hookean" {
        "linearised"
    } else {
        "neo-hookean"
    };
    Error::invalid(
        "data",
        format!("{} points, stretch {lo:.4} to {hi:.4}", data.len()),
        format!(
            "data the {law} law can fit: its least-squares fitted coefficient {name} = {value} \
             is not physical ({name} must be {expected}); give more data (more points, a wider \
             stretch range), fit with nonnegative coefficients, or fit another law (e.g. \
             {other})"
        ),
    )
}

/// Least squares `stress_i ≈ Σ_k c_k basis(i, k)`, optionally with `c >= 0` (exact NNLS by
/// active-set enumeration; `k <= 3`).
fn linear_fit(
    data: &UniaxialData,
    k: usize,
    nonnegative: bool,
    basis: impl Fn(usize, usize) -> f64,
) -> Result<Vec<f64>> {
    let n = data.len();
    let a = DMatrix::from_fn(n, k, &basis);
    let b = DVector::from_column_slice(&data.stress);
    if !nonnegative {
        return solve_columns(&a, &b, &(0..k).collect::<Vec<_>>(), k);
    }
    let mut best: Option<(f64, Vec<f64>)> = None;
    for mask in 0..(1usize << k) {
        let cols: Vec<usize> = (0..k).filter(|j| mask & (1 << j) != 0).collect();
        let c = if cols.is_empty() {
            vec![0.0; k]
        } else {
            solve_columns(&a, &b, &cols, k)?
        };
        if c.iter().any(|&v| v < 0.0) {
            continue;
        }
        let r = &a * DVector::from_column_slice(&c) - &b;
        let sse = r.norm_squared();
        if best.as_ref().is_none_or(|(s, _)| sse < *s) {
            best = Some((sse, c));
        }
    }
    // The empty set (all zeros) is always feasible.
    Ok(best.map(|(_, c)| c).unwrap_or_else(|| vec![0.0; k]))
}

/// Unconstrained least squares on the columns `cols` of `a` (others fixed at zero), with the
/// columns scaled to unit norm; returns the full coefficient vector of length `k`.
fn solve_columns(a: &DMatrix<f64>, b: &DVector<f64>, cols: &[usize], k: usize) -> Result<Vec<f64>> {
    let n = a.nrows();
    let scales: Vec<f64> = cols
        .iter()
        .map(|&j| {
            let s = a.column(j).norm();
            if s > 0.0 {
                s
            } else {
                1.0
            }
        })
        .collect();
    let sub = DMatrix::from_fn(n, cols.len(), |i, j| a[(i, cols[j])] / scales[j]);
    if !sub.iter().chain(b.iter()).all(|v| v.is_finite()) {
        // E.g. an Ogden exponent so large that λ^α overflows; the SVD must not see it.
        return Err(Error::not_converged(
            "least-squares solve (non-finite design matrix)",
            0,
            f64::NAN,
        ));
    }
    let svd = sub.svd(true, true);
    let max_sv = svd.singular_values.max();
    let x = svd
        .solve(b, SVD_RCOND * max_sv)
        .map_err(|msg| Error::not_converged(format!("least-squares solve ({msg})"), 0, f64::NAN))?;
    let mut c = vec![0.0; k];
    for (j, &col) in cols.iter().enumerate() {
        c[col] = x[j] / scales[j];
    }
    Ok(c)
}

/// Ogden fit: grid start over exponents, then Levenberg–Marquardt on the exponents alone with
/// the moduli eliminated by (non-negative) linear least squares at every step (variable
/// projection, with Kaufman's Jacobian).
///
/// # References
/// G. H. Golub, V. Pereyra, "Separable nonlinear least squares: the variable projection method
/// and its applications", Inverse Problems 19, 2003; L. Kaufman, BIT 15, 1975.
fn fit_ogden(data: &UniaxialData, terms: usize, options: &FitOptions) -> Result<(Ogden, usize)> {
    let n = data.len();
    let logs: Vec<f64> = data.stretch.iter().map(|l| l.ln()).collect();
    let factor: Vec<f64> = data
        .stretch
        .iter()
        .map(|&l| match data.measure {
            StressMeasure::Nominal => 1.0 / l,
            StressMeasure::True => 1.0,
        })
        .collect();
    // Stress of one term per unit μ: 2 f(α, ln λ) × (1/λ for nominal).
    let unit = |alpha: f64, i: usize| 2.0 * ogden_term(alpha, logs[i]).0 * factor[i];
    let y = DVector::from_column_slice(&data.stress);
    // Moduli and sum of squares at given exponents.
    let solve_mu = |alpha: &[f64]| -> Result<(Vec<f64>, f64)> {
        let mu = linear_fit(data, terms, options.nonnegative, |i, k| unit(alpha[k], i))?;
        let a = DMatrix::from_fn(n, terms, |i, k| unit(alpha[k], i));
        let cost = (a * DVector::from_column_slice(&mu) - &y).norm_squared();
        Ok((mu, cost))
    };

    // 1. Grid start: exponents from the grid (strictly increasing across terms).
    let grid = &OGDEN_ALPHA_GRID;
    let mut starts: Vec<(f64, Vec<f64>, Vec<f64>)> = Vec::new();
    let mut idx: Vec<usize> = (0..terms).collect();
    loop {
        let alpha: Vec<f64> = idx.iter().map(|&i| grid[i]).collect();
        if let Ok((mu, c)) = solve_mu(&alpha) {
            if c.is_finite() {
                starts.push((c, mu, alpha));
            }
        }
        // Next strictly increasing index tuple, or stop.
        let Some(p) = (0..terms)
            .rev()
            .find(|&p| idx[p] < grid.len() - (terms - p))
        else {
            break;
        };
        idx[p] += 1;
        for q in p + 1..terms {
            idx[q] = idx[q - 1] + 1;
        }
    }
    if starts.is_empty() {
        return Err(Error::not_converged("Ogden grid start", 0, f64::NAN));
    }
    starts.sort_by(|a, b| a.0.total_cmp(&b.0));
    // The best few, plus the best of each sign pattern (number of negative exponents): the
    // best grid points are often neighbours, all heading for the same merged-exponent valley.
    let mut chosen: Vec<(f64, Vec<f64>, Vec<f64>)> = Vec::new();
    for negatives in 0..=terms {
        chosen.extend(
            starts
                .iter()
                .filter(|s| s.2.iter().filter(|&&a| a < 0.0).count() == negatives)
                .take(OGDEN_STARTS_PER_PATTERN)
                .cloned(),
        );
    }
    for s in &starts {
        if chosen.len() >= OGDEN_STARTS + (terms + 1) * OGDEN_STARTS_PER_PATTERN {
            break;
        }
        if !chosen.iter().any(|c| c.2 == s.2) {
            chosen.push(s.clone());
        }
    }
    let starts = chosen;

    // 2. Levenberg–Marquardt from the best starts; keep the lowest converged minimum.
    let mut best: Option<(f64, Vec<f64>, Vec<f64>, usize)> = None;
    let mut last_error = None;
    for (c0, mu, alpha) in starts {
        match ogden_lm(
            data,
            terms,
            options,
            &solve_mu,
            &unit,
            (&logs, &factor),
            (c0, mu, alpha),
        ) {
            Ok((c, mu, alpha, it)) => {
                if best.as_ref().is_none_or(|b| c < b.0) {
                    best = Some((c, mu, alpha, it));
                }
            }
            Err(e) => last_error = Some(e),
        }
    }
    match (best, last_error) {
        (Some((_, mu, alpha, it)), _) => Ok((Ogden::new(&mu, &alpha)?, it)),
        (None, Some(e)) => Err(e),
        (None, None) => Err(Error::not_converged("Ogden fit", 0, f64::NAN)),
    }
}

/// Number of best grid points [`fit_uniaxial`] starts Ogden's Levenberg–Marquardt from, besides
/// the best [`OGDEN_STARTS_PER_PATTERN`] points of each sign pattern of the exponents.
const OGDEN_STARTS: usize = 4;

/// Starts taken from each sign pattern (number of negative exponents) of the Ogden grid.
const OGDEN_STARTS_PER_PATTERN: usize = 3;

/// Moduli and sum of squares of an Ogden fit at given exponents.
type MuSolver<'a> = dyn Fn(&[f64]) -> Result<(Vec<f64>, f64)> + 'a;

/// One variable-projection Levenberg–Marquardt run from `start = (cost, μ, α)`; returns the
/// final `(cost, μ, α, iterations)`.
fn ogden_lm(
    data: &UniaxialData,
    terms: usize,
    options: &FitOptions,
    solve_mu: &MuSolver<'_>,
    unit: &dyn Fn(f64, usize) -> f64,
    (logs, factor): (&[f64], &[f64]),
    start: (f64, Vec<f64>, Vec<f64>),
) -> Result<(f64, Vec<f64>, Vec<f64>, usize)> {
    let n = data.len();
    let y = DVector::from_column_slice(&data.stress);
    let (mut c0, mut mu, mut alpha) = start;
    let mut damping = 1e-3;
    let mut iterations = 0;
    let mut converged = false;
    while iterations < options.max_iterations {
        iterations += 1;
        // Residual, and Kaufman's Jacobian P⊥ (∂A/∂α_j) μ_j, P⊥ the projector off the columns
        // of A with non-zero moduli.
        let a = DMatrix::from_fn(n, terms, |i, k| unit(alpha[k], i));
        let res = &a * DVector::from_column_slice(&mu) - &y;
        let passive: Vec<usize> = (0..terms).filter(|&k| mu[k] != 0.0).collect();
        let basis = if passive.is_empty() {
            None
        } else {
            let sub = DMatrix::from_fn(n, passive.len(), |i, j| a[(i, passive[j])]);
            let svd = sub.svd(true, false);
            let tol = SVD_RCOND * svd.singular_values.max();
            let rank = svd.singular_values.iter().filter(|&&v| v > tol).count();
            svd.u.map(|u| u.columns(0, rank).into_owned())
        };
        let mut jac = DMatrix::<f64>::zeros(n, terms);
        for k in 0..terms {
            let mut v = DVector::from_fn(n, |i, _| {
                2.0 * mu[k] * ogden_term(alpha[k], logs[i]).1 * factor[i]
            });
            if let Some(u) = &basis {
                let coef = u.transpose() * &v;
                v -= u * coef;
            }
            jac.set_column(k, &v);
        }
        let jtj = jac.transpose() * &jac;
        let jtr = jac.transpose() * &res;
        // Stationary point: the residual is (numerically) orthogonal to every Jacobian column,
        // or the fit is exact.
        let res_norm = res.norm();
        let cosine = (0..terms)
            .map(|k| jtr[k].abs() / (jac.column(k).norm() * res_norm).max(f64::MIN_POSITIVE))
            .fold(0.0, f64::max);
        if cosine <= options.tolerance || res_norm <= EXACT_FIT * y.norm() {
            converged = true;
            break;
        }
        let mut accepted = false;
        while damping <= LM_DAMPING_MAX {
            let mut lhs = jtj.clone();
            for d in 0..terms {
                lhs[(d, d)] += damping * jtj[(d, d)].max(f64::MIN_POSITIVE);
            }
            let Some(chol) = lhs.cholesky() else {
                damping *= 10.0;
                continue;
            };
            let step = chol.solve(&(-&jtr));
            let alpha_new: Vec<f64> = (0..terms)
                .map(|k| {
                    let a = alpha[k] + step[k];
                    // Keep each exponent on its side of zero.
                    if a * alpha[k] > 0.0 && a.abs() >= OGDEN_ALPHA_MIN {
                        a
                    } else {
                        alpha[k].signum() * OGDEN_ALPHA_MIN.max(0.5 * alpha[k].abs())
                    }
                })
                .collect();
            if let Ok((mu_new, c1)) = solve_mu(&alpha_new) {
                if c1.is_finite() && c1 <= c0 {
                    let decrease = (c0 - c1) / c0.max(f64::MIN_POSITIVE);
                    let moved = alpha_new
                        .iter()
                        .zip(&alpha)
                        .map(|(a, b)| (a - b).abs() / b.abs())
                        .fold(0.0, f64::max);
                    mu = mu_new;
                    alpha = alpha_new;
                    c0 = c1;
                    // A tiny step only means convergence when it is (nearly) a Gauss–Newton
                    // step, not one shortened by heavy damping.
                    converged = damping <= 1.0
                        && (moved < options.tolerance || decrease < options.tolerance * 1e-2);
                    damping = (damping / 3.0).max(LM_DAMPING_MIN);
                    accepted = true;
                    break;
                }
            }
            damping *= 10.0;
        }
        if !accepted {
            // No step lowers the cost at any damping: a (local) minimum to round-off.
            converged = true;
        }
        if converged {
            break;
        }
    }
    if !converged {
        return Err(Error::not_converged(
            format!("Ogden ({terms} terms) Levenberg-Marquardt fit"),
            iterations,
            (c0 / n as f64).sqrt(),
        ));
    }
    Ok((c0, mu, alpha, iterations))
}
