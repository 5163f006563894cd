//! Capstan friction between the tendons and their channels, with stick and slip.
//!
//! A tendon with friction coefficient `μ` ([`crate::Tendon::with_friction`]) carries a tension that
//! varies along its path: where it slides, `|dτ/dσ| = μ τ κ_path` (σ the path's arc length,
//! `κ_path` its curvature), the tension decreasing away from the side it slides toward; where
//! it sticks, `|dτ/dσ| <= μ τ κ_path`. Along the rod's arc length `s`, `κ_path dσ = |dt_i|` is
//! the turning of the path tangent `t_i`, so over a mesh cell of turning angle `Δθ`:
//!
//! ```text
//! τ_{k+1} ∈ [τ_k e^(−μ Δθ), τ_k e^(+μ Δθ)],
//! ```
//!
//! the lower end when the element slides toward the base (loading: pulled at the base), the
//! upper end when it slides toward the tip (unloading), and anywhere inside when it sticks.
//! On an arc the cell rule is the exact capstan law; at a kink of the path (where a tendon of
//! another segment ends) it is the capstan law of a guide of that wrap angle.
//!
//! **History.** Without a previous state every element slides toward the base (a first
//! loading from rest). With a previous state `τ_prev` on the same mesh, an element keeps its
//! previous tension (sticks) if that tension is admissible, and otherwise slides, the
//! tension clamped to the nearer end of the admissible interval:
//! `τ_{k+1} = clamp(τ_prev,k+1, τ_k e^(−μΔθ), τ_k e^(+μΔθ))`. A sticking element keeps its
//! tension because the tendon is taken inextensible (its own elasticity is not modelled).
//!
//! **Coupling with the rod.** The rod equations are in total-wrench form (see
//! `cosserat::equations`): the friction force is internal to rod + tendons, so the
//! balance `N' = −f`, `M' = −p' × N − l` holds unchanged and only the tension profile enters
//! the constitutive split `n = N − Σ τ_i(s) t_i`. The rod therefore receives from each tendon
//! the distributed load `d(τ_i t_i)/ds = τ_i t_i' + τ_i' t_i` (normal load plus the friction
//! force, opposite to the friction on the tendon) and, at the termination, the point force
//! `−τ_i(σ) t_i(σ)` with the local tension. The shape and the profile are found together in
//! one march with the tension a state (`friction_march`): without external loads at the known
//! zero base wrench, with them at every iterate of a quasi-Newton iteration on the base
//! wrench. The independent formulation, and the fallback when that iteration fails, is a
//! fixed point: solve the rod for the current profile (interpolated geometrically between the
//! mesh nodes), recompute the profile from the shape, until the tension changes by less than
//! [`FrictionOptions::tolerance`] relative to the largest base tension.

use std::sync::Arc;

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

pub use super::friction_march::MAX_CELL_ATTEMPTS;
use super::friction_march::{solve_marched, Setup};
pub use super::guides::{GuideMethod, GuideState, GUIDE_FIXED_POINT_BUDGET, GUIDE_FORCE_TOLERANCE};
use crate::cosserat::equations::{Equations, Evaluator, Workspace, STATE};
use crate::cosserat::statics::{
    interior, scaled, solve_statics_at, Integrator, SolveOptions, StaticsSolution,
    DEFAULT_RK4_STEPS,
};
use crate::error::{Error, Result};
use crate::integrate::march::{march, Scheme};
use crate::model::actuation::TensionProfile;
use crate::model::tendon::Tendon;
use crate::model::{Actuation, RobotModel};

/// Default relative tolerance of the fixed point on the tension profile.
pub const DEFAULT_FRICTION_TOLERANCE: f64 = 1e-9;
/// Default cap on the fixed-point iterations.
pub const DEFAULT_FRICTION_ITERATIONS: usize = 200;
/// Mesh nodes per interval between breaks with the adaptive integrator.
pub const ADAPTIVE_FRICTION_NODES: usize = 32;
/// Offset (relative to the rod length) of the node placed just before every interior break,
/// where the path kinks and tendons end.
pub const BREAK_OFFSET: f64 = 1e-9;

/// Relative change of an element's tension from its previous state below which it is
/// reported sticking (the tension itself is always clamped exactly).
pub const STICK_TOLERANCE: f64 = 1e-9;

