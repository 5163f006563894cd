//! Tendon displacement control: the complementarity of the held tendons, solved exactly by an
//! active set over the shooting problem.
//!
//! Each displacement-controlled tendon `h` (see [`crate::model::actuation`]) satisfies
//! `τ_h >= 0`, `g_h = ℓ_ref,h - ℓ_h - δ_h + τ_h / k_h >= 0`, `τ_h g_h = 0`. For a guess of which
//! held tendons are taut (`g_h = 0`, tension unknown) and which are slack (`τ_h = 0`), the
//! equilibrium is a smooth shooting problem with the taut tensions as extra unknowns and
//! their slack as extra residual rows (`cosserat/shooting.rs`), solved by the same Newton and
//! load continuation as every statics solve. Then the guess is checked: a taut tendon whose
//! tension came out negative is released, a slack tendon whose slack came out negative
//! (stretched) is taken up, and the problem is solved again from the last state, until no
//! tendon changes (the primal-dual active-set strategy; it stops because each tendon's status
//! is decided by the sign of a smooth function of the others). The result satisfies the
//! complementarity exactly: slack tendons carry exactly zero tension, taut ones meet their
//! displacement to the shooting tolerance.
//!
//! The first guess: the tendons a previous solution held taut ([`Actuation::tension_guess`]),
//! or those that would be stretched if every held tendon carried no tension (one march of the
//! actuated, unloaded rod).
//!
//! The zero of the displacements, `ℓ_ref`, is the tendons' path lengths at zero actuation under
//! the model's external loads ([`reference_lengths`]), unless the actuation gives it.
//!
//! Inextensible held tendons can leave their tensions undetermined: four tendons 90° apart
//! take on tension in the proportions `[1, -1, 1, -1]` without moving the rod or changing their
//! lengths, and any tendons on a rod that cannot stretch take on equal tensions. The solve
//! then names `displacements` with the tendons and the pattern (a singular value of the held
//! problem's Jacobian below 1e-8 of the largest), rather than returning one of the
//! many tensions or failing to converge; a tendon stiffness determines them.

use std::sync::Arc;

use nalgebra::DMatrix;

use super::sensitivity::slack_scale;
use super::shooting::{Held, Shooting};
use super::statics::{
    assemble, Integrator, SolveOptions, StaticsSolution, WarmStart, DIRECT_STEP_LIMIT,
};
use crate::error::{Error, Result};
use crate::integrate::march::rk4_plan;
use crate::model::{Actuation, RobotModel, TendonInput};
use crate::solve::{
    continuation, max_norm, newton, ContinuationSettings, Evaluated, NewtonOutcome, NewtonSettings,
    Problem, SolverStats,
};

/// Most rounds of the active set (changes of the taut set) per held tendon, plus a few.
pub const MAX_ACTIVE_SET_ROUNDS_PER_TENDON: usize = 3;

/// Path length of every tendon at zero actuation (all tensions and pressures zero) under the
/// model's external loads, with `options`' integrator (m): the zero of the displacements.
/// A tendon routed through guides has the length of its polyline of chords through its
/// anchors on the zero-actuation shape (what a guided solution reports as its
/// `tendon_lengths`, [`super::solve_frictional`]).
///
/// # Errors
/// As [`super::statics::solve_statics`] for the zero-actuation solve (and
/// [`super::solve_frictional`] for it with guided tendons).
pub fn reference_lengths(model: &Arc<RobotModel>, options: &SolveOptions) -> Result<Vec<f64>> {
    let zero = Actuation::zero(model.tendons().len(), model.chambers().len());
    let opts = SolveOptions {
        warm_start: None,
        newton: crate::solve::NewtonOptions {
            throw: true,
            ..options.newton
        },
        ..*options
    };
    let mut lengths = super::statics::solve_statics(model, &zero, &opts)?.tendon_lengths;
    let tendons = model.tendons();
    if tendons.iter().any(crate::model::tendon::Tendon::is_guided) {
        // The chords through the anchors on the same (zero-actuation) shape: no tendon
        // pulls, so the guided solve is one rod solve.
        let fo = super::friction::FrictionOptions {
            statics: opts,
            ..Default::default()
        };
        let chords = super::friction::solve_frictional(model, &zero, &fo, None)?;
        for (i, t) in tendons.iter().enumerate() {
            if t.is_guided() {
                lengths[i] = chords.statics.tendon_lengths[i];
            }
        }
    }
    Ok(lengths)
}

