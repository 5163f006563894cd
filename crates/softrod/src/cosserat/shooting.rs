//! The shooting problem: unknown scaled base wrench, residual the scaled tip conditions.
//!
//! Unknowns `x = [N(0)/F; M(0)/(F L)]` (`F = E I(0)/L²`, world frame, total wrench of rod and
//! tendons), residual `r = [(N(L) - F_tip)/F; (M(L) - M_tip)/(F L)]`, so the tolerance is
//! dimensionless (a residual `ε` leaves a tip error of about `ε L / 3`). One evaluation is one
//! march over the breaks: the state alone for a residual, the state with six variational
//! columns for the exact Jacobian. With a zero base force and no force along the rod, `N ≡ 0`
//! and the Jacobian is known in closed form (`δN(L) = δN(0)`,
//! `δM(L) = δM(0) - (p(L) - p(0)) × δN(0)`), so it costs nothing. The solver sees it as a
//! [`Problem`]; its safeguard compares shapes node by node.
//!
//! Displacement-controlled tendons held taut add their tensions to the unknowns (scaled by
//! `F`) and their slack to the residual: `g_h = ℓ_ref,h - δ_h - ℓ_h + τ_h / k_h`, scaled by the
//! slack a tension `F` causes ([`slack_scale`]); the Jacobian comes from the tension columns
//! and the path-length sensitivities of the linearised problem (`cosserat/sensitivity.rs`).
//! Which held tendons are taut is decided outside, by the active set of
//! `cosserat/displacement.rs`; the tendons that are slack carry zero tension here.

use nalgebra::{Matrix3, UnitQuaternion, Vector3, Vector6};

use super::equations::{
    col_rot, rot, rotation_variation, v3, Column, Equations, Evaluator, Workspace, COLUMN, FULL,
    STATE,
};
use super::sensitivity::{integrate, scheme_of, Request, Seed};
use super::stability::{certifies, tip_stability, JacobiCheck, Stability};
use super::statics::{Integrator, MAX_LOAD_STEP_TURN};
use crate::error::{Error, Result};
use crate::integrate::march::{march, rk4_plan, Scheme};
use crate::math::so3::hat;
use crate::model::loads::Frame;
use crate::solve::{Evaluated, Problem};

/// A recorded mesh node.
#[derive(Clone, Copy)]
pub(crate) struct Node {
    pub s: f64,
    pub interval: usize,
    pub y: [f64; STATE],
}

fn head<const N: usize>(y: &[f64; N]) -> [f64; STATE] {
    let mut h = [0.0; STATE];
    h.copy_from_slice(&y[..STATE]);
    h
}

/// What a pass returns: the scaled residual, its derivative along each column, the chord.
pub(crate) type PassOutput = (Vector6<f64>, Vec<Vector6<f64>>, Vector3<f64>);

/// Round-off of a tendon path length, in units of `ε ℓ` (the floor of a held row's residual):
/// at least this many, and one per RK4 step (the quadrature sums four stage terms a step and
/// the state it reads carries the march's own round-off; measured: up to 33 at 100 steps and
/// 55 at 200 on random loaded robots).
const HELD_ROUND_OFF: f64 = 16.0;

/// A displacement-controlled tendon held taut: an unknown (its tension) and a residual row
/// (its slack).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Held {
    /// The tendon.
    pub tendon: usize,
    /// `ℓ_ref - δ` (m): the path length at which it is just taut at zero tension.
    pub target: f64,
    /// `1 / k` (m/N).
    pub compliance: f64,
    /// Slack per scaled unit of the residual (m).
    pub scale: f64,
}
/// A shape: arc length, position and rotation at the nodes of a pass.
type Shape = Vec<(f64, Vector3<f64>, Matrix3<f64>)>;

/// The unknowns, load factor and exact tip columns of a pass with columns, and the stability
/// they give (computed when first asked).
struct ExactPass {
    x: [f64; 6],
    lambda: f64,
    jacobian: [f64; 36],
    tip_twist: [Vector6<f64>; 6],
    jacobi: JacobiCheck,
    stability: Option<Option<Stability>>,
}

