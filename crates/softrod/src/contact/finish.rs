//! The solution at the converged unknowns: the polished shape with its contact forces, the
//! tip reaction, the contacts, the stability, and what its compliance needs.

use std::sync::Arc;

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use super::belt::{lumps, Held};
use super::constraint::TipConstraint;
use super::newton::{exact_newton, Effort};
use super::obstacle::Obstacle;
use super::problem::{mesh_of, Active, Constrained, Pass, Site};
use super::rows::Forces;
use super::solve::coarse_mesh;
use super::stability::{constrained_stability, free_stiffness, held_contacts};
use super::{Contact, ContactCompliance, ContactSolution, ContactState};
use crate::cosserat::equations::{Equations, FULL, STATE};
use crate::cosserat::shooting::Shooting;
use crate::cosserat::statics::{assemble, scaled_back, stability_on, Integrator, SolveOptions};
use crate::cosserat::{tip_stability, Stability, NEUTRAL_MARGIN};
use crate::error::{Error, Result};
use crate::model::{Actuation, RobotModel};
use crate::solve::{max_norm, Evaluated, Problem, SolverStats};

/// Stability margin on the coarse mesh beyond which its sign decides whether a contact
/// solution is stable (closer to zero, the margin is computed on the mesh asked).
const COARSE_MARGIN_GAP: f64 = 1e-2;

/// What the compliance of a converged contact solution needs, owned (see
/// [`ContactCompliance`]), and the compliance once computed.
#[derive(Debug)]
pub(crate) struct Frozen {
    model: Arc<RobotModel>,
    obstacles: Vec<Obstacle>,
    tensions: Vec<f64>,
    pressures: Vec<f64>,
    integrator: Integrator,
    tip: Option<TipConstraint>,
    start: (Vector3<f64>, Matrix3<f64>),
    active: Vec<Active>,
    x: Vec<f64>,
    value: std::sync::OnceLock<Option<Matrix6<f64>>>,
}

impl Frozen {
    /// The problem `p` at full load at its solution `x`.
    fn at(p: &Constrained<'_>, x: &[f64]) -> Self {
        Self {
            model: Arc::clone(p.shared),
            obstacles: p.obstacles.to_vec(),
            tensions: p.tensions.clone(),
            pressures: p.pressures.clone(),
            integrator: p.integrator,
            tip: p.tip,
            start: p.start,
            active: p.active.clone(),
            x: x.to_vec(),
            value: std::sync::OnceLock::new(),
        }
    }

    /// The problem at full load with the active set of the solution.
    fn problem(&self) -> Constrained<'_> {
        let mut p = Constrained::new(
            &self.model,
            (self.tensions.clone(), self.pressures.clone()),
            self.integrator,
            self.tip,
            &self.obstacles,
        );
        p.start = self.start;
        p.active = self.active.clone();
        p.load = 1.0;
        p.from = 1.0;
        p
    }

    /// The constrained tip compliance (see [`Constrained::compliance`]), computed once.
    pub(crate) fn compliance(&self) -> Option<Matrix6<f64>> {
        *self
            .value
            .get_or_init(|| self.problem().compliance(&self.x))
    }

    /// Whether an active contact has friction (sticking or sliding).
    pub(crate) fn frictional(&self) -> bool {
        self.active
            .iter()
            .any(|a| a.state != ContactState::Frictionless)
    }

    /// The constrained actuation Jacobian of node `node` and its position (see
    /// [`Constrained::actuation_jacobian`]).
    pub(crate) fn actuation_jacobian(
        &self,
        node: usize,
    ) -> Option<(nalgebra::DMatrix<f64>, Vector3<f64>)> {
        self.problem().actuation_jacobian(&self.x, node)
    }
}

/// The error (or, without `throw`, nothing better to return) of a failed solve.
pub(super) fn fail(
    p: &Constrained<'_>,
    effort: &Effort,
    lambda: f64,
    why: &str,
) -> Result<ContactSolution> {
    let held = if p.tip.is_some() {
        "held tip"
    } else {
        "free tip"
    };
    let kind = if p.obstacles.is_empty() {
        ""
    } else {
        " and contact"
    };
    Err(Error::NotConverged {
        what: format!("constrained shooting ({held}{kind}; {why})"),
        iterations: effort.iterations,
        residual: p.last.as_ref().map_or(f64::INFINITY, |l| max_norm(&l.rows)),
        load_factor: lambda,
    })
}

