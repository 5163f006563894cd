//! Several starts of the inverse statics ([`Starts`]): the iteration is local (it finds the
//! minimum-norm actuation nearest its start; a curled arm's target may lie beyond a fold of
//! the tip's map, and antagonistic actuators can reach one point by several isolated
//! actuations), so it is run from each start and the best answer kept: the converged one of
//! least norm, else the closest.
//!
//! Spread starts are the points of a Halton sequence (the first skipped: the reference) in
//! the box of actuations that turn the tip through up to [`START_TURNS`] turns either side of
//! the reference (within the bounds), each actuator at the reference for a coordinate below
//! [`START_SLACK`] (the minimum-norm actuation leaves antagonists slack). An actuator's turn is judged from the tip's rotation per unit
//! actuation at the reference (the Jacobian of one forward evaluation there).

use std::f64::consts::TAU;

use super::problem::Program;
use super::qp::Bounds;
use super::{Forward, InverseOptions, InverseSolution, InverseWarmStart, Target};
use crate::error::{Error, Result};

/// Turns of the tip (at the reference's rate of rotation per unit actuation) spanned by each
/// actuator in the box of spread starts.
pub const START_TURNS: f64 = 5.0;
/// Fraction of the spread starts at which each actuator is at the reference (its tendon
/// slack, its chamber at ambient pressure by default).
pub const START_SLACK: f64 = 1.0 / 3.0;
/// Relative difference of the objectives of two converged answers below which they count as
/// one (the earlier start kept): the answers of two starts that reach the same minimum differ
/// by the stopping tests.
pub const SAME_OBJECTIVE: f64 = 1e-6;
/// Most starts of one inverse.
pub const MAX_STARTS: usize = 10_000;
/// Most halvings (towards the reference) of a start at which the rod cannot be
/// solved (its tendons' paths turn back on themselves).
pub const MAX_START_HALVINGS: usize = 4;

/// Where the inverse statics starts from (the `starts` option).
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Starts {
    /// From the warm start, or the reference: one local iteration.
    #[default]
    One,
    /// `k` starts (`1 <= k <=` [`MAX_STARTS`]): the warm start (or the reference), then `k - 1`
    /// actuations spread over the box of the module documentation.
    Spread(usize),
    /// The warm start (or the reference), then these actuations (tensions then pressures; N,
    /// Pa), each clamped into the bounds.
    Given(Vec<Vec<f64>>),
}

/// A check made before each start after the first ([`InverseOptions::interrupt`]): `true`
/// stops the call (e.g. a user's Ctrl-C). It is not part of the options' value: any two
/// compare equal.
#[derive(Clone, Copy, Default)]
pub struct Interrupt(pub Option<fn() -> bool>);

impl Interrupt {
    fn asked(self) -> bool {
        self.0.is_some_and(|f| f())
    }
}

impl PartialEq for Interrupt {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::fmt::Debug for Interrupt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.0.is_some() {
            "Interrupt(check)"
        } else {
            "Interrupt(none)"
        })
    }
}

