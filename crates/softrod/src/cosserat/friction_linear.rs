//! The actuation Jacobian of a frictional equilibrium: a one-sided (directional) derivative
//! with the tension profile part of the variational state of the frictional march.
//!
//! Continued from the solution (the solution its own previous state), a small change of an
//! input in one direction keeps every tendon element in the state the nonlinear solve gives
//! it. With `τ_k` the tension at node `k`, `Δθ_k` the turning of the path over the cell
//! `[s_k, s_k+1]` and `lo = τ_k e^(−μΔθ)`, `hi = τ_k e^(+μΔθ)` its capstan bounds, the solve
//! with `previous` sets `τ'_k+1 = clamp(τ_k+1, lo', hi')`, so to first order
//!
//! ```text
//! δτ_k+1 = max(0, δlo)   at the lower bound (sliding toward the base),
//! δτ_k+1 = min(0, δhi)   at the upper bound (sliding toward the tip),
//! δτ_k+1 = 0             strictly inside the bounds (sticking),
//! δlo = e^(−μΔθ) (δτ_k − μ τ_k δΔθ_k),   δhi = e^(+μΔθ) (δτ_k + μ τ_k δΔθ_k),
//! ```
//!
//! (both bounds at once, `Δθ = 0`: `clamp(0, δlo, δhi)`), `δΔθ_k` the change of the angle
//! between the path tangents at the two nodes, which depend on the strains there and so on
//! the shape variation and on `δτ` at the node. An element at its bound slides on if the
//! change pushes it further and sticks otherwise. The rule is piecewise linear in the
//! direction of the change: pulling a tendon (`+δτ_0`) and releasing it (`−δτ_0`) give
//! different columns ([`Direction`]).
//!
//! **Variational march.** The columns `(δp, δR, δN, δM)` are integrated with the state over
//! every cell of the friction mesh as in the frictionless linearisation, each with its own
//! `δτ` per tendon: the profile's variation over the cell (the derivative of its geometric
//! interpolation between `δτ_k` and `δτ_k+1`) forces the constitutive split as a change of
//! the tendons' tension does. `δτ_k+1` enters the step it results from: one extra column per
//! frictional tendon (zero at the proximal node, a unit distal tension variation) makes the
//! distal state affine in `δτ_k+1`, and the rule above is then a small piecewise-linear
//! system per cell, solved by choosing every element's branch until the choices agree with
//! the signs of `δlo`, `δhi` they produce.
//!
//! **Loaded rods.** With external loads the base wrench changes too: the six base-wrench
//! columns carry their own `δτ`, on the branches the actuation column chose, and the base
//! wrench change `δx` solves the tip condition. The branches depend on `δx`, so the march is
//! repeated from the new `δx` until the branches of two successive marches agree (then the
//! last solve is exact on them).

use nalgebra::{DMatrix, Matrix3, Matrix6, Vector3, Vector6};

use super::equations::{
    col_rot, mul_hat, project, rot, rotation_variation, v3, Column, Equations, Evaluator, Tangent,
    Workspace, COLUMN, DM, DN, DR, STATE,
};
use super::friction::angle;
use super::statics::{Integrator, StaticsSolution};
use crate::error::{Error, Result};
use crate::integrate::{adaptive, fixed, System, DP5, RK4};
use crate::model::actuation::TensionProfile;
use crate::model::RobotModel;

/// Relative distance of a tension to its capstan bound within which the element is taken
/// at the bound (sliding on if pushed further): the tension profile of a solution is
/// resolved to the friction tolerance (`1e-9` by default), far below this.
pub const BOUND_TOLERANCE: f64 = 1e-7;

/// Cap on the marches of a loaded rod (the branches of the elements chosen again from the
/// last base-wrench change).
pub const MAX_BRANCH_PASSES: usize = 20;

/// The direction of the one-sided derivative of a frictional equilibrium.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Direction {
    /// The derivative for an increasing input (`(f(a + h e) − f(a)) / h`, `h → 0+`).
    #[default]
    Pull,
    /// The derivative for a decreasing input (`(f(a) − f(a − h e)) / h`, `h → 0+`).
    Release,
}

impl Direction {
    /// `+1` (pull) or `−1` (release).
    pub fn sign(self) -> f64 {
        match self {
            Direction::Pull => 1.0,
            Direction::Release => -1.0,
        }
    }
}

/// The branch an element takes under the change.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Branch {
    /// Slides on at the lower bound: `δτ_k+1 = δlo`.
    Lower,
    /// Slides on at the upper bound: `δτ_k+1 = δhi`.
    Upper,
    /// Sticks: `δτ_k+1 = 0`.
    Stick,
}

/// Which bounds an element's tension is at.
#[derive(Debug, Clone, Copy)]
struct Bounds {
    lower: bool,
    upper: bool,
}

impl Bounds {
    /// The branch the values `δlo`, `δhi` give.
    fn branch(self, dlo: f64, dhi: f64) -> Branch {
        if self.lower && dlo > 0.0 {
            Branch::Lower
        } else if self.upper && dhi < 0.0 {
            Branch::Upper
        } else {
            Branch::Stick
        }
    }
}

