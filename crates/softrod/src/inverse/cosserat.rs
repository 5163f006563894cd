//! The Cosserat model as a forward model of the inverse statics: a statics solve and its
//! exact actuation Jacobian per evaluation, or, for a robot without external loads, one march
//! of the state with one column per actuator.

use std::sync::Arc;

use nalgebra::{DMatrix, Matrix3, Vector3};

use super::{resolved, uniform, InverseWarmStart, Target};
use super::{solve_inverse, Evaluation, Forward, InverseOptions, InverseSolution};
use crate::cosserat::equations::{Column, Equations, Workspace};
use crate::cosserat::mesh::rk4_position_error;
use crate::cosserat::sensitivity::{
    actuation_jacobians, integrate, scheme_of, Linearisation, Request, Seed,
};
use crate::cosserat::shooting::{Node, Shooting};
use crate::cosserat::statics::{
    assemble, solve_statics, Integrator, SolveOptions, StaticsSolution, WarmStart,
};
use crate::error::{Error, Result};
use crate::model::loads::{Frame, PointLoad};
use crate::model::{Actuation, RobotModel};
use crate::solve::SolverStats;

/// Newton tolerance (scaled residual) of the forward solves of the inverse, at most: at the
/// statics default (1e-10) the tips of warm-started solves scatter by about 1e-10 m, the
/// inverse's own default tolerance, and the iteration wandered there (a tapered silicone arm
/// under gravity met its target to 4e-11 m, then 1.2e-10 m, and raised after 60 iterations at
/// 1.9e-10 m).
pub const FORWARD_TOLERANCE: f64 = 1e-12;

/// Whether no external load acts (zero point loads only mark integration breaks).
fn no_external_loads(model: &RobotModel) -> bool {
    let l = model.loads();
    l.tip_force == Vector3::zeros()
        && l.tip_moment == Vector3::zeros()
        && l.point_loads
            .iter()
            .all(|p| p.force == Vector3::zeros() && p.moment == Vector3::zeros())
        && l.distributed_force.is_none()
        && l.distributed_moment.is_none()
        && model.rho_g().is_none()
}

/// The Cosserat model as a [`Forward`] model: a robot model, its solver options and the
/// observed nodes; warm-started from its last solve.
pub struct CosseratForward {
    model: Arc<RobotModel>,
    options: SolveOptions,
    /// Node indices of the observed points; `None`: the tip.
    nodes: Option<Vec<usize>>,
    last: Option<WarmStart>,
    /// The last solution (loaded robots only).
    pub solution: Option<StaticsSolution>,
    /// The last march of an unloaded robot: its actuation, nodes, tendon path lengths and
    /// scaled tip residual (a statics solution is assembled from it without solving again).
    march: Option<March>,
    /// Whether the tip pose and its Jacobian have the closed form of [`super::uniform`] (an
    /// unloaded robot with uniform intervals, a tip target).
    uniform: bool,
    /// The workspace of those closed-form marches, renewed by each.
    uniform_ws: Workspace,
}

/// The state recorded along one march of an unloaded robot at the actuation `a`.
struct March {
    a: Vec<f64>,
    nodes: Vec<Node>,
    lengths: Vec<f64>,
    residual: f64,
    evaluations: usize,
}

impl CosseratForward {
    /// The forward model of `model` solved with `options`, observing the tip, or the backbone
    /// points at the undeformed arc lengths `s` (m; the model gets integration breaks there
    /// unless they are mesh nodes already).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `target_s[k]` outside `(0, L]`, or the model's.
    pub fn new(model: &Arc<RobotModel>, options: &SolveOptions, s: Option<&[f64]>) -> Result<Self> {
        options.validate()?;
        let options = &SolveOptions {
            newton: crate::solve::NewtonOptions {
                tolerance: options.newton.tolerance.min(FORWARD_TOLERANCE),
                ..options.newton
            },
            ..*options
        };
        let mut me = Self {
            model: Arc::clone(model),
            options: *options,
            nodes: None,
            last: None,
            solution: None,
            march: None,
            uniform: false,
            uniform_ws: Workspace::new(model.tendons().len()),
        };
        if let Some(s) = s {
            let l = model.length();
            for (k, &v) in s.iter().enumerate() {
                if !(v.is_finite() && v > 0.0 && v <= l) {
                    return Err(Error::invalid(
                        format!("target_s[{k}]"),
                        v,
                        format!("in (0, length] = (0, {l}] m"),
                    ));
                }
            }
            let zero = Actuation::zero(model.tendons().len(), model.chambers().len());
            let probe = solve_statics(model, &zero, options)?;
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * l;
            let on_mesh = s.iter().all(|&v| probe.s.iter().any(|&x| close(x, v)));
            if !on_mesh {
                let mut loads = model.loads().clone();
                for &v in s {
                    if !model.breaks().iter().any(|&b| close(b, v)) {
                        loads.point_loads.push(PointLoad {
                            s: v,
                            force: Vector3::zeros(),
                            moment: Vector3::zeros(),
                            frame: Frame::World,
                        });
                    }
                }
                me.model = model.with_loads(loads)?;
            }
            let probe = solve_statics(&me.model, &zero, options)?;
            let nodes = s
                .iter()
                .map(|&v| {
                    probe
                        .s
                        .iter()
                        .rposition(|&x| close(x, v))
                        .ok_or_else(|| Error::invalid("target_s", v, "a point of the mesh"))
                })
                .collect::<Result<Vec<_>>>()?;
            me.nodes = Some(nodes);
        }
        me.uniform = me.nodes.is_none()
            && no_external_loads(&me.model)
            && uniform::applies(&me.model, &me.options.integrator);
        Ok(me)
    }