/// The shooting problem of one model and actuation, with its workspace and the nodes of the
/// last pass.
pub(crate) struct Shooting<'a> {
    pub eq: Equations<'a>,
    /// The tendons held taut (unknowns `x[6..]`, residual rows `r[6..]`).
    pub held: Vec<Held>,
    /// Tension of every tendon at the last evaluation (N): `eq.tensions` with the held
    /// tendons' unknowns.
    pub tensions: Vec<f64>,
    pub ws: Workspace,
    pub integrator: Integrator,
    pub plan: Vec<usize>,
    /// Arc lengths (sorted, inside the rod) where every pass puts a node (`s_out`).
    pub stops: Vec<f64>,
    /// Nodes of the last pass (a break appears twice: before and after its jump).
    pub nodes: Vec<Node>,
    /// Tip twist `[δp; δθ]` (m, rad; world) along each base-wrench column of the last pass,
    /// if it integrated the columns (`None` after a pass without them).
    pub tip_twist: Option<[Vector6<f64>; 6]>,
    /// The conjugate points and resolution of the last pass's columns (see [`JacobiCheck`];
    /// clear after a pass without them).
    pub jacobi: JacobiCheck,
    /// The residual's derivative columns (column-major 6×6) of the last pass with columns.
    pub columns: Option<[f64; 36]>,
    /// Whether the continuation's safeguard also refuses an unstable state (judged from the
    /// tip columns of its pass, when it has them; see [`super::stability`]).
    pub require_stable: bool,
    /// Tendon path lengths of the last pass (m).
    pub lengths: Vec<f64>,
    /// Whether a pass integrates the path lengths of the tension-free tendons too (those of
    /// the tensioned ones always are); when not, theirs in [`Self::lengths`] are zero.
    pub passive_lengths: bool,
    /// The exact columns of the last pass with them, the certificate's evidence.
    exact: Option<ExactPass>,
    /// The shape of the committed state, the safeguard's reference.
    reference: Shape,
    /// Right-hand-side evaluations so far.
    pub evaluations: usize,
    /// Subtracted from the tip rows of every residual: a coarse mesh's residual at a nearby
    /// solution on a finer mesh (see `statics::coarse_first`), zero otherwise.
    pub defect: [f64; 6],
    /// The scaled tip residual of the last pass (the tip rows, [`Self::defect`] subtracted).
    pub residual: [f64; 6],
    /// Whether [`Problem::certified`] may answer from the exact columns of an earlier pass
    /// (`false`: the columns at the solution are needed anyway, e.g. on a coarse mesh).
    pub certify: bool,
    /// How many of the next passes with the columns skip the Jacobi check along the rod
    /// (columns only wanted at the tip, e.g. a Newton direction; see [`Self::jacobi_checked`]).
    pub skip_jacobi: usize,
    /// Whether the last pass had its columns checked along the rod ([`Self::jacobi`]): a pass
    /// without is no stability evidence (no certificate is kept from it).
    pub jacobi_checked: bool,
}