/// What the actuation column differentiates with respect to.
#[derive(Debug, Clone, Copy)]
enum Input {
    Tendon(usize),
    Pressure(usize),
    /// Component `k` of a dead world-frame wrench added at the tip (force, then moment).
    TipWrench(usize),
}

/// The solution's data the variational march needs.
struct Frozen<'a> {
    model: &'a RobotModel,
    mesh: &'a [f64],
    /// Tension per node and tendon (N; 0 where the tendon is not).
    tau: Vec<Vec<f64>>,
    base: Vec<f64>,
    pressures: Vec<f64>,
    mus: Vec<f64>,
    x: [f64; 6],
    integrator: Integrator,
    /// Base-wrench columns (0 when the base wrench cannot change: no internal force).
    nb: usize,
}

impl<'a> Frozen<'a> {
    /// The frozen state of `solution` (friction coefficients `mus`), with the six
    /// base-wrench columns.
    fn of(solution: &'a StaticsSolution, mus: &[f64]) -> Result<Self> {
        let model = &*solution.model;
        Ok(Self {
            model,
            mesh: &solution.s,
            tau: node_tensions(solution, mus)?,
            base: solution.tendon_tensions.clone(),
            pressures: solution.pressures(),
            mus: mus.to_vec(),
            x: super::sensitivity::scaled_base_wrench(model, &solution.base_wrench),
            integrator: solution.options.integrator,
            nb: 6,
        })
    }

    fn present(&self, i: usize, s: f64) -> bool {
        let (ends, l) = (self.model.tendon_ends(), self.model.length());
        s < ends[i] || (ends[i] == l && s == l)
    }
}

/// One cell step of the state and the columns: the [`Evaluator`] plus, per column, the
/// variation of the tension profile over the cell (and of a pressure).
struct CellSystem<'e, 'w, 'c> {
    ev: Evaluator<'e, 'w>,
    a: f64,
    b: f64,
    /// Per tendon, the tensions at the cell's ends (N) and whether it carries a profile.
    ends: &'c [[f64; 2]],
    profiled: &'c [bool],
    /// Per column and tendon, `(δτ_k, δτ_k+1)`.
    dtau: &'c [Vec<[f64; 2]>],
    /// Per column, a chamber's pressure change (per Pa).
    pressure: &'c [Option<(usize, f64)>],
    dirs: Vec<Option<Vector6<f64>>>,
}

impl CellSystem<'_, '_, '_> {
    /// `δτ_i(s)` of the interpolated profile at the cell fraction `w` (`TensionProfile::at`:
    /// geometric between two positive tensions, linear otherwise).
    fn rate(&self, i: usize, w: f64, [da, db]: [f64; 2]) -> f64 {
        let [ta, tb] = self.ends[i];
        if self.profiled[i] && ta == 0.0 && tb == 0.0 && da != 0.0 && db / da > 0.0 {
            // A slack tendon taken up: the profile `h c_a^(1−w) c_b^w` of a small tension
            // `h` (geometric) per unit `h`.
            return da * (db / da).powf(w);
        }
        if self.profiled[i] && ta > 0.0 && tb > 0.0 {
            let (la, lb) = (ta.ln(), tb.ln());
            let t = (la + (lb - la) * w).exp();
            t * ((1.0 - w) * da / ta + w * db / tb)
        } else {
            (1.0 - w) * da + w * db
        }
    }
}

/// Adds to a column's rates (starting at `b0` of `out`) the effect of the body-wrench
/// forcing `f` (subtracted from the constitutive balance): `δ(v, u) = −T f`.
fn add_forcing(
    out: &mut [f64],
    b0: usize,
    tangent: &Tangent,
    f: &Vector6<f64>,
    r: &Matrix3<f64>,
    nw: &Vector3<f64>,
) {
    let d = tangent.apply(&[f[0], f[1], f[2], f[3], f[4], f[5]]);
    let dv = -Vector3::new(d[0], d[1], d[2]);
    let du = -Vector3::new(d[3], d[4], d[5]);
    let dpd = r * dv;
    let mut h = [0.0; 9];
    mul_hat(r, &du, &mut h);
    let dmd = -dpd.cross(nw);
    for k in 0..3 {
        out[b0 + k] += dpd[k];
        out[b0 + DM + k] += dmd[k];
    }
    for k in 0..9 {
        out[b0 + DR + k] += h[k];
    }
}