    /// The model solved (with breaks at the observed arc lengths).
    pub fn model(&self) -> &Arc<RobotModel> {
        &self.model
    }

    fn actuation(&self, a: &[f64]) -> Actuation {
        let nt = self.model.tendons().len();
        Actuation::tensions(&a[..nt]).with_pressures(&a[nt..])
    }

    /// The statics solution at the actuation `a` (m, N, Pa).
    ///
    /// # Errors
    /// As [`solve_statics`].
    pub fn solve(&self, a: &[f64]) -> Result<StaticsSolution> {
        if let Some(sol) = self.assembled(a) {
            return Ok(sol);
        }
        let opts = SolveOptions {
            warm_start: self.last,
            ..self.options
        };
        solve_statics(&self.model, &self.actuation(a), &opts)
    }
}

impl CosseratForward {
    /// The estimated tip error of the RK4 mesh at the actuation `a`, relative to the length
    /// ([`rk4_position_error`](crate::cosserat::mesh::rk4_position_error)): from the last solution
    /// or the closed form of a uniform unloaded robot when they apply, else from the solution
    /// at `a`; NaN for the adaptive integrator or where it cannot be solved.
    pub fn mesh_error(&mut self, a: &[f64]) -> f64 {
        if !matches!(self.options.integrator, Integrator::Rk4 { .. }) {
            return f64::NAN;
        }
        let (nt, _) = self.dims();
        let at_a = |s: &&StaticsSolution| s.tensions() == a[..nt] && s.pressures() == a[nt..];
        if let Some(sol) = self.solution.as_ref().filter(at_a) {
            return rk4_position_error(sol);
        }
        if self.uniform && a.len() == nt {
            let closed = uniform::position_error(
                &self.model,
                &self.options.integrator,
                a,
                &mut self.uniform_ws,
            );
            if let Some(e) = closed {
                return e;
            }
        }
        self.solve(a)
            .map_or(f64::NAN, |sol| rk4_position_error(&sol))
    }
}

impl CosseratForward {
    /// The statics solution of an unloaded robot at `a` from the last march, if it was at `a`:
    /// the zero base wrench, the nodes and path lengths of that march (the state integrated
    /// there is the forward solve's, step for step); `None` otherwise.
    fn assembled(&self, a: &[f64]) -> Option<StaticsSolution> {
        let m = self.march.as_ref().filter(|m| m.a == a)?;
        let model = &self.model;
        let nt = model.tendons().len();
        let (tensions, pressures) = (&a[..nt], &a[nt..]);
        let eq = Equations::new(model, tensions, pressures);
        let mut plan = Vec::new();
        let _ = scheme_of(&self.options.integrator, model, &mut plan);
        let mut p = Shooting::new(eq, self.options.integrator, plan);
        p.nodes.clone_from(&m.nodes);
        p.lengths.clone_from(&m.lengths);
        let converged = m.residual <= self.options.newton.tolerance
            && m.nodes.iter().all(|n| n.y.iter().all(|v| v.is_finite()));
        let stats = SolverStats {
            iterations: 0,
            residual: m.residual,
            function_evaluations: m.evaluations,
            converged,
            load_steps: 0,
            load_factor: 1.0,
        };
        let mut sol = assemble(&mut p, model, [0.0; 6], stats, &[]);
        if !converged || p.ws.material_error.is_some() {
            return None;
        }
        sol.actuation = self.actuation(a);
        sol.options = self.options;
        sol.stable = true;
        Some(sol)
    }
}