/// Exact Newton steps from the converged `x` toward round-off (see [`exact_newton`]), so
/// that the balance of the reactions holds to the digits of the loads, not only of the
/// tolerance; `x` itself if they do not lower the residual. The last pass is left at the
/// result, whose residual is returned (`None` if it cannot be integrated).
fn polish(p: &mut Constrained<'_>, x: &[f64], options: &SolveOptions) -> Option<(Vec<f64>, f64)> {
    let mut effort = Effort::default();
    p.hint = p.solved.take();
    if let Some(out) = exact_newton(p, x, &options.newton, &mut effort, true, false) {
        return Some(out);
    }
    let mut r = vec![0.0; p.dim()];
    (p.evaluate(x, 1.0, None, &mut r) != Evaluated::Failed).then(|| (x.to_vec(), max_norm(&r)))
}

/// The contacts of a solution and the contact force at its samples (an interval's
/// distributed reaction lumped by the trapezoid rule).
fn report(
    active: &[Active],
    forces: &Forces,
    tangential: &[Vector3<f64>],
    held: &[Option<Held>],
    model: &RobotModel,
    cm: &RobotModel,
    sol: &crate::cosserat::StaticsSolution,
) -> (Vec<Contact>, Vec<[f64; 3]>) {
    let l = model.length();
    let mut contact_force = vec![[0.0; 3]; sol.s.len()];
    let mut contacts = Vec::with_capacity(forces.len());
    for (i, (((fnorm, n, s, pc), a), ft)) in forces.iter().zip(active).zip(tangential).enumerate() {
        if let Some(h) = held.get(i).and_then(Option::as_ref) {
            contacts.push(report_belt(a, h, model, cm, sol, &mut contact_force));
            continue;
        }
        let radius = model.rod().section_at(*s).radius;
        let point = pc - n * radius;
        contacts.push(Contact {
            obstacle: a.obstacle,
            s: *s,
            length: 0.0,
            point: [point.x, point.y, point.z],
            normal: [n.x, n.y, n.z],
            normal_force: *fnorm,
            tangential_force: [ft.x, ft.y, ft.z],
            state: a.state,
        });
        if let Some(j) = sol.s.iter().rposition(|v| v == s) {
            for k in 0..3 {
                contact_force[j][k] += fnorm * n[k] + ft[k];
            }
        }
        if a.site == Site::Interval {
            // The distributed reaction on (a, L], lumped at the samples by the trapezoid rule.
            let after = f64::from_bits(s.to_bits() + 1);
            // The contact model's distributed force carries the reaction on top of the loads'.
            let force = |m: &RobotModel, t: f64| {
                m.loads()
                    .distributed_force
                    .as_ref()
                    .map_or(Vector3::zeros(), |p| p.at(t))
            };
            let mut total = 0.0;
            let idx: Vec<usize> = (0..sol.s.len()).filter(|j| sol.s[*j] >= after).collect();
            for w in idx.windows(2) {
                let (j0, j1) = (w[0], w[1]);
                let h = sol.s[j1] - sol.s[j0];
                if h <= 0.0 {
                    continue;
                }
                for j in [j0, j1] {
                    let t = sol.s[j];
                    let reaction = force(cm, t) - force(model, t);
                    let lump = reaction * (0.5 * h);
                    total += lump.dot(n);
                    for k in 0..3 {
                        contact_force[j][k] += lump[k];
                    }
                }
            }
            let tip = Vector3::from(sol.tip_position()) - n * radius;
            contacts.push(Contact {
                obstacle: a.obstacle,
                s: after,
                length: l - after,
                point: [tip.x, tip.y, tip.z],
                normal: [n.x, n.y, n.z],
                normal_force: total,
                tangential_force: [0.0; 3],
                state: a.state,
            });
        }
    }
    (contacts, contact_force)
}