impl<const N: usize> System<N> for CellSystem<'_, '_, '_> {
    fn rhs(&mut self, s: f64, y: &[f64; N], out: &mut [f64; N]) {
        let loc = self.ev.rhs_into(s, y, out);
        let ncol = self.dtau.len().min((N - STATE) / COLUMN);
        let model = self.ev.eq.model;
        let props = model.rod().section_at(s);
        let w = ((s - self.a) / (self.b - self.a)).clamp(0.0, 1.0);
        let ends = model.tendon_ends();
        let b_end = model.breaks()[self.ev.ws.interval + 1];
        let (r, nw) = (rot(y), v3(y, 12));
        let tangent = self.ev.ws.tangent;
        self.dirs.iter_mut().for_each(|d| *d = None);
        for c in 0..ncol {
            let mut f = Vector6::zeros();
            let mut any = false;
            for i in 0..ends.len() {
                let d = self.dtau[c][i];
                if (d[0] == 0.0 && d[1] == 0.0) || ends[i] < b_end {
                    continue;
                }
                let dir = match self.dirs[i] {
                    Some(dir) => dir,
                    None => {
                        let dir = self.ev.tendon_direction(i, s, &props, &loc.v, &loc.u);
                        self.dirs[i] = Some(dir);
                        dir
                    }
                };
                f += dir * self.rate(i, w, d);
                any = true;
            }
            if let Some((j, coef)) = self.pressure[c] {
                let (fw, _) = self.ev.forcing(
                    Column::Pressure(j),
                    s,
                    &props,
                    &loc.v,
                    &loc.u,
                    &Vector6::zeros(),
                );
                f += Vector6::from(fw) * coef;
                any = true;
            }
            if any {
                add_forcing(out, STATE + COLUMN * c, &tangent, &f, &r, &nw);
            }
        }
    }

    fn stage_evaluated(&mut self, stage: usize) {
        <Evaluator<'_, '_> as System<N>>::stage_evaluated(&mut self.ev, stage);
    }

    fn step_accepted(&mut self, weights: &[f64], fsal: bool) {
        <Evaluator<'_, '_> as System<N>>::step_accepted(&mut self.ev, weights, fsal);
    }

    fn project(&mut self, y: &mut [f64; N]) {
        project(y);
    }
}

/// The linearisation at a node: strains, the constitutive tangent and, per tendon there,
/// its body direction `(t, r × t)`, the vector `w = v + u × r + r'` and its offset `r`.
struct NodeLin {
    r: Matrix3<f64>,
    nw: Vector3<f64>,
    mw: Vector3<f64>,
    tangent: Tangent,
    dirs: Vec<Option<Vector6<f64>>>,
    w: Vec<Option<(Vector3<f64>, Vector3<f64>)>>,
    /// Per chamber, its fluid wrench per Pa at the node (body).
    fluid: Vec<Vector6<f64>>,
}

impl NodeLin {
    /// At node `s` of state `y` (the evaluator on the node's interval).
    fn at(fr: &Frozen<'_>, ev: &mut Evaluator<'_, '_>, s: f64, y: &[f64]) -> Result<Self> {
        let model = fr.model;
        let props = model.rod().section_at(s);
        let (r, nw, mw) = (rot(y), v3(y, 12), v3(y, 15));
        let loc = ev.local(s, &props, &r.tr_mul(&nw), &r.tr_mul(&mw), true);
        if !(loc.v.iter().chain(loc.u.iter()).all(|c| c.is_finite())) {
            return Err(ev.ws.material_error.take().unwrap_or(Error::NotConverged {
                what: format!(
                    "frictional linearisation: the constitutive solve failed at s = {s} m"
                ),
                iterations: 0,
                residual: f64::INFINITY,
                load_factor: 1.0,
            }));
        }
        let nt = fr.base.len();
        let mut dirs = vec![None; nt];
        let mut w = vec![None; nt];
        for i in 0..nt {
            if fr.present(i, s) {
                dirs[i] = Some(ev.tendon_direction(i, s, &props, &loc.v, &loc.u));
                let (o, op) = model.tendons()[i].routing().offset(s, &props);
                let o = Vector3::new(o[0], o[1], 0.0);
                let wi = loc.v + loc.u.cross(&o) + Vector3::new(op[0], op[1], 0.0);
                w[i] = Some((wi, o));
            }
        }
        let fluid = (0..model.chambers().len())
            .map(|j| {
                let (f, _) = ev.forcing(
                    Column::Pressure(j),
                    s,
                    &props,
                    &loc.v,
                    &loc.u,
                    &Vector6::zeros(),
                );
                Vector6::from(f)
            })
            .collect();
        Ok(Self {
            r,
            nw,
            mw,
            tangent: ev.ws.tangent,
            dirs,
            w,
            fluid,
        })
    }

    /// The unit path tangents (world) per tendon.
    fn tangents(&self) -> Vec<Option<Vector3<f64>>> {
        self.w
            .iter()
            .map(|w| w.map(|(w, _)| (self.r * w).normalize()))
            .collect()
    }

    /// The change of the path tangents (world) of the column at `b0` of `y` with the
    /// tension changes `dtau` at the node (and a pressure change).
    fn variation(
        &self,
        y: &[f64],
        b0: usize,
        dtau: &[f64],
        pressure: Option<(usize, f64)>,
    ) -> Vec<Option<Vector3<f64>>> {
        let dr = col_rot(y, b0);
        let (dn, dm) = (v3(y, b0 + DN), v3(y, b0 + DM));
        let dnb = dr.tr_mul(&self.nw) + self.r.tr_mul(&dn);
        let dmb = dr.tr_mul(&self.mw) + self.r.tr_mul(&dm);
        let mut e = Vector6::new(dnb.x, dnb.y, dnb.z, dmb.x, dmb.y, dmb.z);
        for (i, d) in self.dirs.iter().enumerate() {
            if let Some(d) = d {
                e -= d * dtau[i];
            }
        }
        if let Some((j, coef)) = pressure {
            e -= self.fluid[j] * coef;
        }
        let d = self.tangent.apply(&[e[0], e[1], e[2], e[3], e[4], e[5]]);
        let (dv, du) = (
            Vector3::new(d[0], d[1], d[2]),
            Vector3::new(d[3], d[4], d[5]),
        );
        self.w
            .iter()
            .map(|w| {
                w.map(|(w, o)| {
                    let big = self.r * w;
                    let len = big.norm();
                    let t = big / len;
                    let dbig = dr * w + self.r * (dv + du.cross(&o));
                    (dbig - t * t.dot(&dbig)) / len
                })
            })
            .collect()
    }
}