impl CosseratForward {
    /// One march of an unloaded robot at the actuation `a` (tensions in N, then pressures in
    /// Pa): the base wrench is zero and does not move with the actuation. With `jacobian`, one
    /// column per actuator rides on the march (per observed pose a `6 × (nt + nc)` matrix of
    /// world-frame position and rotation rates per unit actuation) and the march is recorded
    /// for [`CosseratForward::solve`]; without, the state alone is marched and the recorded
    /// march is kept.
    fn unloaded(&mut self, a: &[f64], jacobian: bool) -> Result<Evaluation> {
        let (nt, nc) = self.dims();
        let act = self.actuation(a);
        act.validate(nt, nc)?;
        if self.uniform {
            if let Some(ev) = uniform::tip(
                &self.model,
                &self.options.integrator,
                a,
                jacobian,
                &mut self.uniform_ws,
            ) {
                if jacobian {
                    self.march = None;
                }
                return Ok(ev);
            }
        }
        let eq = Equations::new(&self.model, &a[..nt], &a[nt..]);
        let seeds: Vec<Seed> = if jacobian {
            (0..nt)
                .map(|i| Seed::Forced(Column::Tension(i)))
                .chain((0..nc).map(|j| Seed::Forced(Column::Pressure(j))))
                .collect()
        } else {
            Vec::new()
        };
        let mut plan = Vec::new();
        let scheme = scheme_of(&self.options.integrator, &self.model, &mut plan);
        let mut sorted = self.nodes.clone().unwrap_or_default();
        sorted.sort_unstable();
        sorted.dedup();
        let mut cols = integrate(
            eq,
            scheme,
            &[0.0; 6],
            &Request {
                seeds: &seeds,
                lengths: &[],
                observe: &sorted,
                load_node: None,
                record_nodes: jacobian || self.nodes.is_some(),
                stops: &[],
            },
        )?;
        let to_matrix = |c: &[nalgebra::Vector6<f64>]| DMatrix::from_fn(6, nt + nc, |r, k| c[k][r]);
        let out = match &self.nodes {
            None => Evaluation {
                positions: vec![cols.tip_pose.0],
                rotation: cols.tip_pose.1,
                jacobian: jacobian.then(|| vec![to_matrix(&cols.tip)]),
            },
            Some(nodes) => {
                let at = |i: usize| sorted.iter().position(|&x| x == i).unwrap_or(0);
                let last = *nodes.last().unwrap_or(&0);
                Evaluation {
                    positions: nodes
                        .iter()
                        .map(|&i| crate::cosserat::equations::v3(&cols.nodes[i].y, 0))
                        .collect(),
                    rotation: cols.rotations[at(last)],
                    jacobian: jacobian.then(|| {
                        nodes
                            .iter()
                            .map(|&i| to_matrix(&cols.poses[at(i)]))
                            .collect()
                    }),
                }
            }
        };
        if jacobian {
            // The nodes move into the record of the march (after the positions are read).
            self.march = Some(March {
                a: a.to_vec(),
                nodes: std::mem::take(&mut cols.nodes),
                lengths: std::mem::take(&mut cols.lengths),
                residual: crate::solve::max_norm(cols.residual.as_slice()),
                evaluations: cols.evaluations,
            });
        }
        Ok(out)
    }
}

impl Forward for CosseratForward {
    fn forget(&mut self) {
        self.last = None;
        self.solution = None;
        self.march = None;
    }

    fn has_probes(&self) -> bool {
        // A loaded robot solves a boundary-value problem (several marches): no cheaper pass.
        no_external_loads(&self.model)
    }

    fn probe(&mut self, a: &[f64]) -> Result<Evaluation> {
        if no_external_loads(&self.model) {
            return self.unloaded(a, false);
        }
        self.evaluate(a, false)
    }

    fn dims(&self) -> (usize, usize) {
        (self.model.tendons().len(), self.model.chambers().len())
    }

    fn length(&self) -> f64 {
        self.model.length()
    }

    fn chamber_areas(&self) -> Vec<f64> {
        self.model.chamber_start_areas()
    }