impl<'a> Shooting<'a> {
    /// The same equations on the coarse mesh of this problem's integrator
    /// ([`Integrator::coarse`]); `None` where there is none.
    pub fn coarse(&self) -> Option<Shooting<'a>> {
        let coarse = self.integrator.coarse()?;
        let Integrator::Rk4 { steps } = coarse else {
            return None;
        };
        let plan = rk4_plan(self.eq.model.breaks(), steps);
        Some(Shooting::new(self.eq, coarse, plan))
    }

    pub fn new(eq: Equations<'a>, integrator: Integrator, plan: Vec<usize>) -> Self {
        Self::with_workspace(
            eq,
            integrator,
            plan,
            Workspace::new(eq.model.tendons().len()),
        )
    }

    /// [`Self::new`] in the workspace `ws` of an earlier march of the same model's tendons
    /// (every pass starts afresh in it: its quadratures reset, the local solve from the
    /// straight-tendon guess).
    pub fn with_workspace(
        eq: Equations<'a>,
        integrator: Integrator,
        plan: Vec<usize>,
        ws: Workspace,
    ) -> Self {
        Self {
            eq,
            held: Vec::new(),
            tensions: eq.tensions.to_vec(),
            ws,
            integrator,
            plan,
            stops: Vec::new(),
            nodes: Vec::new(),
            tip_twist: None,
            jacobi: JacobiCheck::default(),
            columns: None,
            require_stable: false,
            lengths: Vec::new(),
            passive_lengths: true,
            exact: None,
            reference: Vec::new(),
            evaluations: 0,
            defect: [0.0; 6],
            residual: [0.0; 6],
            certify: true,
            skip_jacobi: 0,
            jacobi_checked: false,
        }
    }

    /// The equations with the tensions of the last evaluation.
    pub fn equations(&self) -> Equations<'_> {
        Equations {
            model: self.eq.model,
            tensions: &self.tensions,
            pressures: self.eq.pressures,
            load_factor: self.eq.load_factor,
            profile: self.eq.profile,
        }
    }

    fn scheme<'p>(integrator: &Integrator, plan: &'p [usize]) -> Scheme<'p> {
        match *integrator {
            Integrator::Rk4 { .. } => Scheme::Rk4(plan),
            Integrator::Adaptive(options) => Scheme::Adaptive {
                options,
                controlled: STATE,
            },
        }
    }

    /// One march from the base with unknowns `x` at load factor `lambda`, recording the
    /// nodes; with `N == FULL` the six base-wrench columns are integrated too. Returns the
    /// scaled residual, its Jacobian columns (empty without columns) and the chord
    /// `p(L) - p(0)`.
    pub fn pass<const N: usize>(&mut self, x: &[f64], lambda: f64) -> Result<PassOutput> {
        self.eq.load_factor = lambda;
        let columns: &[Column] = if N >= FULL { &[Column::Free; 6] } else { &[] };
        self.ws.set_columns(columns, &[]);
        // The tendon lengths ride on the stages (the quadrature the displacement constraints
        // and their sensitivities use).
        self.ws.track_lengths = self.passive_lengths;
        self.nodes.clear();
        let y0: [f64; N] = self.eq.initial(x);
        let scheme = Self::scheme(&self.integrator, &self.plan);
        let breaks = self.eq.model.breaks();
        let eq = Equations {
            model: self.eq.model,
            tensions: &self.tensions,
            pressures: self.eq.pressures,
            load_factor: lambda,
            profile: self.eq.profile,
        };
        let mut ev = Evaluator {
            eq,
            ws: &mut self.ws,
        };
        let nodes = &mut self.nodes;
        let (length, force) = (eq.model.length(), eq.model.force_scale());
        let mut jacobi = JacobiCheck::default();
        let check = N >= FULL && self.skip_jacobi == 0;
        if N >= FULL && !check {
            self.skip_jacobi -= 1;
        }
        let result = march(
            &mut ev,
            breaks,
            &self.stops,
            y0,
            scheme,
            |_, s, interval, y| {
                nodes.push(Node {
                    s,
                    interval,
                    y: head(y),
                });
                if let (true, Ok(full)) = (check, <&[f64; FULL]>::try_from(&y[..])) {
                    let rod = eq.model.rod();
                    let c = match eq.model.uniform_compliance() {
                        Some(c) => *c,
                        None => rod.material().compliance(
                            &rod.section_at(s),
                            rod.shear_coefficient(),
                            rod.inextensible(),
                        ),
                    };
                    jacobi.node(s, full, (length, force), c[3].max(c[4]));
                }
            },
        );
        self.jacobi = jacobi;
        self.jacobi_checked = check;
        self.evaluations += std::mem::take(&mut self.ws.evaluations);
        self.tip_twist = None;
        let y = result?;
        if !y[..STATE].iter().all(|v| v.is_finite()) {
            return Err(Error::not_converged(
                "rod integration: non-finite state",
                0,
                f64::INFINITY,
            ));
        }
        let nt = self.eq.model.tendons().len();
        self.lengths.clear();
        self.lengths.extend_from_slice(&self.ws.integral[..nt]);
        let (mut r, cols) = eq.residual(&y, columns.len());
        for k in 0..6 {
            r[k] -= self.defect[k];
            self.residual[k] = r[k];
        }
        self.columns = None;
        if N >= FULL {
            let mut j = [0.0; 36];
            for (c, col) in cols.iter().enumerate() {
                j[6 * c..6 * c + 6].copy_from_slice(col.as_slice());
            }
            self.columns = Some(j);
            let rt = rot(&y);
            let tw = std::array::from_fn(|k| {
                let b = STATE + COLUMN * k;
                let (dp, w) = (v3(&y, b), rotation_variation(&rt, &col_rot(&y, b)));
                Vector6::new(dp.x, dp.y, dp.z, w.x, w.y, w.z)
            });
            self.tip_twist = Some(tw);
            if check {
                self.exact = Some(ExactPass {
                    x: std::array::from_fn(|k| x[k]),
                    lambda,
                    jacobian: j,
                    tip_twist: tw,
                    jacobi: self.jacobi,
                    stability: None,
                });
            }
        }
        let chord = v3(&y, 0) - eq.model.rod().base_pose().position();
        Ok((r, cols, chord))
    }

    /// [`Problem::evaluate`] with held tendons: unknowns `[x (6); τ_h / F]`, residual
    /// `[tip (6); g_h / scale_h]`.
    fn evaluate_held(
        &mut self,
        z: &[f64],
        lambda: f64,
        jacobian: Option<&mut [f64]>,
        r: &mut [f64],
    ) -> Evaluated {
        let f_ref = self.eq.model.force_scale();
        let nh = self.held.len();
        for (h, held) in self.held.iter().enumerate() {
            self.tensions[held.tendon] = z[6 + h] * f_ref;
        }
        let x = [z[0], z[1], z[2], z[3], z[4], z[5]];
        let Some(j) = jacobian else {
            let Ok((res, _, _)) = self.pass::<STATE>(&x, lambda) else {
                return Evaluated::Failed;
            };
            r[..6].copy_from_slice(res.as_slice());
            for (h, held) in self.held.iter().enumerate() {
                let g =
                    held.target - self.lengths[held.tendon] + held.compliance * z[6 + h] * f_ref;
                r[6 + h] = g / held.scale;
            }
            return if r.iter().all(|v| v.is_finite()) {
                Evaluated::Residual
            } else {
                Evaluated::Failed
            };
        };
        self.eq.load_factor = lambda;
        let seeds: Vec<Seed> = (0..6)
            .map(Seed::Base)
            .chain(
                self.held
                    .iter()
                    .map(|h| Seed::Forced(Column::Tension(h.tendon))),
            )
            .collect();
        let lengths: Vec<usize> = self.held.iter().map(|h| h.tendon).collect();
        let mut plan = Vec::new();
        let scheme = scheme_of(&self.integrator, self.eq.model, &mut plan);
        let eq = Equations {
            model: self.eq.model,
            tensions: &self.tensions,
            pressures: self.eq.pressures,
            load_factor: lambda,
            profile: self.eq.profile,
        };
        let req = Request {
            seeds: &seeds,
            lengths: &lengths,
            observe: &[],
            load_node: None,
            record_nodes: true,
            stops: &[],
        };
        let Ok(cols) = integrate(eq, scheme, &x, &req) else {
            return Evaluated::Failed;
        };
        self.evaluations += cols.evaluations;
        self.nodes = cols.nodes;
        self.lengths = cols.lengths;
        r[..6].copy_from_slice(cols.residual.as_slice());
        let dim = 6 + nh;
        for (h, held) in self.held.iter().enumerate() {
            let g = held.target - self.lengths[held.tendon] + held.compliance * z[6 + h] * f_ref;
            r[6 + h] = g / held.scale;
        }
        for c in 0..dim {
            let unit = if c < 6 { 1.0 } else { f_ref };
            for row in 0..6 {
                j[c * dim + row] = cols.d_residual[c][row] * unit;
            }
            for (h, held) in self.held.iter().enumerate() {
                let mut d = -cols.d_lengths[c][h];
                if c == 6 + h {
                    d += held.compliance;
                }
                j[c * dim + 6 + h] = d * unit / held.scale;
            }
        }
        if r.iter().chain(j.iter()).all(|v| v.is_finite()) {
            Evaluated::Jacobian
        } else {
            Evaluated::Failed
        }
    }

    /// The stability certified at `x` (load factor `lambda`) by the exact columns of the last
    /// pass with them ([`certifies`]), and that pass's shooting Jacobian (column-major).
    pub fn certificate(&mut self, x: &[f64], lambda: f64) -> Option<(Stability, [f64; 36])> {
        if !self.held.is_empty() || x.len() != 6 {
            return None;
        }
        let length = self.eq.model.length();
        let e = self.exact.as_mut().filter(|e| e.lambda == lambda)?;
        let s = (*e
            .stability
            .get_or_insert_with(|| tip_stability(&e.jacobian, &e.tip_twist, length, e.jacobi)))?;
        let distance = (0..6).map(|k| (x[k] - e.x[k]).abs()).fold(0.0, f64::max);
        certifies(&s, distance).then_some((s, e.jacobian))
    }

    /// Arc lengths, positions and rotations at the nodes of the last pass.
    fn shape(&self) -> Shape {
        self.nodes
            .iter()
            .map(|n| (n.s, v3(&n.y, 0), rot(&n.y)))
            .collect()
    }
}

