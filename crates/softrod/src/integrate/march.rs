//! The march of a piecewise system over the breaks of a rod: interval by interval, fixed RK4
//! steps or adaptive Dormand–Prince steps, with a jump at every interior break and an
//! observer of every node.
//!
//! The Cosserat shooting pass, the tangent compliance and (through the shooting) the
//! compliance all march with this function; they differ only in their system (state and
//! sensitivity columns) and their observer (recording nodes, seeding load columns).

use super::driver::{adaptive, fixed_in, Stages, System};
use super::tableau::{DP5, RK4};
use super::AdaptiveOptions;
use crate::error::Result;

/// A system whose right-hand side changes at the breaks `b_0 < b_1 < ...`.
pub trait Piecewise<const N: usize>: System<N> {
    /// Called before integrating the interval `[b_k, b_{k+1}]`.
    fn enter_interval(&mut self, k: usize);
    /// Applies the jump of the state across the interior break `s` (e.g. a point load).
    fn jump(&mut self, s: f64, y: &mut [f64; N]);
}

/// How each interval is integrated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scheme<'a> {
    /// Classical RK4 with the given number of equal steps per interval.
    Rk4(&'a [usize]),
    /// Adaptive Dormand–Prince 5(4), error control on the first `controlled` components.
    Adaptive {
        /// Tolerances.
        options: AdaptiveOptions,
        /// Number of leading state components under error control.
        controlled: usize,
    },
}

/// Per-interval step counts of an RK4 plan with `steps` in total: `max(1, round(steps
/// length / L))` each.
pub fn rk4_plan(breaks: &[f64], steps: usize) -> Vec<usize> {
    let l = breaks[breaks.len() - 1];
    breaks
        .windows(2)
        .map(|w| ((steps as f64 * (w[1] - w[0]) / l).round() as usize).max(1))
        .collect()
}

/// Integrates `sys` over `breaks` from `y0`, calling `node(sys, s, interval, y)` at the start
/// of every interval and after every step (`y` may be modified there, e.g. to seed a column).
/// Every point of `stops` (sorted) inside an interval ends a step there: an adaptive step is
/// cut short; with RK4 the interval is split there and its steps shared among the parts in
/// proportion to their lengths (at least one each), so a stop is a node of the mesh. With
/// an empty RK4 plan every part takes one step: a mesh anchored at the stops, which a
/// moving break changes continuously (no step count jumps).
/// Returns the state at the last break.
///
/// # Errors
/// What the driver reports (non-finite state, adaptive step failures).
pub fn march<const N: usize, Y: Piecewise<N>>(
    sys: &mut Y,
    breaks: &[f64],
    stops: &[f64],
    y0: [f64; N],
    scheme: Scheme<'_>,
    mut node: impl FnMut(&mut Y, f64, usize, &mut [f64; N]),
) -> Result<[f64; N]> {
    let mut y = y0;
    // RK4's stage buffers, allocated once for every interval.
    let mut rk4 = None;
    for k in 0..breaks.len() - 1 {
        let (a, b) = (breaks[k], breaks[k + 1]);
        sys.enter_interval(k);
        node(sys, a, k, &mut y);
        match scheme {
            Scheme::Rk4(plan) => {
                // Stops split the interval; its steps are shared in proportion to length.
                let mut start = a;
                for &stop in stops.iter().filter(|&&s| s > a && s < b).chain([&b]) {
                    let n = match plan.get(k) {
                        // (An empty plan: one step from stop to stop.)
                        None => 1,
                        Some(&steps) if stop == b && start == a => steps,
                        Some(&steps) => {
                            ((steps as f64 * (stop - start) / (b - a)).round() as usize).max(1)
                        }
                    };
                    let st = rk4.get_or_insert_with(Stages::<N, 4>::new);
                    y = fixed_in(&RK4, sys, st, (start, y), stop, n, |sys, s, y| {
                        node(sys, s, k, y);
                    })?;
                    start = stop;
                }
            }
            Scheme::Adaptive {
                options,
                controlled,
            } => {
                let mut start = a;
                for &stop in stops.iter().filter(|&&s| s > a && s < b).chain([&b]) {
                    let (end, _) = adaptive(
                        &DP5,
                        sys,
                        [start, stop],
                        y,
                        &options,
                        controlled,
                        |sys, y, step| node(sys, step.t1, k, y),
                    )?;
                    y = end;
                    start = stop;
                }
            }
        }
        if k + 2 < breaks.len() {
            sys.jump(b, &mut y);
        }
    }
    Ok(y)
}