/// Options of the frictional solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionOptions {
    /// The rod solve (integrator, Newton options).
    pub statics: SolveOptions,
    /// Relative change of the tension profile (to the largest base tension) that ends the
    /// fixed point.
    pub tolerance: f64,
    /// Cap on the fixed-point iterations.
    pub max_iterations: usize,
    /// Solve in one march with the tension as a state (default `true`; with external loads,
    /// one march per quasi-Newton iterate of the base wrench, the fixed point if that
    /// iteration fails); `false`: by the fixed point on the profile (the same discrete
    /// equations, an independent solve of them).
    pub single_march: bool,
    /// How disk-guided tendons are solved (default [`GuideMethod::Auto`]: the guide fixed
    /// point first, Newton on the guide forces if it does not settle).
    pub guide_method: GuideMethod,
}

impl Default for FrictionOptions {
    fn default() -> Self {
        Self {
            statics: SolveOptions::default(),
            tolerance: DEFAULT_FRICTION_TOLERANCE,
            max_iterations: DEFAULT_FRICTION_ITERATIONS,
            single_march: true,
            guide_method: GuideMethod::Auto,
        }
    }
}

/// The sliding state of a tendon element.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Slip {
    /// Sliding toward the base (the tension decreases toward the tip): loading.
    Loading,
    /// Sliding toward the tip (the tension increases toward the tip): unloading.
    Unloading,
    /// Sticking: the element keeps its previous tension.
    Stick,
    /// No tendon there (beyond its termination).
    Absent,
}

impl Slip {
    /// `+1` loading, `-1` unloading, `0` sticking or absent.
    pub fn sign(self) -> i8 {
        match self {
            Slip::Loading => 1,
            Slip::Unloading => -1,
            Slip::Stick | Slip::Absent => 0,
        }
    }
}

/// A frictional equilibrium: the rod solution at the friction mesh and, per node and tendon,
/// the tension, the slip state, the path tangent and the friction force on the rod.
#[derive(Debug, Clone)]
pub struct FrictionalSolution {
    /// The rod's solution, at the nodes of the friction mesh ([`friction_mesh`], or the one
    /// the adaptive integrator chose: `cosserat::friction_mesh`); its actuation carries the
    /// tension profile.
    pub statics: StaticsSolution,
    /// Tension (N) per node and tendon, `[node][tendon]`; `0` beyond a tendon's termination.
    pub tension: Vec<Vec<f64>>,
    /// Slip state per node and tendon.
    pub slip: Vec<Vec<Slip>>,
    /// Unit tangent of each tendon's path (world) per node; zero beyond its termination.
    pub tangent: Vec<Vec<[f64; 3]>>,
    /// Friction force on the rod per unit length of rod (N/m, world), `τ_i'(s) t_i`, per node
    /// and tendon (the normal load `τ_i t_i'` is not included).
    pub friction_force: Vec<Vec<[f64; 3]>>,
    /// Path length (m) of each tendon from the base to each node, `[node][tendon]` (the
    /// whole path length beyond its termination), from the integrator's quadrature. The
    /// tendon being inextensible and anchored at its termination, its slip toward the base
    /// at a node between two states is the change of `path length − path_length[node]`.
    pub path_length: Vec<Vec<f64>>,
    /// Per tendon, the states at its anchors (base hole, guides, termination) for a tendon
    /// routed through guides ([`crate::Tendon::with_guides`]); empty for a tendon in a
    /// continuous channel.
    pub guides: Vec<Vec<GuideState>>,
    /// Marches: 1 for an unloaded model, one per quasi-Newton iterate of a loaded one; the
    /// rod solves of the fixed point when it was used (summed over the rod solves of the
    /// guide fixed point with guided tendons; over the meshes the adaptive integrator tried).
    pub iterations: usize,
    /// Integration steps over the cells of the friction mesh, all rod solves and repeated
    /// cells together (a rod solve without friction takes one per cell and Newton iteration;
    /// over the meshes the adaptive integrator tried).
    pub cell_steps: usize,
    /// Last relative change of the profile.
    pub change: f64,
}

impl FrictionalSolution {
    /// Tip position (m, world).
    pub fn tip_position(&self) -> [f64; 3] {
        self.statics.tip_position()
    }