/// The pose of `shape` at `s`: linear in position, normalised linear in the quaternion of
/// the rotation between the two nodes around `s` (the node itself if `s` is one).
fn pose_at(shape: &Shape, s: f64) -> (Vector3<f64>, Matrix3<f64>) {
    let j = shape.partition_point(|n| n.0 < s).min(shape.len() - 1);
    if j == 0 || shape[j].0 == s {
        return (shape[j].1, shape[j].2);
    }
    let (a, b) = (&shape[j - 1], &shape[j]);
    let t = ((s - a.0) / (b.0 - a.0)).clamp(0.0, 1.0);
    let qa = UnitQuaternion::from_matrix(&a.2);
    let qb = UnitQuaternion::from_matrix(&b.2);
    let q = qa.nlerp(&qb, t);
    (a.1 + (b.1 - a.1) * t, *q.to_rotation_matrix().matrix())
}

/// Whether two shapes differ by at most [`MAX_LOAD_STEP_TURN`] in rotation (rad) and
/// `MAX_LOAD_STEP_TURN L / 2` in position at every node: node by node on a common mesh (RK4),
/// else at the nodes of `b`, `a` interpolated there (adaptive meshes differ between passes).
fn shape_change_is_small(a: &Shape, b: &Shape, length: f64) -> bool {
    let close = |(p0, r0): (Vector3<f64>, Matrix3<f64>), (p1, r1): (Vector3<f64>, Matrix3<f64>)| {
        let c = ((r0.tr_mul(&r1).trace() - 1.0) * 0.5).clamp(-1.0, 1.0);
        c.acos() <= MAX_LOAD_STEP_TURN && (p1 - p0).norm() <= 0.5 * MAX_LOAD_STEP_TURN * length
    };
    if a.is_empty() || b.is_empty() {
        return false;
    }
    if a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.0 == y.0) {
        a.iter().zip(b).all(|(x, y)| close((x.1, x.2), (y.1, y.2)))
    } else {
        b.iter().all(|y| close(pose_at(a, y.0), (y.1, y.2)))
    }
}