/// One held tendon: its index, `ℓ_ref - δ` (m), compliance (m/N), slack scale (m).
pub(super) fn held_of(model: &RobotModel, actuation: &Actuation, reference: &[f64]) -> Vec<Held> {
    actuation
        .tendons
        .iter()
        .enumerate()
        .filter_map(|(i, t)| match *t {
            TendonInput::Displacement {
                displacement,
                stiffness,
            } => {
                let compliance = 1.0 / stiffness;
                Some(Held {
                    tendon: i,
                    target: reference[i] - displacement,
                    compliance,
                    scale: slack_scale(model, i, compliance),
                })
            }
            TendonInput::Tension(_) => None,
        })
        .collect()
}

/// The shooting's Newton settings ([`super::statics::settings`]) without a given Jacobian or
/// an exact one at the solution.
fn settings(broyden: bool) -> NewtonSettings<'static> {
    super::statics::settings(broyden, None, false)
}

/// Solves the smooth problem of the current taut set from `z0`: directly at full load when
/// `warm`, else at zero load (where the base wrench is zero) and then at full load, directly
/// or by continuation.
fn smooth(
    p: &mut Shooting<'_>,
    z0: &[f64],
    options: &SolveOptions,
    warm: bool,
    stats: &mut SolverStats,
) -> NewtonOutcome {
    let opts = &options.newton;
    let broyden = matches!(options.integrator, Integrator::Rk4 { .. });
    let limit = opts.continuation.then_some(DIRECT_STEP_LIMIT);
    let unloaded = p.eq.model.loads().is_unloaded();
    stats.load_factor = 1.0;
    if warm || unloaded {
        let s = NewtonSettings {
            first_step_limit: if unloaded { None } else { limit },
            ..settings(broyden)
        };
        let out = newton(p, z0, 1.0, opts, &s);
        stats.iterations += out.iterations;
        if out.converged || unloaded {
            return out;
        }
    }
    let mut z = z0.to_vec();
    z[..6].fill(0.0);
    let out0 = newton(p, &z, 0.0, opts, &settings(broyden));
    stats.iterations += out0.iterations;
    if !out0.converged {
        stats.load_factor = 0.0;
        return out0;
    }
    let s = NewtonSettings {
        first_step_limit: limit,
        jacobian: out0.jacobian.as_deref(),
        ..settings(broyden)
    };
    let out1 = newton(p, &out0.x, 1.0, opts, &s);
    stats.iterations += out1.iterations;
    if out1.converged || !opts.continuation {
        return out1;
    }
    let start = ContinuationSettings {
        x0: &out0.x,
        jacobian0: out0.jacobian.as_deref(),
        first_increment: 0.25,
        max_increment: 0.5,
    };
    let s = NewtonSettings {
        first_step_limit: Some(DIRECT_STEP_LIMIT),
        ..settings(broyden)
    };
    let c = continuation(p, &start, opts, &s);
    stats.iterations += c.iterations;
    stats.load_steps += c.steps;
    stats.load_factor = c.load_factor;
    c.outcome
}