/// The distributed force per length (N/m, world) on the rod of `model` at arc length `t`
/// (m): its distributed load and its weight.
fn distributed(model: &RobotModel, t: f64) -> Vector3<f64> {
    let mut f = model
        .loads()
        .distributed_force
        .as_ref()
        .map_or(Vector3::zeros(), |p| p.at(t));
    if let Some(g) = model.rho_g() {
        f += g * model.rod().section_at(t).area;
    }
    f
}

/// The contact of the belt `a` that carries `held` on the solution `sol` (of the contact
/// model `cm`), its pressure lumped into `contact_force` (see [`lumps`]): at its start `s`,
/// of `length` `b - a`, its point where the pressure is largest, its normal force the
/// magnitude of the resultant of the lumps and its normal the resultant's direction (so that
/// `normal_force * normal` is the belt's share of `contact_force`, as for the other
/// contacts).
fn report_belt(
    a: &Active,
    held: &Held,
    model: &RobotModel,
    cm: &RobotModel,
    sol: &crate::cosserat::StaticsSolution,
    contact_force: &mut [[f64; 3]],
) -> Contact {
    let applied = |t: f64| distributed(cm, t);
    let mut resultant = Vector3::zeros();
    for (j, c) in lumps(held, &sol.s, &sol.position, &applied) {
        resultant += c;
        for k in 0..3 {
            contact_force[j][k] += c[k];
        }
    }
    let (sa, sb) = held.range();
    let peak = held.peak().copied();
    let (point, peak_normal) = peak.map_or((Vector3::zeros(), Vector3::z()), |h| {
        let radius = model.rod().section_at(h.s).radius;
        (h.point - h.normal * radius, h.normal)
    });
    let force = resultant.norm();
    let normal = if force > 0.0 {
        resultant / force
    } else {
        peak_normal
    };
    Contact {
        obstacle: a.obstacle,
        s: sa,
        length: sb - sa,
        point: [point.x, point.y, point.z],
        normal: [normal.x, normal.y, normal.z],
        normal_force: force,
        tangential_force: [0.0; 3],
        state: ContactState::Frictionless,
    }
}

/// The stability of a rod with a held tip (see [`super::stability`]): whether stable, the
/// margin (the free directions' smallest stiffness; `+inf` for a full clamp, minus the
/// number of conjugate points when there are some) and the conjugate points.
fn held_stability(
    sh: &Shooting<'_>,
    c: &TipConstraint,
    cols: &[Vector6<f64>],
    tw: &[Vector6<f64>; 6],
) -> (bool, f64, Option<usize>) {
    let l = sh.eq.model.length();
    let mut y = Matrix6::zeros();
    let mut xt = Matrix6::zeros();
    for k in 0..6 {
        for i in 0..6 {
            y[(i, k)] = cols[k][i];
            xt[(i, k)] = tw[k][i] / if i < 3 { l } else { 1.0 };
        }
    }
    // (Counted along the final march with the columns, at these unknowns.)
    let count = Some(sh.jacobi.conjugate);
    let free: Vec<usize> = (0..6).filter(|k| !c.held[*k]).collect();
    let stiff = free_stiffness(&y, &xt, &c.pose.rotation(), &free);
    let (stable, margin) = match (count, stiff) {
        (Some(0), Some((m, neg))) => (neg == 0 && m > -NEUTRAL_MARGIN, m),
        (Some(0), None) if free.is_empty() => (true, f64::INFINITY),
        (Some(n), _) if n > 0 => (false, -(n as f64)),
        _ => (false, 0.0),
    };
    (stable, margin, count)
}