/// The change of the angle between the unit vectors `a` and `b` for their changes `da`,
/// `db` (0 where they are parallel: the angle is not differentiable there).
fn angle_variation(
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    da: &Vector3<f64>,
    db: &Vector3<f64>,
) -> f64 {
    let c = a.cross(b);
    let (sin, cos) = (c.norm(), a.dot(b));
    if sin < 1e-12 {
        return 0.0;
    }
    let dsin = (c / sin).dot(&(da.cross(b) + a.cross(db)));
    let dcos = da.dot(b) + a.dot(db);
    (cos * dsin - sin * dcos) / (sin * sin + cos * cos)
}

/// The piecewise-linear rule of one cell: per unknown distal tension `p`, the affine
/// `δlo_p = lo[p] + L[p]·z`, `δhi_p = hi[p] + H[p]·z`, and which bounds it is at.
struct CellRule {
    bounds: Vec<Bounds>,
    l: DMatrix<f64>,
    h: DMatrix<f64>,
}

impl CellRule {
    /// The distal tension changes `z` on the branches `branches` for the constant parts
    /// `lo`, `hi`.
    fn solve(&self, branches: &[Branch], lo: &[f64], hi: &[f64]) -> Result<Vec<f64>> {
        let n = branches.len();
        if n == 0 {
            return Ok(Vec::new());
        }
        let mut a = DMatrix::identity(n, n);
        let mut rhs = nalgebra::DVector::zeros(n);
        for (p, br) in branches.iter().enumerate() {
            match br {
                Branch::Lower => {
                    for q in 0..n {
                        a[(p, q)] -= self.l[(p, q)];
                    }
                    rhs[p] = lo[p];
                }
                Branch::Upper => {
                    for q in 0..n {
                        a[(p, q)] -= self.h[(p, q)];
                    }
                    rhs[p] = hi[p];
                }
                Branch::Stick => {}
            }
        }
        a.lu()
            .solve(&rhs)
            .map(|z| z.iter().copied().collect())
            .ok_or_else(|| Error::NotConverged {
                what: "frictional linearisation: singular cell rule".into(),
                iterations: 0,
                residual: f64::INFINITY,
                load_factor: 1.0,
            })
    }

    /// The branches consistent with their own solution, from the bounds' natural branches.
    fn branches(&self, lo: &[f64], hi: &[f64]) -> Result<(Vec<Branch>, Vec<f64>)> {
        let n = lo.len();
        let mut br: Vec<Branch> = self
            .bounds
            .iter()
            .map(|b| match (b.lower, b.upper) {
                (true, _) => Branch::Lower,
                (false, true) => Branch::Upper,
                _ => Branch::Stick,
            })
            .collect();
        for _ in 0..2 * n + 2 {
            let z = self.solve(&br, lo, hi)?;
            let next: Vec<Branch> = (0..n)
                .map(|p| {
                    let dlo = lo[p] + (0..n).map(|q| self.l[(p, q)] * z[q]).sum::<f64>();
                    let dhi = hi[p] + (0..n).map(|q| self.h[(p, q)] * z[q]).sum::<f64>();
                    self.bounds[p].branch(dlo, dhi)
                })
                .collect();
            if next == br {
                return Ok((br, z));
            }
            br = next;
        }
        Err(Error::NotConverged {
            what: "frictional linearisation: the slip branches of a cell do not settle".into(),
            iterations: 2 * n + 2,
            residual: f64::INFINITY,
            load_factor: 1.0,
        })
    }
}

/// One variational march.
struct Pass {
    /// Per node, per main column (the input's, then the base-wrench ones), `(δp, δθ)`.
    poses: Vec<Vec<Vector6<f64>>>,
    /// Per main column, the derivative of the scaled tip residual.
    residual: Vec<Vector6<f64>>,
    /// The branches the input's column took, cell by cell.
    branches: Vec<Branch>,
}

/// Column `c`'s pose change at state `y`.
fn pose_of(y: &[f64], c: usize) -> Vector6<f64> {
    let b0 = STATE + COLUMN * c;
    let (dp, w) = (v3(y, b0), rotation_variation(&rot(y), &col_rot(y, b0)));
    Vector6::new(dp.x, dp.y, dp.z, w.x, w.y, w.z)
}