    /// Whether the stability of this equilibrium is assessed: false while a tendon pulls
    /// through disk guides, whose rod is solved under the guide forces held in the guides'
    /// frames (`statics.stable` then judges that rod, not the guided robot: the chords' own
    /// stiffness is left out; see `docs/friction.md`).
    pub fn stability_assessed(&self) -> bool {
        !self
            .guides
            .iter()
            .any(|row| row.first().is_some_and(|g| g.tension_in > 0.0))
    }
}

/// The nodes of the friction mesh of `model` (m): with RK4 the nodes of its steps, with the
/// adaptive integrator [`ADAPTIVE_FRICTION_NODES`] per interval, plus a node
/// [`BREAK_OFFSET`] `L` before every interior break (the end of the tendons there and the
/// path before its kink).
pub fn friction_mesh(model: &RobotModel, integrator: &Integrator) -> Vec<f64> {
    let breaks = model.breaks();
    let l = model.length();
    let per: Vec<usize> = match integrator {
        Integrator::Rk4 { steps } => crate::integrate::march::rk4_plan(breaks, *steps),
        Integrator::Adaptive(_) => vec![ADAPTIVE_FRICTION_NODES; breaks.len() - 1],
    };
    let mut mesh = Vec::new();
    for (k, w) in breaks.windows(2).enumerate() {
        let (a, b) = (w[0], w[1]);
        let n = per[k].max(1);
        for j in 0..n {
            mesh.push(a + (b - a) * j as f64 / n as f64);
        }
        if k + 2 < breaks.len() {
            let before = b - BREAK_OFFSET * l;
            if before > mesh[mesh.len() - 1] {
                mesh.push(before);
            }
        }
    }
    mesh.push(l);
    mesh
}

/// Per node and tendon: the unit path tangent (world) and whether the tendon is there.
fn tangents(model: &RobotModel, sol: &StaticsSolution) -> Vec<Vec<Option<Vector3<f64>>>> {
    sol.s
        .iter()
        .enumerate()
        .map(|(j, &s)| {
            let r = Matrix3::from_fn(|a, b| sol.rotation[j][a][b]);
            node_tangents(
                model,
                s,
                &r,
                &Vector3::from(sol.v[j]),
                &Vector3::from(sol.u[j]),
            )
        })
        .collect()
}

/// Per tendon, the unit path tangent (world) at `s` of a section of rotation `r` and strains
/// `(v, u)`, `None` where the tendon is not there (beyond its termination).
pub(super) fn node_tangents(
    model: &RobotModel,
    s: f64,
    r: &Matrix3<f64>,
    v: &Vector3<f64>,
    u: &Vector3<f64>,
) -> Vec<Option<Vector3<f64>>> {
    let l = model.length();
    let ends = model.tendon_ends();
    let props = model.rod().section_at(s);
    model
        .tendons()
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let present = s < ends[i] || (ends[i] == l && s == l);
            present.then(|| {
                let (o, op) = t.routing().offset(s, &props);
                let w =
                    v + u.cross(&Vector3::new(o[0], o[1], 0.0)) + Vector3::new(op[0], op[1], 0.0);
                (r * w).normalize()
            })
        })
        .collect()
}

/// The tangents per node and tendon as arrays (zero where the tendon is not there).
pub(super) fn tangent_rows(dirs: &[Vec<Option<Vector3<f64>>>]) -> Vec<Vec<[f64; 3]>> {
    dirs.iter()
        .map(|row| {
            row.iter()
                .map(|t| t.map_or([0.0; 3], |t| [t.x, t.y, t.z]))
                .collect()
        })
        .collect()
}

/// The angle (rad) between two unit vectors.
pub(super) fn angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// The slip state at the base of a tendon pulled with `base` (N) after `previous` (N; `None`:
/// from rest).
pub(super) fn base_slip(base: f64, previous: Option<f64>) -> Slip {
    match previous {
        None => Slip::Loading,
        Some(q) if (base - q).abs() <= STICK_TOLERANCE * q => Slip::Stick,
        Some(q) if base > q => Slip::Loading,
        Some(_) => Slip::Unloading,
    }
}

