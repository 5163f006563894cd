//! A solved Cosserat rod ([`StaticsSolution`]): the shape and internal wrenches at the
//! nodes of the last pass, the model, actuation and options it was solved with, and its
//! stability margin on first read.

use std::sync::{Arc, OnceLock};

use nalgebra::{Matrix3, Matrix6, Vector3};

use super::equations::{rot, v3, Equations, Evaluator, Workspace};
use super::options::{CoarseDefect, SolveOptions, WarmStart};
use super::shooting::{Node, Shooting};
use super::statics::stability_on;
use crate::math::so3::quaternion_xyzw;
use crate::model::{Actuation, RobotModel};
use crate::solve::SolverStats;

/// A solved rod, sampled at the integration mesh, with the model, actuation and options it
/// was solved with (so that [`crate::compliance::compliance`] and
/// [`crate::compliance::tangent_compliance`] need nothing else).
///
/// Every array has one entry per sample. At an interval break (tendon termination, point
/// load) the sample appears twice with the same `s`: the values just before and just after
/// the jump. Vectors are `[x, y, z]`; rotations are body → world matrices; quaternions are
/// scalar-last `[x, y, z, w]` with `w >= 0`.
#[derive(Debug, Clone)]
pub struct StaticsSolution {
    /// Undeformed arc length (m).
    pub s: Vec<f64>,
    /// Backbone position (m, world), shape (N, 3).
    pub position: Vec<[f64; 3]>,
    /// Rotation body → world, row-major, shape (N, 3, 3).
    pub rotation: Vec<[[f64; 3]; 3]>,
    /// Orientation quaternion `[x, y, z, w]`, shape (N, 4).
    pub quaternion: Vec<[f64; 4]>,
    /// Rod's internal force `n` (N, world), excluding the tendons' tension.
    pub n_world: Vec<[f64; 3]>,
    /// Rod's internal moment `m` (N m, world).
    pub m_world: Vec<[f64; 3]>,
    /// Rod's internal force `n` in body components (N).
    pub n_body: Vec<[f64; 3]>,
    /// Rod's internal moment `m` in body components (N m).
    pub m_body: Vec<[f64; 3]>,
    /// Shear/stretch strain `v` (body, dimensionless; `(0, 0, 1)` undeformed).
    pub v: Vec<[f64; 3]>,
    /// Bending/twist strain `u` (body, 1/m per undeformed length).
    pub u: Vec<[f64; 3]>,
    /// Path length of each tendon from the base to its termination (m), `∫ |p_i'| ds`
    /// (quadrature on the integration stages).
    pub tendon_lengths: Vec<f64>,
    /// Tension carried by each tendon (N): the input of a tension-controlled tendon, the
    /// solved tension of a displacement-controlled one (0 when slack).
    pub tendon_tensions: Vec<f64>,
    /// Total base wrench (rod + tendons), for [`SolveOptions::warm_start`].
    pub base_wrench: [f64; 6],
    /// Solver statistics.
    pub stats: SolverStats,
    /// The model solved.
    pub model: Arc<RobotModel>,
    /// The actuation it was solved for.
    pub actuation: Actuation,
    /// The options it was solved with.
    pub options: SolveOptions,
    /// The (exact or updated) shooting Jacobian at the solution, in scaled unknowns.
    pub jacobian: Option<Matrix6<f64>>,
    /// The coarse mesh's residual at the solution, when it was solved from a coarse mesh
    /// (carried by [`StaticsSolution::warm_start`]).
    pub coarse_defect: Option<CoarseDefect>,
    /// The arc lengths the solution was asked at (m; empty: the integration mesh).
    pub s_out: Vec<f64>,
    /// Whether the equilibrium is stable: its tip tangent stiffness (tendons at fixed
    /// tension, dead loads; for a contact solution with a free tip, its frictionless point
    /// contacts held) is positive definite (see [`StaticsSolution::stability_margin`] and
    /// `docs/stability.md`). Always true without external loads; false for a result that did
    /// not converge.
    pub stable: bool,
    /// The stability margin, once computed.
    pub(crate) margin: OnceLock<f64>,
}

impl StaticsSolution {
    /// Tip position (m, world).
    pub fn tip_position(&self) -> [f64; 3] {
        self.position.last().copied().unwrap_or([f64::NAN; 3])
    }

    /// Warm start for a nearby problem (base wrench and Jacobian).
    pub fn warm_start(&self) -> WarmStart {
        WarmStart {
            base_wrench: self.base_wrench,
            jacobian: self.jacobian,
            coarse_defect: self.coarse_defect,
        }
    }

    /// Tension of every tendon (N), as [`StaticsSolution::tendon_tensions`].
    pub fn tensions(&self) -> Vec<f64> {
        self.tendon_tensions.clone()
    }

    /// Pressure of every chamber (Pa).
    pub fn pressures(&self) -> Vec<f64> {
        self.actuation.pressure_values(self.model.chambers().len())
    }

    /// The equations of this solution's model under its actuation: its tendon tensions (N),
    /// the chamber `pressures` (Pa, those of [`Self::pressures`]) and its tension profile, at
    /// the load factor `load_factor`.
    pub(crate) fn equations<'a>(&'a self, pressures: &'a [f64], load_factor: f64) -> Equations<'a> {
        Equations {
            model: &self.model,
            tensions: &self.tendon_tensions,
            pressures,
            load_factor,
            profile: self.actuation.profile.as_deref(),
        }
    }