/// The variational march of the inputs `inputs` in the direction `sigma` (±1), one column
/// each with its own slip branches; with the base-wrench columns if `fr.nb` (then one input,
/// the base wrench changed by `dx` (scaled) at the base, the base-wrench columns on its
/// branches).
#[allow(clippy::too_many_lines)] // one sequential march
fn march<const N: usize>(
    fr: &Frozen<'_>,
    inputs: &[Input],
    sigma: f64,
    dx: &[f64; 6],
) -> Result<Pass> {
    let model = fr.model;
    let nt = fr.base.len();
    let n_in = inputs.len();
    let nm = n_in + fr.nb;
    let breaks = model.breaks();
    let f_ref = model.force_scale();
    let fm = f_ref * model.length();
    let mut cell = TensionProfile::new(
        (0..nt)
            .map(|i| (fr.mus[i] > 0.0).then(|| (vec![0.0, 1.0], vec![fr.base[i]; 2])))
            .collect(),
    );
    let profiled: Vec<bool> = fr.mus.iter().map(|&m| m > 0.0).collect();
    let eq = Equations {
        model,
        tensions: &fr.base,
        pressures: &fr.pressures,
        load_factor: 1.0,
        profile: None,
    };
    let mut ws = Workspace::new(nt);
    let mut y: [f64; N] = eq.initial(&fr.x);
    y[STATE..].fill(0.0);
    for k in 0..3 {
        y[STATE + DN + k] = f_ref * dx[k];
        y[STATE + DM + k] = fm * dx[3 + k];
    }
    for k in 0..fr.nb {
        let b0 = STATE + COLUMN * (n_in + k);
        if k < 3 {
            y[b0 + DN + k] = f_ref;
        } else {
            y[b0 + DM + k - 3] = fm;
        }
    }
    // δτ per main column and tendon at the current node.
    let mut dtau = vec![vec![0.0; nt]; nm];
    let pressure_of = |c: usize| match inputs.get(c) {
        Some(Input::Pressure(j)) => Some((*j, sigma)),
        _ => None,
    };
    for (c, input) in inputs.iter().enumerate() {
        if let Input::Tendon(k) = input {
            dtau[c][*k] = sigma;
        }
    }
    let mut interval = 0;
    let (mut ta, mut dta) = {
        let mut ev = Evaluator {
            eq: Equations {
                profile: Some(&cell),
                ..eq
            },
            ws: &mut ws,
        };
        ev.set_interval(0);
        let node = NodeLin::at(fr, &mut ev, 0.0, &y)?;
        let dta: Vec<_> = (0..nm)
            .map(|c| node.variation(&y, STATE + COLUMN * c, &dtau[c], pressure_of(c)))
            .collect();
        (node.tangents(), dta)
    };
    let n = fr.mesh.len();
    let mut poses = Vec::with_capacity(n);
    poses.push((0..nm).map(|c| pose_of(&y, c)).collect::<Vec<_>>());
    let mut branches = Vec::new();
    let width = (N - STATE) / COLUMN;
    for j in 0..n - 1 {
        let (a, b) = (fr.mesh[j], fr.mesh[j + 1]);
        let crosses = breaks[interval + 1] == b && interval + 2 < breaks.len();
        let mut ends = vec![[0.0; 2]; nt];
        for i in 0..nt {
            let distal = if fr.present(i, b) {
                fr.tau[j + 1][i]
            } else {
                fr.tau[j][i]
            };
            ends[i] = [fr.tau[j][i], distal];
            if fr.mus[i] > 0.0 {
                cell.set_cell(i, [a, b], ends[i]);
            }
        }
        // A slack tendon (zero tension at both nodes) keeps the ratio e^(−μΔθ) of its
        // distal to its proximal tension change (the term in δΔθ vanishes with τ): its Δθ
        // from the state stepped alone; the others' distal changes are unknowns.
        let slack: Vec<usize> = (0..nt)
            .filter(|&i| {
                fr.mus[i] > 0.0
                    && fr.present(i, b)
                    && fr.tau[j][i] == 0.0
                    && fr.tau[j + 1][i] == 0.0
            })
            .collect();
        let ratio = if slack.is_empty() {
            vec![1.0; nt]
        } else {
            slack_ratios(fr, &mut ws, &cell, &y, [a, b], interval, crosses, &ta)?
        };
        let unknown: Vec<usize> = (0..nt)
            .filter(|&i| fr.mus[i] > 0.0 && fr.present(i, b) && !slack.contains(&i))
            .collect();
        let nq = unknown.len();
        let ncols = nm + nq;
        if ncols > width {
            return Err(Error::invalid(
                "tendons",
                format!("{nq} frictional tendons"),
                format!("at most {} frictional tendons", width - nm),
            ));
        }
        let mut coef = vec![vec![[0.0; 2]; nt]; ncols];
        for c in 0..nm {
            for i in 0..nt {
                let d = dtau[c][i];
                coef[c][i] = [
                    d,
                    if unknown.contains(&i) {
                        0.0
                    } else {
                        d * ratio[i]
                    },
                ];
            }
        }
        for (q, &i) in unknown.iter().enumerate() {
            coef[nm + q][i] = [0.0, 1.0];
        }
        let pressure: Vec<_> = (0..ncols).map(pressure_of).collect();
        y[STATE + COLUMN * nm..].fill(0.0);
        ws.set_columns(&vec![Column::Free; ncols], &[]);
        let (y1, node) = {
            let mut sys = CellSystem {
                ev: Evaluator {
                    eq: Equations {
                        profile: Some(&cell),
                        ..eq
                    },
                    ws: &mut ws,
                },
                a,
                b,
                ends: &ends,
                profiled: &profiled,
                dtau: &coef,
                pressure: &pressure,
                dirs: vec![None; nt],
            };
            if sys.ev.ws.interval != interval {
                sys.ev.set_interval(interval);
            }
            let mut y1 = match fr.integrator {
                Integrator::Rk4 { .. } => fixed(&RK4, &mut sys, a, y, b, 1, |_, _, _| {})?,
                Integrator::Adaptive(o) => {
                    adaptive(&DP5, &mut sys, [a, b], y, &o, STATE, |_, _, _| {})?.0
                }
            };
            if crosses {
                sys.ev.eq.jump(b, &mut y1, ncols);
                sys.ev.set_interval(interval + 1);
            }
            let node = NodeLin::at(fr, &mut sys.ev, b, &y1)?;
            (y1, node)
        };
        let tb = node.tangents();
        let at_node = |c: usize| -> Vec<f64> {
            (0..nt)
                .map(|i| {
                    if !fr.present(i, b) {
                        0.0
                    } else if c >= nm {
                        f64::from(u8::from(unknown[c - nm] == i))
                    } else {
                        coef[c][i][1]
                    }
                })
                .collect()
        };
        let mut dtb: Vec<Vec<Option<Vector3<f64>>>> = (0..ncols)
            .map(|c| node.variation(&y1, STATE + COLUMN * c, &at_node(c), pressure_of(c)))
            .collect();
        // The cell rule, affine in the distal changes z.
        let mut rule = CellRule {
            bounds: Vec::with_capacity(nq),
            l: DMatrix::zeros(nq, nq),
            h: DMatrix::zeros(nq, nq),
        };
        let mut lo = vec![vec![0.0; nq]; nm];
        let mut hi = vec![vec![0.0; nq]; nm];
        for (p, &i) in unknown.iter().enumerate() {
            let (Some(a_t), Some(b_t)) = (ta[i], tb[i]) else {
                continue;
            };
            let theta = angle(&a_t, &b_t);
            let mu = fr.mus[i];
            let g = (mu * theta).exp();
            let [t0, t1] = ends[i];
            let tol = BOUND_TOLERANCE * t0.max(t1);
            rule.bounds.push(Bounds {
                lower: (t1 - t0 / g).abs() <= tol,
                upper: (t1 - t0 * g).abs() <= tol,
            });
            let zero = Vector3::zeros();
            for c in 0..nm {
                let da = dta[c][i].unwrap_or(zero);
                let db = dtb[c][i].unwrap_or(zero);
                let dth = angle_variation(&a_t, &b_t, &da, &db);
                lo[c][p] = (dtau[c][i] - mu * t0 * dth) / g;
                hi[c][p] = g * (dtau[c][i] + mu * t0 * dth);
            }
            for q in 0..nq {
                let db = dtb[nm + q][i].unwrap_or(zero);
                let dth = angle_variation(&a_t, &b_t, &zero, &db);
                rule.l[(p, q)] = -mu * t0 * dth / g;
                rule.h[(p, q)] = g * mu * t0 * dth;
            }
        }
        if rule.bounds.len() != nq {
            return Err(Error::NotConverged {
                what: format!(
                    "frictional linearisation: a tendon has no path tangent at s = {b} m"
                ),
                iterations: 0,
                residual: f64::INFINITY,
                load_factor: 1.0,
            });
        }
        // Each input's column on its own branches, the base-wrench ones on the first's.
        let mut zs = Vec::with_capacity(nm);
        let mut first = Vec::new();
        for c in 0..n_in {
            let (br, z) = rule.branches(&lo[c], &hi[c])?;
            if c == 0 {
                first = br;
            }
            zs.push(z);
        }
        for c in n_in..nm {
            zs.push(rule.solve(&first, &lo[c], &hi[c])?);
        }
        branches.extend_from_slice(&first);
        // The main columns with their distal tension changes.
        let mut y_next = y1;
        for (c, z) in zs.iter().enumerate() {
            let b0 = STATE + COLUMN * c;
            for (q, zq) in z.iter().enumerate() {
                let bq = STATE + COLUMN * (nm + q);
                for k in 0..COLUMN {
                    y_next[b0 + k] += zq * y1[bq + k];
                }
                for i in 0..nt {
                    if let (Some(d), Some(dq)) = (dtb[c][i], dtb[nm + q][i]) {
                        dtb[c][i] = Some(d + dq * *zq);
                    }
                }
            }
            for i in 0..nt {
                dtau[c][i] = match unknown.iter().position(|&u| u == i) {
                    Some(p) => z[p],
                    None if fr.present(i, b) => dtau[c][i] * ratio[i],
                    None => 0.0,
                };
            }
        }
        y = y_next;
        poses.push((0..nm).map(|c| pose_of(&y, c)).collect());
        dtb.truncate(nm);
        dta = dtb;
        ta = tb;
        interval += usize::from(crosses);
    }
    let (_, residual) = eq.residual(&y, nm);
    Ok(Pass {
        poses,
        residual,
        branches,
    })
}