/// The capstan rule of one cell: the tension (N) at its distal node from the tension `tau` at
/// its proximal node, `mu_theta = μ Δθ` over the cell and the previous tension `q` at the
/// distal node (`None`: from rest, sliding toward the base); an element within rounding of
/// its previous tension sticks.
pub(super) fn cell_rule(tau: f64, mu_theta: f64, q: Option<f64>) -> (f64, Slip) {
    let g = mu_theta.exp();
    let (lo, hi) = (tau / g, tau * g);
    match q {
        None => (lo, Slip::Loading),
        Some(q) => {
            let t = q.max(lo).min(hi);
            if (t - q).abs() <= STICK_TOLERANCE * q {
                (t, Slip::Stick)
            } else if q > hi {
                (t, Slip::Unloading)
            } else {
                (t, Slip::Loading)
            }
        }
    }
}

/// The capstan rule on the shape `sol`: the tension and slip state per node and tendon.
fn profile_on(
    model: &RobotModel,
    sol: &StaticsSolution,
    dirs: &[Vec<Option<Vector3<f64>>>],
    base: &[f64],
    previous: Option<&[Vec<f64>]>,
) -> (Vec<Vec<f64>>, Vec<Vec<Slip>>) {
    let n = sol.s.len();
    let nt = base.len();
    let mut tau = vec![vec![0.0; nt]; n];
    let mut slip = vec![vec![Slip::Absent; nt]; n];
    for i in 0..nt {
        let mu = model.tendons()[i].friction();
        tau[0][i] = base[i];
        slip[0][i] = base_slip(base[i], previous.map(|p| p[0][i]));
        for j in 1..n {
            let (Some(ta), Some(tb)) = (&dirs[j - 1][i], &dirs[j][i]) else {
                break;
            };
            let q = previous.map(|p| p[j][i]);
            (tau[j][i], slip[j][i]) = cell_rule(tau[j - 1][i], mu * angle(ta, tb), q);
        }
    }
    (tau, slip)
}

/// The tension profile of the frictional tendons (the others carry their base tension).
pub(super) fn to_profile(model: &RobotModel, s: &[f64], tau: &[Vec<f64>]) -> TensionProfile {
    let nt = model.tendons().len();
    let ends = model.tendon_ends();
    let l = model.length();
    TensionProfile::new(
        (0..nt)
            .map(|i| {
                (model.tendons()[i].friction() > 0.0).then(|| {
                    let (mut nodes, mut vals) = (Vec::new(), Vec::new());
                    for (j, &sj) in s.iter().enumerate() {
                        if sj < ends[i] || (ends[i] == l && sj == l) {
                            nodes.push(sj);
                            vals.push(tau[j][i]);
                        }
                    }
                    (nodes, vals)
                })
            })
            .collect(),
    )
}

/// The relative change between two profiles.
fn change(a: &[Vec<f64>], b: &[Vec<f64>], scale: f64) -> f64 {
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
        / scale
}

/// Checks the options and the actuation of a frictional solve.
fn check_inputs(
    model: &RobotModel,
    actuation: &Actuation,
    options: &FrictionOptions,
) -> Result<()> {
    if !(options.tolerance.is_finite() && options.tolerance > 0.0) {
        return Err(Error::invalid(
            "friction.tolerance",
            options.tolerance,
            "finite and > 0",
        ));
    }
    if options.max_iterations == 0 {
        return Err(Error::invalid("friction.max_iterations", 0, ">= 1"));
    }
    model.check_actuation(actuation)?;
    Ok(())
}