impl Problem for Shooting<'_> {
    fn dim(&self) -> usize {
        6 + self.held.len()
    }

    fn evaluate(
        &mut self,
        x: &[f64],
        lambda: f64,
        jacobian: Option<&mut [f64]>,
        r: &mut [f64],
    ) -> Evaluated {
        if !self.held.is_empty() {
            return self.evaluate_held(x, lambda, jacobian, r);
        }
        // N ≡ 0 along the rod: the Jacobian in closed form from a pass without columns.
        let analytic =
            x[..3].iter().all(|v| *v == 0.0) && (self.eq.model.force_free() || lambda == 0.0);
        let full = jacobian.is_some() && !analytic;
        let pass = if full {
            self.pass::<FULL>(x, lambda)
        } else {
            self.pass::<STATE>(x, lambda)
        };
        let Ok((res, cols, chord)) = pass else {
            return Evaluated::Failed;
        };
        r.copy_from_slice(res.as_slice());
        if !r.iter().all(|v| v.is_finite()) {
            return Evaluated::Failed;
        }
        let Some(j) = jacobian else {
            return Evaluated::Residual;
        };
        j.fill(0.0);
        if full {
            for (c, col) in cols.iter().enumerate() {
                j[6 * c..6 * c + 6].copy_from_slice(col.as_slice());
            }
        } else {
            for k in 0..6 {
                j[7 * k] = 1.0;
            }
            let h = hat(&chord) / self.eq.model.length();
            for a in 0..3 {
                for b in 0..3 {
                    j[(3 + a) + 6 * b] = -h[(a, b)];
                }
            }
        }
        Evaluated::Jacobian
    }

    fn tolerance(&self, x: &[f64], tolerance: f64) -> f64 {
        // A held row resolves its slack to the round-off of the path length.
        let units = match self.integrator {
            Integrator::Rk4 { steps } => HELD_ROUND_OFF.max(steps as f64),
            Integrator::Adaptive(_) => HELD_ROUND_OFF,
        };
        let tolerance = self.held.iter().fold(tolerance, |t, h| {
            t.max(units * f64::EPSILON * h.target.abs() / h.scale)
        });
        match self.integrator {
            Integrator::Rk4 { .. } => tolerance,
            Integrator::Adaptive(a) => {
                let amax = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                tolerance.max(10.0 * a.rtol * (1.0 + amax))
            }
        }
    }

    fn stops_at_round_off(&self) -> bool {
        // The fixed mesh makes the residual smooth in the unknowns and the columns its exact
        // Jacobian; the adaptive integrator's residual carries its error control instead.
        matches!(self.integrator, Integrator::Rk4 { .. })
    }

    fn load_derivative(&mut self, x: &[f64], lambda: f64, out: &mut [f64]) -> bool {
        if !self.held.is_empty() {
            // The held rows change with the shape: a secant predictor.
            return false;
        }
        if let Some(d) = self.eq.load_derivative_force_free() {
            out.copy_from_slice(d.as_slice());
            return true;
        }
        // At the unloaded equilibrium (N ≡ 0) every external load acts on the shape of the
        // last pass: ∂N(L)/∂λ is the total force and ∂M(L)/∂λ their moment about the tip.
        if !(lambda == 0.0 && x.iter().all(|v| *v == 0.0) && !self.nodes.is_empty()) {
            return false;
        }
        let model = self.eq.model;
        let loads = model.loads();
        let rod = model.rod();
        let tip = v3(&self.nodes[self.nodes.len() - 1].y, 0);
        let (mut fsum, mut msum) = (Vector3::zeros(), Vector3::zeros());
        let load_at = |s: f64| -> (Vector3<f64>, Vector3<f64>) {
            let mut f = loads
                .distributed_force
                .as_ref()
                .map_or(Vector3::zeros(), |p| p.at(s));
            if let Some(g) = model.rho_g() {
                f += g * rod.section_at(s).area;
            }
            let l = loads
                .distributed_moment
                .as_ref()
                .map_or(Vector3::zeros(), |p| p.at(s));
            (f, l)
        };
        // Trapezoid rule over the nodes of each interval.
        for w in self.nodes.windows(2) {
            if w[0].interval != w[1].interval || w[1].s <= w[0].s {
                continue;
            }
            let h = w[1].s - w[0].s;
            for n in w {
                let (f, l) = load_at(n.s);
                let p = v3(&n.y, 0);
                fsum += f * (0.5 * h);
                msum += ((tip - p).cross(&f) + l) * (0.5 * h);
            }
        }
        for pl in &loads.point_loads {
            let Some(n) = self.nodes.iter().find(|n| n.s == pl.s) else {
                return false;
            };
            let (f, m) = match pl.frame {
                Frame::World => (pl.force, pl.moment),
                Frame::Body => (rot(&n.y) * pl.force, rot(&n.y) * pl.moment),
            };
            fsum += f;
            msum += (tip - v3(&n.y, 0)).cross(&f) + m;
        }
        let rt = rot(&self.nodes[self.nodes.len() - 1].y);
        let (ft, mt) = match loads.tip_frame {
            Frame::World => (loads.tip_force, loads.tip_moment),
            Frame::Body => (rt * loads.tip_force, rt * loads.tip_moment),
        };
        let f_ref = model.force_scale();
        let fm = f_ref * model.length();
        let dn = -(fsum + ft) / f_ref;
        let dm = -(msum + mt) / fm;
        out.copy_from_slice(&[dn.x, dn.y, dn.z, dm.x, dm.y, dm.z]);
        out.iter().all(|v| v.is_finite())
    }

    fn certified(&mut self, x: &[f64], lambda: f64) -> bool {
        self.certify && self.certificate(x, lambda).is_some()
    }

    fn commit(&mut self) {
        self.reference = self.shape();
    }

    fn close(&self) -> bool {
        let length = self.eq.model.length();
        if self.reference.is_empty()
            || !shape_change_is_small(&self.reference, &self.shape(), length)
        {
            return false;
        }
        match (self.require_stable, &self.columns, &self.tip_twist) {
            (true, Some(j), Some(tw)) if self.jacobi_checked => {
                tip_stability(j, tw, length, self.jacobi).is_some_and(|s| s.stable)
            }
            _ => true,
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use std::f64::consts::PI;

    use nalgebra::Vector3;

    use super::*;
    use crate::model::chamber::{Chamber, ChamberArea};
    use crate::model::loads::{Frame, Loads, PointLoad};
    use crate::model::material::hyperelastic::UniaxialModel;
    use crate::model::material::silicone::Silicone;
    use crate::model::rod::Rod;
    use crate::model::section::Section;
    use crate::model::tendon::Tendon;
    use crate::model::RobotModel;

    /// The exact shooting Jacobian (variational columns) against central differences of the
    /// residual, on a hyperelastic tube with a tendon, two chambers, a follower point load and
    /// a tip wrench, away from equilibrium.
    #[test]
    fn shooting_jacobian_is_exact_for_a_hyperelastic_rod_with_chambers() {
        let rod = Rod::new(
            0.16,
            Section::tube(0.012, 0.002).unwrap(),
            UniaxialModel::from(Silicone::DragonSkin10.yeoh()),
        )
        .unwrap();
        let ac = PI * 0.0025f64.powi(2);
        let tendons = vec![Tendon::constant([0.008, 0.0], Some(0.12)).unwrap()];
        let chambers = vec![
            Chamber::new(ChamberArea::Constant(ac), [0.0, 0.0072], 0.0, None).unwrap(),
            Chamber::new(
                ChamberArea::Constant(ac),
                [0.0072 * (-30f64).to_radians().cos(), -0.0036],
                0.03,
                Some(0.13),
            )
            .unwrap(),
        ];
        let loads = Loads {
            tip_force: Vector3::new(0.1, -0.05, 0.2),
            tip_moment: Vector3::new(0.0, 2e-3, 1e-3),
            point_loads: vec![PointLoad {
                s: 0.1,
                force: Vector3::new(0.0, 0.1, 0.0),
                moment: Vector3::zeros(),
                frame: Frame::Body,
            }],
            ..Default::default()
        };
        let model = RobotModel::new(rod, tendons, chambers, loads).unwrap();
        let (tensions, pressures) = ([2.0], [60e3, 30e3]);
        let eq = Equations::new(&model, &tensions, &pressures);
        let plan = crate::integrate::march::rk4_plan(model.breaks(), 40 * 6);
        let mut p = Shooting::new(eq, Integrator::Rk4 { steps: 240 }, plan);
        let x = [0.3, -0.2, 0.5, 0.1, -0.15, 0.05];
        let mut r = [0.0; 6];
        let mut jac = [0.0; 36];
        assert_eq!(
            p.evaluate(&x, 1.0, Some(&mut jac), &mut r),
            Evaluated::Jacobian
        );
        let h = 1e-6;
        let mut err = 0.0f64;
        let scale = jac.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for j in 0..6 {
            let (mut xp, mut xm) = (x, x);
            xp[j] += h;
            xm[j] -= h;
            let (mut rp, mut rm) = ([0.0; 6], [0.0; 6]);
            p.evaluate(&xp, 1.0, None, &mut rp);
            p.evaluate(&xm, 1.0, None, &mut rm);
            for i in 0..6 {
                let fd = (rp[i] - rm[i]) / (2.0 * h);
                err = err.max((fd - jac[i + 6 * j]).abs() / scale);
            }
        }
        assert!(err < 1e-6, "relative Jacobian error {err:e}");
        assert!(p.ws.material_error.is_none());
    }
}

#[cfg(test)]
mod taper_tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::model::loads::Loads;
    use crate::model::material::LinearElastic;
    use crate::model::rod::Rod;
    use crate::model::section::Section;
    use crate::model::tendon::Tendon;
    use crate::model::RobotModel;

    /// On a soft tapered rod bent by two tendons (27 times the base curvature at the thin
    /// end), the integrated columns are the derivative of the discrete march: central
    /// differences of the residual agree to round-off at 40 RK4 steps (a rotation variation
    /// `w` with `δR = R ŵ` differs from it by 5e-6, the truncation error of RK4).
    #[test]
    fn columns_are_the_derivative_of_the_discrete_march_on_a_taper() {
        let sec = Section::tapered_circular(0.015625, 0.0068359375).unwrap();
        let rod = Rod::new(0.5, sec, LinearElastic::new(51614.7, 0.49).unwrap()).unwrap();
        let tendons = vec![Tendon::constant([0.00341796875, 0.0], None).unwrap(); 2];
        let model = RobotModel::new(rod, tendons, vec![], Loads::default()).unwrap();
        let tensions = [0.7069281979685804; 2];
        let eq = Equations::new(&model, &tensions, &[]);
        let plan = crate::integrate::march::rk4_plan(model.breaks(), 40);
        let mut p = Shooting::new(eq, Integrator::Rk4 { steps: 40 }, plan);
        let x = [0.01, -0.02, 0.03, 0.01, -0.015, 0.005];
        let (_, cols, _) = p.pass::<FULL>(&x, 1.0).unwrap();
        let h = 1e-6;
        let mut err = 0.0f64;
        for j in 0..6 {
            let (mut xp, mut xm) = (x, x);
            xp[j] += h;
            xm[j] -= h;
            let (rp, _, _) = p.pass::<STATE>(&xp, 1.0).unwrap();
            let (rm, _, _) = p.pass::<STATE>(&xm, 1.0).unwrap();
            for i in 0..6 {
                err = err.max(((rp[i] - rm[i]) / (2.0 * h) - cols[j][i]).abs());
            }
        }
        assert!(err < 1e-9, "Jacobian error {err:e}");
    }
}