    /// The smallest eigenvalue of the symmetric part of the dimensionless tip tangent
    /// stiffness `D K D / (E I(0) / L)`, `K` the inverse of the tip tangent compliance
    /// (tendons at fixed tension, dead loads), `D = diag(L, L, L, 1, 1, 1)`: positive for a
    /// stable equilibrium (see `docs/stability.md`). Computed during a loaded solve when its
    /// sign is in doubt; for an unloaded one (always stable) and a loaded one certified
    /// stable by the exact columns of a nearby Newton iterate, on first call, by one march
    /// with the six base-wrench columns. NaN for a result that did not converge.
    pub fn stability_margin(&self) -> f64 {
        *self.margin.get_or_init(|| {
            if !self.stats.converged {
                return f64::NAN;
            }
            margin_of(self).unwrap_or(f64::NAN)
        })
    }
}

/// The stability margin of a solution, from one march with the base-wrench columns.
fn margin_of(sol: &StaticsSolution) -> Option<f64> {
    stability_on(sol, sol.options.integrator).map(|s| s.margin)
}

/// The base wrench (N, N m) of scaled unknowns.
pub(crate) fn scaled_back(model: &RobotModel, x: &[f64]) -> [f64; 6] {
    let f = model.force_scale();
    let fm = f * model.length();
    [
        x[0] * f,
        x[1] * f,
        x[2] * f,
        x[3] * fm,
        x[4] * fm,
        x[5] * fm,
    ]
}

fn arr(v: &Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}

fn rows(r: &Matrix3<f64>) -> [[f64; 3]; 3] {
    [
        [r[(0, 0)], r[(0, 1)], r[(0, 2)]],
        [r[(1, 0)], r[(1, 1)], r[(1, 2)]],
        [r[(2, 0)], r[(2, 1)], r[(2, 2)]],
    ]
}

/// Derived quantities at the recorded nodes of the last pass (which is at the solution).
pub(crate) fn assemble(
    p: &mut Shooting<'_>,
    shared: &Arc<RobotModel>,
    base_wrench: [f64; 6],
    stats: SolverStats,
    s_out: &[f64],
) -> StaticsSolution {
    let n = p.nodes.len();
    let model = p.eq.model;
    let mut sol = StaticsSolution {
        s: Vec::with_capacity(n),
        position: Vec::with_capacity(n),
        rotation: Vec::with_capacity(n),
        quaternion: Vec::with_capacity(n),
        n_world: Vec::with_capacity(n),
        m_world: Vec::with_capacity(n),
        n_body: Vec::with_capacity(n),
        m_body: Vec::with_capacity(n),
        v: Vec::with_capacity(n),
        u: Vec::with_capacity(n),
        tendon_lengths: if p.lengths.len() == p.eq.model.tendons().len() {
            p.lengths.clone()
        } else {
            vec![f64::NAN; p.eq.model.tendons().len()]
        },
        tendon_tensions: p.tensions.clone(),
        base_wrench,
        stats,
        model: Arc::clone(shared),
        actuation: Actuation::default(),
        options: SolveOptions::default(),
        jacobian: None,
        coarse_defect: None,
        s_out: Vec::new(),
        stable: false,
        margin: OnceLock::new(),
    };
    let mut ws = Workspace::new(model.tendons().len());
    let mut ev = Evaluator {
        eq: p.equations(),
        ws: &mut ws,
    };
    // With `s_out`, only the nodes there (the last copy of a break).
    let keep: Option<Vec<bool>> = (!s_out.is_empty()).then(|| {
        let mut keep = vec![false; n];
        for &s in s_out {
            if let Some(j) = p.nodes.iter().rposition(|node| node.s == s) {
                keep[j] = true;
            }
        }
        keep
    });
    let mut current = usize::MAX;
    let nodes: &[Node] = &p.nodes;
    for (j, node) in nodes.iter().enumerate() {
        if node.interval != current {
            ev.set_interval(node.interval);
            current = node.interval;
        }
        let y = &node.y;
        let r = rot(y);
        let nb_tot = r.tr_mul(&v3(y, 12));
        let mb_tot = r.tr_mul(&v3(y, 15));
        let props = model.rod().section_at(node.s);
        let loc = ev.local(node.s, &props, &nb_tot, &mb_tot, false);
        if keep.as_ref().is_some_and(|k| !k[j]) {
            continue;
        }
        let nb = nb_tot - loc.tendon_force;
        let mb = mb_tot - loc.tendon_moment;
        sol.s.push(node.s);
        sol.position.push(arr(&v3(y, 0)));
        sol.rotation.push(rows(&r));
        sol.quaternion.push(quaternion_xyzw(&r));
        sol.n_world.push(arr(&(r * nb)));
        sol.m_world.push(arr(&(r * mb)));
        sol.n_body.push(arr(&nb));
        sol.m_body.push(arr(&mb));
        sol.v.push(arr(&loc.v));
        sol.u.push(arr(&loc.u));
    }
    if let Some(e) = ws.material_error.take() {
        p.ws.material_error.get_or_insert(e);
    }
    sol
}