/// The statics of `model` under an actuation with displacement-controlled tendons (see the
/// module documentation).
///
/// # Errors
/// As [`super::statics::solve_statics`]; [`Error::NotConverged`] naming the active set if it
/// does not settle.
pub(crate) fn solve_held(
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &SolveOptions,
    s_out: &[f64],
) -> Result<StaticsSolution> {
    let mut sol = solve_held_on_mesh(model, actuation, options)?;
    let loaded = !model.loads().is_unloaded();
    sol.stable = !loaded && sol.stats.converged;
    if (loaded || !s_out.is_empty()) && sol.stats.converged {
        // The same equilibrium under tension control at the solved tensions (a warm-started
        // direct solve): its nodes at `s_out`, and its stability, which is sufficient for the
        // held tendons (holding a tendon only adds a constraint).
        let act = Actuation {
            tendons: sol
                .tendon_tensions
                .iter()
                .map(|&t| TendonInput::Tension(t))
                .collect(),
            pressures: actuation.pressures.clone(),
            reference_lengths: None,
            tension_guess: None,
            profile: None,
        };
        let opts = SolveOptions {
            warm_start: Some(WarmStart::wrench(sol.base_wrench)),
            ..*options
        };
        let fixed = super::statics::solve_statics_at(model, &act, &opts, s_out)?;
        if s_out.is_empty() {
            sol.stable = fixed.stable;
            if let Some(m) = fixed.margin.get() {
                let _ = sol.margin.set(*m);
            }
        } else {
            let (actuation, stats, lengths, tensions) = (
                sol.actuation.clone(),
                sol.stats,
                sol.tendon_lengths.clone(),
                sol.tendon_tensions.clone(),
            );
            sol = fixed;
            sol.actuation = actuation;
            sol.stats = stats;
            sol.tendon_lengths = lengths;
            sol.tendon_tensions = tensions;
        }
    }
    Ok(sol)
}

/// One displacement-controlled solve: the model, its actuation and options, the zero of the
/// displacements and the held tendons.
struct HeldProblem<'a> {
    model: &'a Arc<RobotModel>,
    actuation: &'a Actuation,
    options: &'a SolveOptions,
    /// Path lengths at zero actuation (m), the zero of the displacements.
    reference: Vec<f64>,
    /// Every displacement-controlled tendon.
    all_held: Vec<Held>,
}

/// The state of the active set between rounds.
struct HeldState {
    /// Tensions of every tendon (N): the inputs, and the held ones as solved.
    tensions: Vec<f64>,
    /// Per held tendon, whether it is taut in the current guess.
    taut: Vec<bool>,
    /// The scaled base wrench of the last solve (the start of the next).
    x0: [f64; 6],
    /// Whether the next solve starts from a solved state.
    warm: bool,
    /// Accumulated solver statistics.
    stats: SolverStats,
    /// The scaled base wrench and the tensions the last round started from.
    start: ([f64; 6], Vec<f64>),
}

/// The scaled base wrench of `options`' warm start (zero without).
fn scaled_base_wrench(model: &RobotModel, options: &SolveOptions) -> [f64; 6] {
    let f_ref = model.force_scale();
    let fm = f_ref * model.length();
    match &options.warm_start {
        Some(w) => {
            let b = &w.base_wrench;
            [
                b[0] / f_ref,
                b[1] / f_ref,
                b[2] / f_ref,
                b[3] / fm,
                b[4] / fm,
                b[5] / fm,
            ]
        }
        None => [0.0; 6],
    }
}