/// Every tendon at its base tension over its length, 0 beyond (per node and tendon).
pub(super) fn base_profile(model: &RobotModel, mesh: &[f64], base: &[f64]) -> Vec<Vec<f64>> {
    let (ends, l) = (model.tendon_ends(), model.length());
    mesh.iter()
        .map(|&s| {
            (0..base.len())
                .map(|i| {
                    if s < ends[i] || (ends[i] == l && s == l) {
                        base[i]
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect()
}

/// The tension profile of `previous`, checked to be on `mesh` with `nt` tendons.
fn previous_profile<'p>(
    previous: Option<&'p FrictionalSolution>,
    mesh: &[f64],
    nt: usize,
) -> Result<Option<&'p [Vec<f64>]>> {
    let Some(p) = previous else {
        return Ok(None);
    };
    if p.tension.len() != mesh.len() || p.tension.first().map_or(0, Vec::len) != nt {
        return Err(wrong_previous(p, mesh.len(), nt));
    }
    Ok(Some(p.tension.as_slice()))
}

/// The error of a `previous` state that is not of this robot and integrator (`nodes` on its
/// mesh, `nt` tendons).
fn wrong_previous(p: &FrictionalSolution, nodes: usize, nt: usize) -> Error {
    Error::invalid(
        "previous",
        format!("a solution on {} nodes", p.statics.s.len()),
        format!(
            "a frictional solution of the same robot and integrator ({nodes} nodes, {nt} tendons)"
        ),
    )
}

/// [`solve_frictional`] under the mesh control of a forward solve
/// ([`with_mesh_control`](super::mesh::with_mesh_control)): on the default RK4 mesh, a
/// shape it does not resolve is solved again on a finer one, from the same history (carried
/// onto it: the profile of `previous` read at its nodes as the solve reads it); a `previous`
/// state on a finer RK4 mesh (one this control chose) sets the mesh.
///
/// # Errors
/// As [`solve_frictional`]; [`Error::InvalidParameter`] naming `steps` for a chosen mesh that
/// cannot resolve the shape.
pub fn solve_frictional_checked(
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &FrictionOptions,
    previous: Option<&FrictionalSolution>,
) -> Result<FrictionalSolution> {
    let default = options.statics.integrator.is_default_mesh();
    let mut statics = options.statics;
    if let Some(Integrator::Rk4 { steps }) = previous.map(|p| p.statics.options.integrator) {
        if default && steps > DEFAULT_RK4_STEPS {
            statics.integrator = Integrator::Rk4 { steps };
        }
    }
    super::mesh::with_mesh_control(
        &statics,
        default,
        |o| {
            let fo = FrictionOptions {
                statics: *o,
                ..*options
            };
            solve_frictional(model, actuation, &fo, previous)
        },
        |f| &f.statics,
    )
}

/// Solves the statics of `model` under `actuation` with capstan friction along the tendons
/// (see the module documentation), from the state `previous` (a solution of the same model
/// and options: the history of stick and slip) or from rest (`None`: every element slides
/// toward the base). A `previous` state on another mesh (other RK4 steps) has its history,
/// the tension profile read as the solve reads it, carried onto this one. With the adaptive
/// integrator the friction mesh is chosen by the shape's turning (`friction_mesh` module): it
/// starts from that of `previous` or from [`ADAPTIVE_FRICTION_NODES`] cells per interval.
///
/// # Errors
/// What [`solve_statics_at`] reports; [`Error::InvalidParameter`] naming `previous` if it is
/// not a state of this robot (its nodes not a friction mesh of it, other tendons), or
/// `friction.tolerance` / `friction.max_iterations`;
/// [`Error::NotConverged`] if the fixed point does not converge (`what` says so, `iterations`
/// are the rod solves, `residual` the last relative change of the profile), or if the
/// adaptive friction mesh still has a cell turning by more than
/// [`ADAPTIVE_FRICTION_TURN`](super::friction_mesh::ADAPTIVE_FRICTION_TURN) after
/// [`MAX_FRICTION_MESH_ROUNDS`](super::friction_mesh::MAX_FRICTION_MESH_ROUNDS) refinements
/// (`residual` that turn, rad).
pub fn solve_frictional(
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &FrictionOptions,
    previous: Option<&FrictionalSolution>,
) -> Result<FrictionalSolution> {
    use super::friction_mesh::{
        finer_mesh, history_on, is_friction_mesh, ADAPTIVE_FRICTION_TURN, MAX_FRICTION_MESH_ROUNDS,
    };
    check_inputs(model, actuation, options)?;
    if model.tendons().iter().any(Tendon::is_guided) {
        // Its rod solves (the guide forces point loads, breaks of their own) choose their
        // meshes themselves.
        let mesh = friction_mesh(model, &options.statics.integrator);
        return solve_on(model, actuation, options, previous, &mesh);
    }
    let adaptive = matches!(options.statics.integrator, Integrator::Adaptive(_));
    let frictional = model.tendons().iter().any(|t| t.friction() > 0.0);
    if let Some(p) = previous.filter(|p| !is_friction_mesh(model, &p.statics.s)) {
        let mesh = friction_mesh(model, &options.statics.integrator);
        return Err(wrong_previous(p, mesh.len(), model.tendons().len()));
    }
    let mut mesh = match previous {
        Some(p) if adaptive => p.statics.s.clone(),
        _ => friction_mesh(model, &options.statics.integrator),
    };
    // The mesh is the shape's to choose with the adaptive integrator and a frictional tendon.
    let chooses = adaptive && frictional;
    let (mut largest, mut iterations, mut cell_steps) = (f64::NAN, 0, 0);
    for round in 0..=MAX_FRICTION_MESH_ROUNDS {
        // The history on another mesh than its own (RK4 steps other than the state's, a finer
        // adaptive mesh): its profile read at the nodes of this one.
        let carried = previous.filter(|p| p.statics.s != mesh).map(|p| {
            let mut q = p.clone();
            q.tension = history_on(p, &mesh);
            q
        });
        let history = carried.as_ref().or(previous);
        let mut sol = solve_on(model, actuation, options, history, &mesh)?;
        // (The effort of every round is reported.)
        iterations += sol.iterations;
        cell_steps += sol.cell_steps;
        let (finer, turn) = if chooses {
            finer_mesh(model, &sol.statics, &mesh)
        } else {
            (None, 0.0)
        };
        largest = turn;
        match finer {
            None => {
                (sol.iterations, sol.cell_steps) = (iterations, cell_steps);
                return Ok(sol);
            }
            Some(f) if round < MAX_FRICTION_MESH_ROUNDS => mesh = f,
            Some(_) => {}
        }
    }
    Err(Error::NotConverged {
        what: format!(
            "friction: a cell of the adaptive friction mesh ({} nodes) still turns by \
             {largest:.3} rad > {ADAPTIVE_FRICTION_TURN} after {MAX_FRICTION_MESH_ROUNDS} \
             refinements",
            mesh.len()
        ),
        iterations,
        residual: largest,
        load_factor: 1.0,
    })
}

/// [`solve_frictional`] on the friction mesh `mesh` (m), `previous` (if any) on it.
pub(super) fn solve_on(
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &FrictionOptions,
    previous: Option<&FrictionalSolution>,
    mesh: &[f64],
) -> Result<FrictionalSolution> {
    if actuation.has_held() {
        return super::friction_held::solve_held_frictional(
            model, actuation, options, previous, mesh,
        );
    }
    if model.tendons().iter().any(Tendon::is_guided) {
        return super::guides::solve_guided(model, actuation, options, previous);
    }
    let nt = model.tendons().len();
    let base = actuation.tension_values(nt);
    let prev = previous_profile(previous, mesh, nt)?;
    if options.single_march {
        let setup = Setup {
            model,
            actuation,
            options,
            mesh,
            base: &base,
            prev,
        };
        if let Some(sol) = solve_marched(&setup, previous)? {
            return Ok(sol);
        }
    }
    let scale = base
        .iter()
        .fold(0.0, |a: f64, &b| a.max(b))
        .max(f64::MIN_POSITIVE);
    // The first profile: the rule on the previous shape, or the base tensions.
    let mut tau = match previous {
        // (A history carried onto a finer mesh starts from its own profile there.)
        Some(p) if p.statics.s != mesh => p.tension.clone(),
        Some(p) => {
            let dirs = tangents(model, &p.statics);
            profile_on(model, &p.statics, &dirs, &base, prev).0
        }
        None => base_profile(model, mesh, &base),
    };
    let mut statics_options = options.statics;
    // Without external loads the zero base wrench is exact (docs/statics.md): no warm start.
    let loaded = !model.loads().is_unloaded();
    if let Some(p) = previous.filter(|_| loaded) {
        statics_options.warm_start = Some(p.statics.warm_start());
    }
    let mut iterations = 0;
    let mut anderson = Anderson::new(true);
    loop {
        let mut act = actuation.clone();
        act.profile = Some(Arc::new(to_profile(model, mesh, &tau)));
        let sol = solve_statics_at(model, &act, &statics_options, mesh)?;
        iterations += 1;
        let dirs = tangents(model, &sol);
        let (next, slip) = profile_on(model, &sol, &dirs, &base, prev);
        let delta = change(&next, &tau, scale);
        if !delta.is_finite() {
            return Err(Error::NotConverged {
                what: "friction: the tension profile became non-finite".into(),
                iterations,
                residual: delta,
                load_factor: sol.stats.load_factor,
            });
        }
        if delta <= options.tolerance {
            let forces = friction_forces(&sol.s, &next, &dirs);
            let tangent = tangent_rows(&dirs);
            let path_length = node_path_lengths(model, &act, &statics_options, mesh, &sol)?;
            return Ok(FrictionalSolution {
                guides: vec![Vec::new(); nt],
                path_length,
                statics: sol,
                tension: next,
                slip,
                tangent,
                friction_force: forces,
                iterations,
                change: delta,
                cell_steps: iterations * (mesh.len() - 1),
            });
        }
        if iterations >= options.max_iterations {
            return Err(Error::NotConverged {
                what: format!(
                    "friction: the tension profile did not settle in {iterations} rod solves \
                     (relative change {delta:e} > tolerance {:e})",
                    options.tolerance
                ),
                iterations,
                residual: delta,
                load_factor: sol.stats.load_factor,
            });
        }
        if loaded {
            statics_options.warm_start = Some(sol.warm_start());
        }
        tau = anderson.update(&tau, next);
    }
}

/// The path length of every tendon from the base to every node of `mesh` (m, `[node][tendon]`)
/// in the state `sol` of actuation `act` (with its profile): one march from its base wrench,
/// the tendon-length quadrature read at the nodes.
fn node_path_lengths(
    model: &Arc<RobotModel>,
    act: &Actuation,
    options: &SolveOptions,
    mesh: &[f64],
    sol: &StaticsSolution,
) -> Result<Vec<Vec<f64>>> {
    let nt = model.tendons().len();
    let tensions = act.tension_values(nt);
    let pressures = act.pressure_values(model.chambers().len());
    let eq = Equations {
        model,
        tensions: &tensions,
        pressures: &pressures,
        load_factor: 1.0,
        profile: act.profile.as_deref(),
    };
    let mut ws = Workspace::new(nt);
    ws.set_columns(&[], &[]);
    ws.track_lengths = true;
    let y0: [f64; STATE] = eq.initial(&scaled(model, &sol.base_wrench));
    let breaks = model.breaks();
    let plan = match options.integrator {
        Integrator::Rk4 { steps } => crate::integrate::march::rk4_plan(breaks, steps),
        Integrator::Adaptive(_) => Vec::new(),
    };
    let scheme = match options.integrator {
        Integrator::Rk4 { .. } => Scheme::Rk4(&plan),
        Integrator::Adaptive(o) => Scheme::Adaptive {
            options: o,
            controlled: STATE,
        },
    };
    let mut out = vec![vec![0.0; nt]; mesh.len()];
    let mut ev = Evaluator { eq, ws: &mut ws };
    march(
        &mut ev,
        breaks,
        &interior(mesh, model.length()),
        y0,
        scheme,
        |ev, s, _, _| {
            let j = mesh.partition_point(|&m| m < s);
            if j < mesh.len() && mesh[j] == s {
                out[j].copy_from_slice(&ev.ws.integral[..nt]);
            }
        },
    )?;
    Ok(out)
}

/// Anderson acceleration (type II, depth [`ANDERSON_DEPTH`]) of a fixed point `x = g(x)` (the
/// tension profile, or the guide points of `guides`): the next iterate combines the last images so as to minimise the
/// linearised residual `g(x) - x` (Walker & Ni, SIAM J. Numer. Anal. 49(4), 2011). The rule
/// is applied to the rod's shape at every iterate, so the accepted profile always satisfies
/// the capstan bounds; the acceleration only chooses where the rod is solved next.
pub(super) struct Anderson {
    /// Past residuals `f = g(x) - x` and images `g(x)` (flattened).
    f: Vec<Vec<f64>>,
    g: Vec<Vec<f64>>,
    /// Whether the iterates are tensions (kept >= 0, zero where the image is zero).
    tensions: bool,
    /// Past iterates kept.
    depth: usize,
}

/// Depth of the Anderson acceleration.
const ANDERSON_DEPTH: usize = 3;

impl Anderson {
    /// An empty history; `tensions`: the iterates are tension profiles (kept >= 0, a tendon
    /// absent at a node stays absent).
    pub(super) fn new(tensions: bool) -> Self {
        Self::with_depth(tensions, ANDERSON_DEPTH)
    }

    /// An empty history keeping `depth` past iterates.
    pub(super) fn with_depth(tensions: bool, depth: usize) -> Self {
        Self {
            f: Vec::new(),
            g: Vec::new(),
            tensions,
            depth,
        }
    }

    /// The next iterate from the current `x` and its image `gx`.
    fn update(&mut self, x: &[Vec<f64>], gx: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
        let flat_x: Vec<f64> = x.iter().flatten().copied().collect();
        let flat_g: Vec<f64> = gx.iter().flatten().copied().collect();
        let next = self.update_flat(&flat_x, flat_g);
        let cols = gx.first().map_or(0, Vec::len);
        next.chunks(cols.max(1)).map(<[f64]>::to_vec).collect()
    }

    /// The next iterate from the current `x` and its image `gx` (flattened).
    pub(super) fn update_flat(&mut self, x: &[f64], gx: Vec<f64>) -> Vec<f64> {
        let flat_f: Vec<f64> = gx.iter().zip(x).map(|(g, x)| g - x).collect();
        self.f.push(flat_f);
        self.g.push(gx.clone());
        if self.f.len() > self.depth + 1 {
            self.f.remove(0);
            self.g.remove(0);
        }
        let m = self.f.len() - 1;
        if m == 0 {
            return gx;
        }
        let n = self.f[0].len();
        let last = &self.f[m];
        // Differences of consecutive residuals and images.
        let df = DMatrix::from_fn(n, m, |r, c| self.f[c + 1][r] - self.f[c][r]);
        let dg = DMatrix::from_fn(n, m, |r, c| self.g[c + 1][r] - self.g[c][r]);
        let rhs = DVector::from_column_slice(last);
        let Ok(gamma) = df.svd(true, true).solve(&rhs, 1e-12) else {
            return gx;
        };
        let next = DVector::from_column_slice(&self.g[m]) - dg * gamma;
        if !next.iter().all(|v| v.is_finite()) {
            self.f.clear();
            self.g.clear();
            return gx;
        }
        next.iter()
            .zip(&gx)
            .map(|(&v, &g)| {
                if !self.tensions {
                    v
                } else if g == 0.0 {
                    // A tendon absent at a node stays absent; tensions stay >= 0.
                    0.0
                } else {
                    v.max(0.0)
                }
            })
            .collect()
    }
}

/// `τ_i'(s) t_i` at the nodes (N/m): the slope of `ln τ` over the neighbouring cells longer
/// than the break offset, times `τ`.
pub(super) fn friction_forces(
    s: &[f64],
    tau: &[Vec<f64>],
    dirs: &[Vec<Option<Vector3<f64>>>],
) -> Vec<Vec<[f64; 3]>> {
    let n = s.len();
    let nt = tau.first().map_or(0, Vec::len);
    let tiny = BREAK_OFFSET * 10.0 * s[n - 1];
    let mut out = vec![vec![[0.0; 3]; nt]; n];
    for i in 0..nt {
        for j in 0..n {
            let Some(t) = dirs[j][i] else { continue };
            let (mut sum, mut count) = (0.0, 0.0);
            for (a, b) in [(j.wrapping_sub(1), j), (j, j + 1)] {
                if a >= n || b >= n || s[b] - s[a] <= tiny || dirs[a][i].is_none() {
                    continue;
                }
                if dirs[b][i].is_none() {
                    continue;
                }
                sum += (tau[b][i] - tau[a][i]) / (s[b] - s[a]);
                count += 1.0;
            }
            if count == 0.0 {
                continue;
            }
            let d = sum / count;
            out[j][i] = [d * t.x, d * t.y, d * t.z];
        }
    }
    out
}

/// Solves a quasi-static actuation path with friction: each actuation from the equilibrium of
/// the one before (the first from rest), so that stick and slip follow the history.
///
/// # Errors
/// What [`solve_frictional`] reports, for the first actuation that fails.
pub fn solve_path(
    model: &Arc<RobotModel>,
    actuations: &[Actuation],
    options: &FrictionOptions,
) -> Result<Vec<FrictionalSolution>> {
    let mut out: Vec<FrictionalSolution> = Vec::with_capacity(actuations.len());
    for a in actuations {
        let next = solve_frictional(model, a, options, out.last())?;
        out.push(next);
    }
    Ok(out)
}