/// With a free tip, the stability of the contacts as dead loads from the exact Jacobian of
/// the pass at `x` (its base-wrench block and tip columns, as the compliance left it), so
/// that no march with the columns is needed again; `None` otherwise.
pub(super) fn jacobian_stability(p: &Constrained<'_>, pass: &Pass, x: &[f64]) -> Option<Stability> {
    let (j, twists) = pass.jacobian.as_ref()?;
    if p.tip.is_some() || pass.key != p.key(x, 1.0) || twists.len() < 6 {
        return None;
    }
    let n = p.dim();
    let mut y = [0.0; 36];
    for c in 0..6 {
        y[6 * c..6 * c + 6].copy_from_slice(&j[n * c..n * c + 6]);
    }
    let tw: [Vector6<f64>; 6] = std::array::from_fn(|k| twists[k]);
    tip_stability(
        &y,
        &tw,
        p.model.length(),
        crate::cosserat::JacobiCheck::default(),
    )
}

/// With a free tip and frictionless point contacts ([`held_contacts`]), the stability with
/// the contacts held at the solution `x`: from the coarse mesh when its sign is clear there,
/// else on the mesh asked ([`constrained_stability`]), whose compliance under contact is
/// then kept in `frozen` (the solution's, read later without another march).
fn held_contacts_stability(
    p: &mut Constrained<'_>,
    x: &[f64],
    frozen: Option<&Frozen>,
) -> Option<Stability> {
    if let Some(st) = coarse_stability(p).filter(|st| st.margin.abs() > COARSE_MARGIN_GAP) {
        return Some(st);
    }
    let (st, c) = constrained_stability(p, x)?;
    if let Some(f) = frozen {
        let _ = f.value.set(Some(c));
    }
    Some(st)
}

/// The stability of the coarse mesh's solution ([`Constrained::coarse_stability`]) when it
/// has the active set of `p` (the same contacts, sites and states).
fn coarse_stability(p: &Constrained<'_>) -> Option<Stability> {
    let (active, st) = p.coarse_stability.as_ref()?;
    let same = active.len() == p.active.len()
        && active
            .iter()
            .zip(&p.active)
            .all(|(a, b)| (a.obstacle, a.site, a.state) == (b.obstacle, b.site, b.state));
    same.then_some(*st)
}

/// The shooting residual at the solution `x` and, with a held tip, the base-wrench columns,
/// with the nodes in `sh`: those of the last pass when it marched the state alone at `x` on
/// the mesh of `sh` (free tip), else from a new march.
fn final_march(
    p: &Constrained<'_>,
    sh: &mut Shooting<'_>,
    pass: Pass,
    x: &[f64],
) -> Result<(Vector6<f64>, Vec<Vector6<f64>>)> {
    if let Some((mesh, lengths, tensions)) = pass.marched {
        if p.tip.is_none() && mesh == sh.integrator && pass.key == p.key(x, 1.0) {
            sh.nodes = pass.nodes;
            sh.lengths = lengths;
            sh.tensions = tensions;
            return Ok((pass.residual, Vec::new()));
        }
    }
    let marched = if p.tip.is_none() {
        sh.pass::<STATE>(&x[..6], 1.0)
    } else {
        sh.pass::<FULL>(&x[..6], 1.0)
    };
    let (res, cols, _) = marched.map_err(|e| match e {
        // (The march's own failure, said once: its message is not wrapped in another.)
        Error::NotConverged {
            what,
            iterations,
            residual,
            load_factor,
        } => Error::NotConverged {
            what: format!(
                "constrained shooting: the march of the last state ({what}, {iterations} steps)"
            ),
            iterations: 0,
            residual,
            load_factor,
        },
        e => Error::not_converged(format!("constrained shooting: {e}"), 0, f64::INFINITY),
    })?;
    Ok((res, cols))
}