/// Per tendon, `e^(−μΔθ)` over the cell `[a, b]` from the state `y` (stepped alone, the
/// path tangents `ta` at `a`); 1 for the tendons without friction.
#[allow(clippy::too_many_arguments)] // the march's state at one cell
fn slack_ratios<const N: usize>(
    fr: &Frozen<'_>,
    ws: &mut Workspace,
    cell: &TensionProfile,
    y: &[f64; N],
    [a, b]: [f64; 2],
    interval: usize,
    crosses: bool,
    ta: &[Option<Vector3<f64>>],
) -> Result<Vec<f64>> {
    let eq = Equations {
        model: fr.model,
        tensions: &fr.base,
        pressures: &fr.pressures,
        load_factor: 1.0,
        profile: Some(cell),
    };
    ws.set_columns(&[], &[]);
    let mut ev = Evaluator { eq, ws };
    if ev.ws.interval != interval {
        ev.set_interval(interval);
    }
    let mut ys = [0.0; STATE];
    ys.copy_from_slice(&y[..STATE]);
    let mut y1 = match fr.integrator {
        Integrator::Rk4 { .. } => fixed(&RK4, &mut ev, a, ys, b, 1, |_, _, _| {})?,
        Integrator::Adaptive(o) => adaptive(&DP5, &mut ev, [a, b], ys, &o, STATE, |_, _, _| {})?.0,
    };
    if crosses {
        ev.eq.jump(b, &mut y1, 0);
        ev.set_interval(interval + 1);
    }
    let tb = NodeLin::at(fr, &mut ev, b, &y1)?.tangents();
    Ok((0..fr.base.len())
        .map(|i| match (ta[i], tb[i]) {
            (Some(x), Some(z)) if fr.mus[i] > 0.0 => (-fr.mus[i] * angle(&x, &z)).exp(),
            _ => 1.0,
        })
        .collect())
}