impl HeldProblem<'_> {
    /// The first taut set: the tendons of the tension guess that carry tension (their
    /// guessed tensions into `tensions`), else those stretched when every held tendon carries
    /// no tension (one march of the actuated, unloaded rod; all taut if it fails).
    fn first_taut(&self, plan: &[usize], pressures: &[f64], tensions: &mut [f64]) -> Vec<bool> {
        match &self.actuation.tension_guess {
            Some(g) => self
                .all_held
                .iter()
                .map(|h| {
                    tensions[h.tendon] = g[h.tendon].max(0.0);
                    g[h.tendon] > 0.0
                })
                .collect(),
            None => {
                let eq = super::equations::Equations {
                    model: self.model,
                    tensions,
                    pressures,
                    load_factor: 0.0,
                    profile: None,
                };
                let mut p = Shooting::new(eq, self.options.integrator, plan.to_vec());
                let mut r = [0.0; 6];
                if p.evaluate(&[0.0; 6], 0.0, None, &mut r) == Evaluated::Failed {
                    vec![true; self.all_held.len()]
                } else {
                    self.all_held
                        .iter()
                        .map(|h| h.target - p.lengths[h.tendon] < 0.0)
                        .collect()
                }
            }
        }
    }

    /// Solves the smooth problem of the current taut set (slack tendons at zero tension) from
    /// the last state; the solved tensions and base wrench go into `st`.
    fn round(&self, p: &mut Shooting<'_>, st: &mut HeldState) -> NewtonOutcome {
        let f_ref = self.model.force_scale();
        p.held = self
            .all_held
            .iter()
            .zip(&st.taut)
            .filter(|(_, t)| **t)
            .map(|(h, _)| *h)
            .collect();
        for (h, t) in self.all_held.iter().zip(&st.taut) {
            if !t {
                st.tensions[h.tendon] = 0.0;
            }
        }
        p.tensions.clone_from(&st.tensions);
        st.start = (st.x0, st.tensions.clone());
        let mut z0 = st.x0.to_vec();
        z0.extend(p.held.iter().map(|h| st.tensions[h.tendon] / f_ref));
        let mut round_stats = SolverStats::default();
        let mut out = smooth(p, &z0, self.options, st.warm, &mut round_stats);
        st.stats.iterations += round_stats.iterations;
        st.stats.load_steps += round_stats.load_steps;
        st.stats.load_factor = round_stats.load_factor;
        if !out.at_x {
            let mut r = vec![0.0; p.dim()];
            if p.evaluate(&out.x, st.stats.load_factor, None, &mut r) != Evaluated::Failed
                && !out.converged
                && st.stats.load_factor >= 1.0
            {
                out.residual = max_norm(&r);
            }
        }
        for (h, held) in p.held.iter().enumerate() {
            st.tensions[held.tendon] = out.x[6 + h] * f_ref;
        }
        st.x0.copy_from_slice(&out.x[..6]);
        st.warm = true;
        out
    }

    /// Checks the guess of a converged round: a taut tendon with a negative tension (beyond
    /// `eps` relative) is released, a slack one stretched is taken up. Returns whether any
    /// changed.
    fn update_taut(&self, p: &Shooting<'_>, st: &mut HeldState, eps: f64) -> bool {
        let f_ref = self.model.force_scale();
        let mut changed = false;
        for (k, h) in self.all_held.iter().enumerate() {
            let tau = st.tensions[h.tendon];
            let slack = h.target - p.lengths[h.tendon] + h.compliance * tau;
            if st.taut[k] && tau < -eps * f_ref {
                st.taut[k] = false;
                st.tensions[h.tendon] = 0.0;
                changed = true;
            } else if !st.taut[k] && slack < -eps * h.scale {
                st.taut[k] = true;
                changed = true;
            }
        }
        changed
    }

    /// The solution of the last round `out` (after `round + 1` rounds).
    ///
    /// # Errors
    /// With `throw`, the material error met or [`Error::NotConverged`] naming the active set
    /// or the shooting if not `settled`.
    fn finish(
        self,
        p: &mut Shooting<'_>,
        mut st: HeldState,
        out: &NewtonOutcome,
        settled: bool,
        round: usize,
    ) -> Result<StaticsSolution> {
        st.stats.residual = out.residual;
        st.stats.converged = settled;
        st.stats.function_evaluations = p.evaluations;
        if !settled && self.options.newton.throw {
            if let Some(e) = p.ws.material_error.take() {
                return Err(e);
            }
            // Judged where the last round started: a Newton iteration on undetermined tensions
            // wanders along them (to tensions of 1e6 force scales, where the rod collapses).
            let (x0, tensions) = &st.start;
            if let Some(e) = self.undetermined(p, &st.taut, (x0, tensions), 1.0, false) {
                return Err(e);
            }
            let what = if out.converged {
                format!(
                    "active set of the displacement-controlled tendons ({} rounds)",
                    round + 1
                )
            } else {
                "shooting Newton (Cosserat rod statics, displacement control)".into()
            };
            return Err(Error::NotConverged {
                what,
                iterations: st.stats.iterations,
                residual: out.residual,
                load_factor: 1.0,
            });
        }
        p.tensions.clone_from(&st.tensions);
        let f_ref = self.model.force_scale();
        let fm = f_ref * self.model.length();
        let x0 = st.x0;
        let base_wrench = [
            x0[0] * f_ref,
            x0[1] * f_ref,
            x0[2] * f_ref,
            x0[3] * fm,
            x0[4] * fm,
            x0[5] * fm,
        ];
        if settled {
            let at = (&st.x0, &st.tensions[..]);
            if let Some(e) = self.undetermined(p, &st.taut, at, st.stats.load_factor, true) {
                return Err(e);
            }
        }
        let mut sol = assemble(p, self.model, base_wrench, st.stats, &[]);
        let mut act = self.actuation.clone();
        act.reference_lengths = Some(self.reference);
        sol.actuation = act;
        sol.options = *self.options;
        Ok(sol)
    }

    /// The error naming `displacements` when they do not determine the tensions of the held
    /// tendons `taut` at the scaled base wrench and tensions `at` (load factor `lambda`; with
    /// `at_zero_slack`, the slack tendons with no slack left at the last evaluation of `p` count
    /// as held too): a pattern of their tensions that changes neither the
    /// tip's balance nor their slacks, within [`UNDETERMINED`] of the largest singular value
    /// of the held problem's Jacobian, and that keeps the slack ones' tensions non-negative in
    /// one direction. Such tendons pull against each other without moving the rod (four 90°
    /// apart, or any three on a rod that cannot stretch): only their stiffness decides how.
    fn undetermined(
        &self,
        p: &Shooting<'_>,
        taut: &[bool],
        (x0, tensions): (&[f64; 6], &[f64]),
        lambda: f64,
        at_zero_slack: bool,
    ) -> Option<Error> {
        let f_ref = self.model.force_scale();
        let eps = 10.0 * self.options.newton.tolerance;
        // The held tendons at zero slack, and which of them are slack (tension 0).
        let (mut zero, mut slack) = (Vec::new(), Vec::new());
        for (h, &taut) in self.all_held.iter().zip(taut) {
            let gap = h.target - p.lengths[h.tendon] + h.compliance * tensions[h.tendon];
            if taut || (at_zero_slack && gap <= eps * h.scale) {
                zero.push(*h);
                slack.push(!taut);
            }
        }
        if zero.is_empty() {
            return None;
        }
        let dim = 6 + zero.len();
        let mut z = x0.to_vec();
        z.extend(zero.iter().map(|h| tensions[h.tendon] / f_ref));
        // On the coarse mesh when there is one (a fifth of the cost): a pattern that moves
        // nothing does so on any mesh, and a determined one is far above the threshold.
        let mut q = p
            .coarse()
            .unwrap_or_else(|| Shooting::new(p.eq, p.integrator, p.plan.clone()));
        q.tensions = tensions.to_vec();
        q.held = zero;
        let (mut jac, mut r) = (vec![0.0; dim * dim], vec![0.0; dim]);
        let ev = q.evaluate(&z, lambda, Some(&mut jac), &mut r);
        let zero = q.held;
        if ev != Evaluated::Jacobian {
            return None;
        }
        let svd = DMatrix::from_column_slice(dim, dim, &jac).svd(false, true);
        let v_t = svd.v_t?;
        let largest = svd.singular_values.max();
        let pattern = svd
            .singular_values
            .iter()
            .zip(v_t.row_iter())
            .filter(|(sv, _)| **sv <= UNDETERMINED * largest)
            .map(|(_, row)| row.columns(6, dim - 6).transpose())
            .find_map(|t| {
                // Largest entry 1 in size, the first sizeable one positive.
                let big = t.amax();
                let first = t
                    .iter()
                    .find(|v| v.abs() > 1e-6 * big)
                    .map_or(1.0, |v| v.signum());
                let t = &t / (big * first);
                // Tensions of slack tendons may only grow: one sign on all of them.
                let on_slack = || t.iter().zip(&slack).filter(|(_, s)| **s).map(|(v, _)| *v);
                if on_slack().all(|v| v >= -1e-6) {
                    Some(t)
                } else if on_slack().all(|v| v <= 1e-6) {
                    Some(-t)
                } else {
                    None
                }
            })?;
        let tendons: Vec<usize> = zero.iter().map(|h| h.tendon).collect();
        let shown: Vec<String> = pattern.iter().map(|v| format!("{v:.3}")).collect();
        let displacements: Vec<String> = self
            .actuation
            .tendons
            .iter()
            .map(|t| match t {
                TendonInput::Displacement { displacement, .. } => format!("{displacement:.4e}"),
                TendonInput::Tension(_) => "None".into(),
            })
            .collect();
        Some(Error::invalid(
            "displacements",
            format!("[{}]", displacements.join(", ")),
            format!(
                "displacements that determine the held tendons' tensions: the tendons {tendons:?} \
                 can take on tension in the proportions [{}] without moving the rod or \
                 changing their lengths (they pull against each other or against a rod that \
                 cannot stretch); give them a tendon_stiffness (N/m) or hold fewer of them",
                shown.join(", ")
            ),
        ))
    }
}