/// The solution at the converged unknowns `x`: the shape with its contact forces, the tip
/// reaction, the contacts, the stability.
pub(super) fn finish(
    p: &mut Constrained<'_>,
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &SolveOptions,
    x: &[f64],
    effort: &Effort,
    load_factor: f64,
) -> Result<ContactSolution> {
    let reached = if load_factor >= 1.0 {
        polish(p, x, options)
    } else {
        let mut r = vec![0.0; p.dim()];
        (p.evaluate(x, 1.0, None, &mut r) != Evaluated::Failed).then(|| (x.to_vec(), max_norm(&r)))
    };
    let Some((polished, residual)) = reached else {
        return fail(p, effort, 1.0, "the solution could not be integrated");
    };
    let x: &[f64] = &polished;
    let forces = p.normal_forces(x);
    // The compliance under the constraints, on first read.
    let frozen = (residual <= options.newton.tolerance).then(|| Frozen::at(p, x));
    let held_verdict = held_contacts(p).then(|| held_contacts_stability(p, x, frozen.as_ref()));
    let compliance = ContactCompliance::of(frozen);
    let Some(pass) = p.last.take() else {
        return fail(p, effort, 1.0, "no pass");
    };
    let free_stability = held_verdict.unwrap_or_else(|| jacobian_stability(p, &pass, x));
    let held = pass.held.clone();
    let belts = held.iter().any(Option::is_some);
    let cm = Arc::clone(&pass.model);
    let (plan, stops) = mesh_of(&cm, options.integrator);
    let eq = Equations::new(&cm, &p.tensions, &p.pressures);
    let mut sh = Shooting::new(eq, options.integrator, plan);
    sh.stops = stops;
    let (res, cols) = final_march(p, &mut sh, pass, x)?;
    let tip_twist = sh.tip_twist;
    let stats = SolverStats {
        iterations: effort.iterations,
        residual,
        function_evaluations: p.evaluations + sh.evaluations,
        converged: residual <= options.newton.tolerance && load_factor >= 1.0,
        load_steps: effort.load_steps,
        load_factor,
    };
    let fs = model.force_scale();
    let l = model.length();
    let mut sol = assemble(&mut sh, &cm, scaled_back(model, &x[..6]), stats, &[]);
    if sol.stats.converged {
        let name = if p.tip.is_some() {
            "tip_constraint"
        } else {
            "loads"
        };
        if let Some(e) = crate::cosserat::collapse::compressed_through_zero(&sol, name) {
            return Err(e);
        }
    }
    sol.actuation = actuation.clone();
    sol.options = *options;
    let tangential = p.tangential_forces(x, &forces);
    let (contacts, contact_force) =
        report(&p.active, &forces, &tangential, &held, model, &cm, &sol);
    let tip_reaction = p.tip.as_ref().map(|_| {
        let f = res.fixed_rows::<3>(0) * fs;
        let m = res.fixed_rows::<3>(3) * (fs * l);
        [f.x, f.y, f.z, m.x, m.y, m.z]
    });
    // Stability: with a held tip, conjugate points and the free directions' stiffness; with
    // a free tip, the tip criterion of `solve_statics` (frictionless point contacts held,
    // other contacts as dead loads).
    let mut conjugate = None;
    if let (Some(c), Some(tw)) = (p.tip, tip_twist) {
        let (stable, margin, count) = held_stability(&sh, &c, &cols, &tw);
        conjugate = count;
        sol.stable = stable && sol.stats.converged;
        let _ = sol.margin.set(margin);
    } else if let Some(st) = free_stability.filter(|_| sol.stats.converged) {
        let _ = sol.margin.set(st.margin);
        sol.stable = st.stable;
    } else if let Some(st) = coarse_stability(p)
        .or_else(|| coarse_mesh(options.integrator).and_then(|mesh| stability_on(&sol, mesh)))
        .filter(|st| sol.stats.converged && st.margin.abs() > COARSE_MARGIN_GAP && !belts)
    {
        // Clear on the coarse mesh; the margin itself is computed on the mesh asked when
        // read.
        sol.stable = st.stable;
    } else if let Some(st) = stability_on(&sol, options.integrator).filter(|_| sol.stats.converged)
    {
        // One march with the columns on the mesh asked: the tip criterion and the conjugate
        // points along the rod (a tip margin alone passes a rod past one).
        let _ = sol.margin.set(st.margin);
        sol.stable = st.stable;
    } else {
        sol.stable = false;
    }
    if !sol.stats.converged && options.newton.throw {
        return fail(
            p,
            effort,
            1.0,
            "the residual at the solution is above the tolerance",
        );
    }
    Ok(ContactSolution {
        solution: sol,
        tip_reaction,
        contacts,
        contact_force,
        conjugate_points: conjugate,
        compliance,
    })
}