/// The one-sided derivative of the poses at every node along `input` in `direction`
/// (per unit input, sign included: the release column is `(f(a) − f(a − h e)) / h`).
fn directional<const N: usize>(
    fr: &Frozen<'_>,
    input: Input,
    direction: Direction,
) -> Result<Vec<Vector6<f64>>> {
    let sigma = direction.sign();
    let mut dx = [0.0; 6];
    let mut last: Option<Vec<Branch>> = None;
    for pass in 0..MAX_BRANCH_PASSES {
        let p = march::<N>(fr, &[input], sigma, &dx)?;
        if fr.nb == 0 {
            return Ok(p.poses.iter().map(|c| c[0] * sigma).collect());
        }
        let d = Matrix6::from_columns(&p.residual[1..7]);
        let mut r0 = p.residual[0];
        if let Input::TipWrench(k) = input {
            // The scaled tip residual `(N(L) − F) / f_ref`, `(M(L) − M) / (f_ref L)`.
            let f_ref = fr.model.force_scale();
            r0[k] -= sigma
                / if k < 3 {
                    f_ref
                } else {
                    f_ref * fr.model.length()
                };
        }
        let step = d.lu().solve(&(-r0)).ok_or_else(|| Error::NotConverged {
            what: "frictional linearisation: singular shooting Jacobian".into(),
            iterations: pass + 1,
            residual: f64::INFINITY,
            load_factor: 1.0,
        })?;
        if last.as_ref() == Some(&p.branches) {
            return Ok(p
                .poses
                .iter()
                .map(|c| {
                    let mut t = c[0];
                    for k in 0..6 {
                        t += c[1 + k] * step[k];
                    }
                    t * sigma
                })
                .collect());
        }
        last = Some(p.branches);
        for k in 0..6 {
            dx[k] += step[k];
        }
    }
    Err(Error::NotConverged {
        what: format!(
            "frictional linearisation: the slip branches did not settle in \
             {MAX_BRANCH_PASSES} marches"
        ),
        iterations: MAX_BRANCH_PASSES,
        residual: f64::INFINITY,
        load_factor: 1.0,
    })
}

/// The tension per node and tendon of a frictional solution (its profile at its mesh).
fn node_tensions(solution: &StaticsSolution, mus: &[f64]) -> Result<Vec<Vec<f64>>> {
    let model = &*solution.model;
    let (ends, l) = (model.tendon_ends(), model.length());
    let nt = mus.len();
    let mesh = &solution.s;
    let profile = solution.actuation.profile.as_deref();
    let mut tau = vec![vec![0.0; nt]; mesh.len()];
    for i in 0..nt {
        let track = profile.and_then(|p| p.tendon(i)).filter(|_| mus[i] > 0.0);
        for (j, &s) in mesh.iter().enumerate() {
            if !(s < ends[i] || (ends[i] == l && s == l)) {
                continue;
            }
            tau[j][i] = match track {
                Some((nodes, vals)) if nodes.get(j) == Some(&s) => vals[j],
                Some(_) => {
                    return Err(Error::invalid(
                        "solution",
                        "a tension profile off its mesh",
                        "a frictional solution at its friction mesh",
                    ))
                }
                None => solution.tendon_tensions[i],
            };
        }
    }
    Ok(tau)
}