/// Singular values of the held problem's Jacobian (scaled: base wrench and tensions per force
/// scale, tip rows per force scale, slacks per their scale) below this fraction of the
/// largest leave a tension pattern undetermined: a change of the pattern by the force scale
/// moves the tendons' lengths by less than 1e-8 of the slack scale. Tendons that pull against
/// each other exactly come out at round-off (1e-15); the nearest determined patterns (the
/// axial stretch of a rod whose tendons sit 10 radii out) near 1e-3.
const UNDETERMINED: f64 = 1e-8;

/// [`solve_held`] on the integration mesh: the rounds of the active set.
fn solve_held_on_mesh(
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &SolveOptions,
) -> Result<StaticsSolution> {
    let (nt, nc) = (model.tendons().len(), model.chambers().len());
    let reference = match &actuation.reference_lengths {
        Some(r) => r.clone(),
        None => reference_lengths(model, options)?,
    };
    let all_held = held_of(model, actuation, &reference);
    // (A pull-in of the tendon's whole length asks for a path of no length: no equilibrium.)
    if let Some(h) = all_held.iter().find(|h| h.target <= 0.0) {
        return Err(Error::invalid(
            format!("displacements[{}]", h.tendon),
            reference[h.tendon] - h.target,
            format!(
                "< {:.6e} m, the tendon's path length at the motor's zero (a pull-in of its \
                 whole length leaves it no path)",
                reference[h.tendon]
            ),
        ));
    }
    let hp = HeldProblem {
        model,
        actuation,
        options,
        reference,
        all_held,
    };
    let pressures = actuation.pressure_values(nc);
    let plan = match options.integrator {
        Integrator::Rk4 { steps } => rk4_plan(model.breaks(), steps),
        Integrator::Adaptive(_) => Vec::new(),
    };
    let mut st = HeldState {
        tensions: actuation.tension_values(nt),
        taut: Vec::new(),
        x0: scaled_base_wrench(model, options),
        warm: options.warm_start.is_some(),
        stats: SolverStats::default(),
        start: ([0.0; 6], Vec::new()),
    };
    st.taut = hp.first_taut(&plan, &pressures, &mut st.tensions);
    let rounds = MAX_ACTIVE_SET_ROUNDS_PER_TENDON * hp.all_held.len() + 4;
    let inputs = actuation.tension_values(nt);
    let eq = super::equations::Equations::new(model, &inputs, &pressures);
    let mut p = Shooting::new(eq, options.integrator, plan);
    // A tension or slack counts as negative beyond the shooting tolerance.
    let eps = 10.0 * options.newton.tolerance;
    let mut round = 0;
    loop {
        let out = hp.round(&mut p, &mut st);
        let changed = out.converged && hp.update_taut(&p, &mut st, eps);
        let settled = out.converged && !changed;
        for h in &hp.all_held {
            st.tensions[h.tendon] = st.tensions[h.tendon].max(0.0);
        }
        if settled || !out.converged || round + 1 >= rounds {
            return hp.finish(&mut p, st, &out, settled, round);
        }
        round += 1;
    }
}