/// Checks `starts` for `n` actuators.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `starts` (a count outside `1..=MAX_STARTS`) or
/// `starts[k]` (not `n` finite values).
pub(crate) fn check_starts(starts: &Starts, n: usize) -> Result<()> {
    match starts {
        Starts::One => {}
        Starts::Spread(k) => {
            if !(1..=MAX_STARTS).contains(k) {
                return Err(Error::invalid(
                    "starts",
                    k,
                    format!("a count of starts in [1, {MAX_STARTS}]"),
                ));
            }
        }
        Starts::Given(given) => {
            if given.is_empty() || given.len() >= MAX_STARTS {
                return Err(Error::invalid(
                    "starts",
                    format!("{} actuations", given.len()),
                    format!(
                        "1 to {} actuations (one start per row; {MAX_STARTS} starts with the \
                         first)",
                        MAX_STARTS - 1
                    ),
                ));
            }
            for (k, a) in given.iter().enumerate() {
                if a.len() != n || a.iter().any(|v| !v.is_finite()) {
                    return Err(Error::invalid(
                        format!("starts[{k}]"),
                        format!("{a:?}"),
                        format!("{n} finite actuation values (tensions, then pressures)"),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// The starts after the first: the given ones, and how many to spread with the tip's rates of
/// rotation at the reference (`None` where it cannot be solved: then those at the first
/// answer); the bounds, weights and centre that rank the answers.
pub(crate) struct LaterStarts {
    given: Vec<Vec<f64>>,
    spread: usize,
    rates: Option<Vec<f64>>,
    bounds: Bounds,
}

/// [`starts_on`] the forward model made by `forward` (only when there are several starts).
///
/// # Errors
/// As [`starts_on`]; `forward`'s.
pub(crate) fn later_starts<F: Forward>(
    target: &Target,
    options: &InverseOptions,
    forward: impl FnOnce() -> Result<F>,
) -> Result<Option<LaterStarts>> {
    match options.starts {
        Starts::One => Ok(None),
        _ => starts_on(&mut forward()?, target, options),
    }
}

/// The starts after the first of `options.starts` for `target` on `forward` (`None` for one
/// start). Spread starts take one forward evaluation with the Jacobian at the reference
/// (clamped into the bounds).
///
/// # Errors
/// As [`Program::new`].
pub(crate) fn starts_on<F: Forward + ?Sized>(
    forward: &mut F,
    target: &Target,
    options: &InverseOptions,
) -> Result<Option<LaterStarts>> {
    let (given, spread) = match &options.starts {
        Starts::One | Starts::Spread(0 | 1) => return Ok(None),
        Starts::Spread(k) => (Vec::new(), k - 1),
        Starts::Given(given) => (given.clone(), 0),
    };
    let p = Program::new(forward, target, options)?;
    let rates = (spread > 0).then(|| {
        let mut a = p.bounds.centre.clone();
        p.clamp(&mut a);
        forward
            .evaluate(&a, true)
            .ok()
            .map(|ev| turn_rates(ev.jacobian.as_deref().and_then(<[_]>::last)))
    });
    Ok(Some(LaterStarts {
        given,
        spread,
        rates: rates.flatten(),
        bounds: p.bounds,
    }))
}

impl LaterStarts {
    /// The actuations of the later starts, the spread ones with the rates at the reference,
    /// else those at the answer of the first start (`first`), else none.
    fn actuations(&self, first: Option<&InverseSolution>) -> Vec<Vec<f64>> {
        let mut out = self.given.clone();
        if self.spread > 0 {
            let at_first = || {
                let jacobian = first.and_then(|f| f.evaluation.jacobian.as_deref());
                turn_rates(jacobian.and_then(<[_]>::last))
            };
            let rates = self.rates.clone().unwrap_or_else(at_first);
            if !rates.is_empty() {
                out.extend(spread(&self.bounds, &rates, self.spread));
            }
        }
        out
    }
}

/// The rate of the tip's rotation (rad per unit actuation) of each actuator, from the
/// Jacobian of the pose twist (6 × n); none without a Jacobian.
fn turn_rates(jacobian: Option<&nalgebra::DMatrix<f64>>) -> Vec<f64> {
    let Some(j) = jacobian else {
        return Vec::new();
    };
    (0..j.ncols())
        .map(|i| j.view((3, i), (3, 1)).norm())
        .collect()
}

/// `count` actuations spread over the box of the module documentation: actuator `i` within
/// [`START_TURNS`] turns at `rates[i]` of the reference (clamped into the bounds) and within
/// its bounds (a rate that is zero, not finite or missing leaves it at the reference).
fn spread(bounds: &Bounds, rates: &[f64], count: usize) -> Vec<Vec<f64>> {
    let n = bounds.lo.len();
    let primes = primes(n);
    let rest = at_rest(bounds);
    let (lo, hi): (Vec<f64>, Vec<f64>) = (0..n)
        .map(|i| {
            let rate = rates.get(i).copied().unwrap_or(0.0);
            let width = if rate.is_finite() && rate > 0.0 {
                START_TURNS * TAU / rate
            } else {
                0.0
            };
            (
                bounds.lo[i].max(rest[i] - width),
                bounds.hi[i].min(rest[i] + width),
            )
        })
        .unzip();
    (1..=count)
        .map(|k| {
            (0..n)
                .map(|i| {
                    let h = radical_inverse(k, primes[i]);
                    if h < START_SLACK {
                        rest[i]
                    } else {
                        lo[i] + (h - START_SLACK) / (1.0 - START_SLACK) * (hi[i] - lo[i])
                    }
                })
                .collect()
        })
        .collect()
}

/// The reference clamped into the bounds.
fn at_rest(bounds: &Bounds) -> Vec<f64> {
    (0..bounds.lo.len())
        .map(|i| bounds.centre[i].clamp(bounds.lo[i], bounds.hi[i]))
        .collect()
}

/// The `k`-th point (`k >= 1`) of the van der Corput sequence in base `b`: the digits of `k`
/// in base `b` mirrored about the point.
fn radical_inverse(mut k: usize, b: usize) -> f64 {
    let (mut x, mut f) = (0.0, 1.0 / b as f64);
    while k > 0 {
        x += (k % b) as f64 * f;
        k /= b;
        f /= b as f64;
    }
    x
}

/// The first `n` primes (the bases of an `n`-dimensional Halton sequence).
fn primes(n: usize) -> Vec<usize> {
    let mut out: Vec<usize> = Vec::with_capacity(n);
    let mut c = 2;
    while out.len() < n {
        if out.iter().take_while(|p| *p * *p <= c).all(|p| c % p != 0) {
            out.push(c);
        }
        c += 1;
    }
    out
}

/// Whether `a` is a better answer than `b`: converged beats not; between converged answers
/// the lower objective `½ |x - c|²_W` (lower by more than [`SAME_OBJECTIVE`]); between others, reached beats not,
/// then the smaller position error, then the smaller rotation error.
fn better(a: &InverseSolution, b: &InverseSolution, bounds: &Bounds) -> bool {
    let objective = |s: &InverseSolution| -> f64 {
        s.actuation
            .iter()
            .zip(&bounds.centre)
            .zip(&bounds.weights)
            .map(|((x, c), w)| 0.5 * w * (x - c) * (x - c))
            .sum()
    };
    match (a.converged, b.converged) {
        (true, false) => true,
        (false, true) => false,
        (true, true) => objective(a) < (1.0 - SAME_OBJECTIVE) * objective(b),
        (false, false) => {
            (a.reached, -a.position_error, -a.rotation_error)
                > (b.reached, -b.position_error, -b.rotation_error)
        }
    }
}

/// One inverse `run` (with the options and the warm start given; it returns the answer and
/// what comes with it, e.g. its forward model) from each start of `options.starts`: the
/// first from `warm`, the `later` ones each from its actuation (halved towards the
/// reference, at most [`MAX_START_HALVINGS`] times, where the rod cannot be solved there). A
/// start whose run fails is passed over. The best answer ([`better`]) is returned, its
/// `start` the index of its start (0: the first).
///
/// # Errors
/// The first start's error if every start fails; with `options.throw`, for the best answer
/// not converged, the error of its start's run with `options` (as from that start alone);
/// [`Error::NotConverged`] (interrupted) when `options.interrupt` asks to stop.
pub(crate) fn over_starts<T>(
    options: &InverseOptions,
    warm: Option<&InverseWarmStart>,
    later: Option<LaterStarts>,
    mut run: impl FnMut(&InverseOptions, Option<&InverseWarmStart>) -> Result<(InverseSolution, T)>,
) -> Result<(InverseSolution, T)> {
    let Some(later) = later else {
        return run(options, warm);
    };
    let quiet = InverseOptions {
        throw: false,
        ..options.clone()
    };
    // The best answer so far and the start it came from (`None`: `warm`); the first start's
    // error until a start is solved.
    let mut best = run(&quiet, warm).map(|out| (out, None));
    let starts = later.actuations(best.as_ref().ok().map(|((out, _), _)| out));
    let count = starts.len() + 1;
    for (k, start) in starts.into_iter().enumerate() {
        if options.interrupt.asked() {
            let solved = best.as_ref().ok().map(|((b, _), _)| b);
            return Err(Error::NotConverged {
                what: format!(
                    "inverse statics: interrupted after {} of {count} starts",
                    k + 1
                ),
                iterations: solved.map_or(0, |b| b.iterations),
                residual: solved.map_or(f64::NAN, |b| b.position_error),
                load_factor: 1.0,
            });
        }
        let Some((mut out, with, from)) = run_from(&mut run, &quiet, &later.bounds, start) else {
            continue;
        };
        out.start = k + 1;
        if best
            .as_ref()
            .map_or(true, |((b, _), _)| better(&out, b, &later.bounds))
        {
            best = Ok(((out, with), Some(from)));
        }
    }
    let (best, from) = best?;
    if options.throw && !best.0.converged {
        // Its own error, as the call from that start alone raises it.
        let start = best.0.start;
        let (mut out, with) = run(options, from.as_ref().or(warm))?;
        out.start = start;
        return Ok((out, with));
    }
    Ok(best)
}

/// `run` from the actuation `start` (clamped into `bounds`), halved towards the reference
/// where the rod cannot be solved there; the answer and the start it came from, `None` if it
/// fails.
fn run_from<T>(
    run: &mut impl FnMut(&InverseOptions, Option<&InverseWarmStart>) -> Result<(InverseSolution, T)>,
    options: &InverseOptions,
    bounds: &Bounds,
    mut start: Vec<f64>,
) -> Option<(InverseSolution, T, InverseWarmStart)> {
    for (x, (lo, hi)) in start.iter_mut().zip(bounds.lo.iter().zip(&bounds.hi)) {
        *x = x.clamp(*lo, *hi);
    }
    let rest = at_rest(bounds);
    for _ in 0..=MAX_START_HALVINGS {
        let from = InverseWarmStart::actuation(start.clone());
        match run(options, Some(&from)) {
            Ok((out, with)) => return Some((out, with, from)),
            Err(e) if e.names("warm_start") => {
                for (x, r) in start.iter_mut().zip(&rest) {
                    *x = r + 0.5 * (*x - r);
                }
            }
            Err(_) => return None,
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_van_der_corput_points_mirror_the_digits() {
        // Base 2: 1 -> 0.1b, 2 -> 0.01b, 3 -> 0.11b, 6 = 110b -> 0.011b; base 3: 5 = 12 -> 0.21.
        for (k, b, x) in [
            (1, 2, 0.5),
            (2, 2, 0.25),
            (3, 2, 0.75),
            (6, 2, 0.375),
            (1, 3, 1.0 / 3.0),
            (5, 3, 2.0 / 3.0 + 1.0 / 9.0),
        ] {
            assert!((radical_inverse(k, b) - x).abs() < 1e-15, "{k} {b}");
        }
        assert_eq!(primes(6), vec![2, 3, 5, 7, 11, 13]);
    }

    #[test]
    fn spread_starts_span_the_turns_within_the_bounds() {
        let bounds = Bounds {
            lo: vec![0.5, 0.0, -1e5],
            hi: vec![f64::INFINITY, 1.0, f64::INFINITY],
            weights: vec![1.0; 3],
            centre: vec![0.0; 3],
        };
        // Rates (rad per unit): START_TURNS turns take START_TURNS τ / 2 units of actuator 0
        // (from its lower bound 0.5, the reference 0 clamped), START_TURNS τ / 20 of actuator 1
        // (capped at 1), START_TURNS τ / 1e-4 Pa of the chamber either side of ambient (capped
        // at -1e5 Pa below).
        let rates = [2.0, 20.0, 1e-4];
        let width = |rate: f64| START_TURNS * TAU / rate;
        let starts = spread(&bounds, &rates, 500);
        let rest = [0.5, 0.0, 0.0];
        let mut slack = [0; 3];
        for s in &starts {
            assert!(s[0] >= 0.5 && s[0] <= 0.5 + width(2.0));
            assert!(s[1] >= 0.0 && s[1] <= 1.0 && width(20.0) > 1.0);
            assert!(s[2] >= -1e5 && s[2] <= width(1e-4));
            for i in 0..3 {
                slack[i] += usize::from(s[i] == rest[i]);
            }
        }
        // A third of the points at the reference (the sequence is equidistributed).
        for n in slack {
            assert!((n as f64 / 500.0 - START_SLACK).abs() < 0.01, "{slack:?}");
        }
        // The extreme values come close to the ends of the box.
        let top = starts.iter().map(|s| s[0]).fold(0.0, f64::max);
        assert!(top > 0.5 + 0.99 * width(2.0));
        let bottom = starts.iter().map(|s| s[2]).fold(0.0, f64::min);
        assert!(bottom < -0.95e5);
        // No rate: at the reference.
        assert!(spread(&bounds, &[], 4).iter().all(|s| s == &rest));
    }
}