/// Width of a state with `c` columns.
const fn width(c: usize) -> usize {
    STATE + COLUMN * c
}

/// The one-sided actuation Jacobians of a frictional equilibrium `solution` (a
/// [`crate::FrictionalSolution`]'s `statics`) at the nodes `nodes` (increasing, distinct),
/// in `direction`: per node, `d[δp; δθ]` (world; m, rad) per N of each tendon's base tension,
/// then per Pa of each chamber's pressure; 6 × (n_tendons + n_chambers). The release column
/// of a slack tendon (zero tension) is zero: it cannot be released.
///
/// # Errors
/// [`Error::NotConverged`] if a constitutive solve fails, or the slip branches do not settle.
pub(crate) fn frictional_actuation_jacobians(
    solution: &StaticsSolution,
    nodes: &[usize],
    direction: Direction,
) -> Result<Vec<DMatrix<f64>>> {
    let model = &*solution.model;
    let nt = model.tendons().len();
    let nc = model.chambers().len();
    let mus: Vec<f64> = model.tendons().iter().map(|t| t.friction()).collect();
    let mut fr = Frozen::of(solution, &mus)?;
    if fr.x[..3].iter().all(|v| *v == 0.0) && model.force_free() {
        fr.nb = 0;
    }
    let nb = fr.nb;
    let frictional = mus.iter().filter(|&&m| m > 0.0).count();
    let need = 1 + nb + frictional;
    let mut out = vec![DMatrix::zeros(6, nt + nc); nodes.len()];
    let inputs: Vec<(usize, Input)> = (0..nt)
        .map(Input::Tendon)
        .chain((0..nc).map(Input::Pressure))
        .enumerate()
        .filter(|(_, input)| match (input, direction) {
            (Input::Tendon(k), Direction::Release) => fr.base[*k] != 0.0,
            _ => true,
        })
        .collect();
    if nb == 0 {
        // No base-wrench change: every input's column in one march (as many as fit).
        let per = (width(24) - STATE) / COLUMN - frictional;
        for chunk in inputs.chunks(per.max(1)) {
            let ins: Vec<Input> = chunk.iter().map(|(_, i)| *i).collect();
            let sigma = direction.sign();
            let p = match chunk.len() + frictional {
                0..=6 => march::<{ width(6) }>(&fr, &ins, sigma, &[0.0; 6])?,
                7..=12 => march::<{ width(12) }>(&fr, &ins, sigma, &[0.0; 6])?,
                13..=18 => march::<{ width(18) }>(&fr, &ins, sigma, &[0.0; 6])?,
                _ => march::<{ width(24) }>(&fr, &ins, sigma, &[0.0; 6])?,
            };
            for (c, (col, _)) in chunk.iter().enumerate() {
                for (m, &node) in out.iter_mut().zip(nodes) {
                    m.set_column(*col, &(p.poses[node][c] * sigma));
                }
            }
        }
        return Ok(out);
    }
    for (col, input) in inputs {
        let poses = match need {
            0..=6 => directional::<{ width(6) }>(&fr, input, direction)?,
            7..=12 => directional::<{ width(12) }>(&fr, input, direction)?,
            13..=18 => directional::<{ width(18) }>(&fr, input, direction)?,
            _ => directional::<{ width(24) }>(&fr, input, direction)?,
        };
        for (m, &node) in out.iter_mut().zip(nodes) {
            m.set_column(col, &poses[node]);
        }
    }
    Ok(out)
}

/// The one-sided tangent compliance of a frictional equilibrium `solution` at its tip: per
/// column `k`, the derivative of the tip twist `[δp; δθ]` (world; m, rad) for a dead
/// world-frame tip wrench `[f; m]` (N, N m) growing along `+e_k` ([`Direction::Pull`]) or
/// along `−e_k` ([`Direction::Release`]; the column is then `(f(0) − f(−h e_k)) / h`), the
/// tension profile following the same stick/slip rule as the actuation Jacobian (tendons at
/// fixed base tension). The columns need not form a symmetric matrix: each is the derivative
/// along its own direction.
///
/// # Errors
/// [`Error::NotConverged`] if a constitutive solve fails or the slip branches do not settle.
pub fn frictional_tip_compliance(
    solution: &StaticsSolution,
    direction: Direction,
) -> Result<Matrix6<f64>> {
    let model = &*solution.model;
    let mus: Vec<f64> = model.tendons().iter().map(|t| t.friction()).collect();
    let fr = Frozen::of(solution, &mus)?;
    let need = 7 + mus.iter().filter(|&&m| m > 0.0).count();
    let mut out = Matrix6::zeros();
    for k in 0..6 {
        let input = Input::TipWrench(k);
        let poses = match need {
            0..=12 => directional::<{ width(12) }>(&fr, input, direction)?,
            13..=18 => directional::<{ width(18) }>(&fr, input, direction)?,
            _ => directional::<{ width(24) }>(&fr, input, direction)?,
        };
        out.set_column(k, &poses[poses.len() - 1]);
    }
    Ok(out)
}