    fn evaluate(&mut self, a: &[f64], jacobian: bool) -> Result<Evaluation> {
        if no_external_loads(&self.model) && jacobian {
            return self.unloaded(a, true).map_err(|e| {
                // A march that fails where the tendons compress the rod to nothing or bend it
                // inside a tendon's path: the tension named, as a solve names it.
                let nt = self.model.tendons().len();
                let tensions = &a[..nt.min(a.len())];
                crate::cosserat::collapse::compressed_to_zero(&self.model, tensions)
                    .or_else(|| {
                        crate::cosserat::collapse::bent_inside_a_tendon(&self.model, tensions)
                    })
                    .filter(|_| matches!(e, Error::NotConverged { .. }))
                    .unwrap_or(e)
            });
        }
        let sol = self.solve(a)?;
        self.last = Some(sol.warm_start());
        let n = sol.s.len();
        let nodes = self.nodes.clone().unwrap_or_else(|| vec![n - 1]);
        let rot = |i: usize| {
            let r = sol.rotation[i];
            Matrix3::new(
                r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1], r[2][2],
            )
        };
        let positions = nodes
            .iter()
            .map(|&i| Vector3::from(sol.position[i]))
            .collect();
        let last = *nodes.last().unwrap_or(&(n - 1));
        let jac = if jacobian {
            let mut sorted = nodes.clone();
            sorted.sort_unstable();
            sorted.dedup();
            let js = actuation_jacobians(&sol, &sorted, Linearisation::Tension)?;
            Some(
                nodes
                    .iter()
                    .map(|i| js[sorted.iter().position(|x| x == i).unwrap_or(0)].clone())
                    .collect(),
            )
        } else {
            None
        };
        let out = Evaluation {
            positions,
            rotation: rot(last),
            jacobian: jac,
        };
        self.solution = Some(sol);
        Ok(out)
    }
}

/// The inverse statics of a Cosserat robot `model` (solved with `solve`) for `target` (see
/// the module documentation), under the mesh control of a forward solve
/// ([`solve_at_output`](crate::cosserat::mesh::solve_at_output)): on the default RK4 mesh, an
/// answer whose estimated tip error ([`CosseratForward::mesh_error`]) exceeds
/// [`DEFAULT_MESH_POSITION_LIMIT`](crate::cosserat::mesh::DEFAULT_MESH_POSITION_LIMIT) makes the
/// inverse run again on a finer mesh from the answer (its actuation and Hessian), and that
/// result is returned; on a chosen mesh, one above
/// [`CHOSEN_MESH_POSITION_LIMIT`](crate::cosserat::mesh::CHOSEN_MESH_POSITION_LIMIT) is an error
/// naming `steps`. [`inverse_statics`] also returns the solution at the answer.
///
/// # Errors
/// As [`solve_inverse`]; the forward solve's errors; `steps` as above.
pub fn inverse_actuation(
    model: &Arc<RobotModel>,
    target: &Target,
    options: &InverseOptions,
    solve: &SolveOptions,
    warm: Option<&InverseWarmStart>,
) -> Result<InverseSolution> {
    inverse_resolved(model, target, options, solve, warm).map(|(out, _)| out)
}

/// [`inverse_actuation`] and the forward model on the mesh of its answer (from each start of
/// `options.starts`, the best answer: see [`Starts`](super::Starts)).
fn inverse_resolved(
    model: &Arc<RobotModel>,
    target: &Target,
    options: &InverseOptions,
    solve: &SolveOptions,
    warm: Option<&InverseWarmStart>,
) -> Result<(InverseSolution, CosseratForward)> {
    resolved(
        target,
        options,
        solve,
        warm,
        |so| CosseratForward::new(model, so, target.s.as_deref()),
        |fwd, io, w| solve_inverse(fwd, target, io, w),
        CosseratForward::mesh_error,
    )
}

/// [`inverse_actuation`] and the statics solution at the actuation found (on the mesh of the
/// answer); the position error is that of the solution's tip for a tip target.
///
/// # Errors
/// As [`inverse_actuation`].
pub fn inverse_statics(
    model: &Arc<RobotModel>,
    target: &Target,
    options: &InverseOptions,
    solve: &SolveOptions,
    warm: Option<&InverseWarmStart>,
) -> Result<(InverseSolution, StaticsSolution)> {
    let (mut out, mut fwd) = inverse_resolved(model, target, options, solve, warm)?;
    let sol = match fwd.solution.take() {
        Some(s) if s.tensions() == out.tensions() && s.pressures() == out.pressures() => s,
        _ => fwd.solve(&out.actuation)?,
    };
    if target.s.is_none() {
        // The distance of the tip returned: the iteration's own evaluation may be the
        // closed-form march (`uniform.rs`), equal to the returned solution's to round-off.
        let tip = Vector3::from(sol.tip_position());
        out.position_error = target
            .points
            .iter()
            .map(|p| (tip - p).norm())
            .fold(0.0, f64::max);
    }
    Ok((out, sol))
}
