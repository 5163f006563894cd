//! The exact Jacobian of the guide forces (Newton on the guide forces, [`super`]) from the
//! linearised rod.
//!
//! An unknown of the guide forces is a follower point load at an anchor `s_g`: the body-frame
//! force `f` applied at the tendon's offset `o`, so that the internal force and moment jump
//! by `−R f` and `−R (o × f)` there. Its derivative of the rod's state is the variation
//! started at `s_g⁺` from the jump `δN = −R e_q`, `δM = −R (o × e_q)` per newton, carried to
//! the tip by the linearised rod and corrected by the base wrench that restores the tip
//! balance. One march of the state with twelve variational columns (the scaled base wrench,
//! the base translation and rotation: the transition matrix `Φ(s)` of the 12-dimensional
//! linearised state `(δp, δθ, δN, δM)`, identity at the base in the rod's scales) gives
//! every response: a variation `e` started at `s_g⁺` is `Φ(s) Φ(s_g⁺)⁻¹ e` beyond `s_g`,
//! with the jumps of the other point loads (their `δR f` terms) included in `Φ`. The
//! columns are the exact derivative of the discrete march (see [`crate::cosserat::equations`]),
//! so the Jacobian is that of the solve's own discretisation. A load at the tip changes the
//! tip balance only.
//!
//! The capstan forces `z'` are algebraic in the poses of the anchors (their points and
//! frames), so their derivative along each unknown's pose variation is a central difference
//! of that algebraic map (no rod solve). The rod solve of one evaluation is linearised at
//! fixed tensions of the other tendons: the exact Jacobian serves robots whose other tendons
//! are frictionless and tension-controlled; otherwise the forward differences remain.

use nalgebra::{DMatrix, Matrix3, Rotation3, SMatrix, Vector3, Vector6};

use super::{anchors, node_at, states, Counters, Evaluation, Guided};
use crate::cosserat::columns::scheme_of;
use crate::cosserat::equations::{
    col_rot, rot, rotation_variation, Column, Evaluator, Workspace, COLUMN, DM, DN, DR, STATE,
};
use crate::cosserat::friction::Slip;
use crate::cosserat::statics::interior;
use crate::cosserat::StaticsSolution;
use crate::error::{Error, Result};
use crate::integrate::march::march;
use crate::math::so3::hat;
use crate::model::actuation::TendonInput;

/// Columns of the transition march: the scaled base wrench (6), the base translation (3)
/// and rotation (3).
const NCOL: usize = 12;

/// State length of the transition march.
const WIDTH: usize = STATE + COLUMN * NCOL;

/// Step of the central differences of the capstan forces in an anchor's twist: of its
/// position over the rod's length, of its frame in rad. Small: at a guide of small wrap angle
/// `θ` with friction the forces have a curvature of order `1/θ` (`θ` is not smooth at 0), and
/// the truncation error falls with the square of the step (1.4e-6 relative at 1e-6 on the
/// NiTi robot at 4 N, 1.4e-8 at 1e-7), while the rounding error stays below 1e-10.
const POSE_STEP: f64 = 1e-7;

/// The linearised rod at the anchors: per anchor arc length (increasing), the transition
/// matrix after the anchor's jump, in the scaled coordinates `(δp/L, δθ, δN/f, δM/(f L))`,
/// and the rotation there; the scaled tip residual's derivative along the columns.
struct Transition {
    at: Vec<f64>,
    phi: Vec<SMatrix<f64, NCOL, NCOL>>,
    rotation: Vec<Matrix3<f64>>,
    tip: SMatrix<f64, 6, NCOL>,
    length: f64,
    force: f64,
}

/// Column `c` of the state `y` in the scaled coordinates.
fn scaled_column(y: &[f64], c: usize, l: f64, fs: f64) -> [f64; NCOL] {
    let b = STATE + COLUMN * c;
    let w = rotation_variation(&rot(y), &col_rot(y, b));
    let mut out = [0.0; NCOL];
    for k in 0..3 {
        out[k] = y[b + k] / l;
        out[3 + k] = w[k];
        out[6 + k] = y[b + DN + k] / fs;
        out[9 + k] = y[b + DM + k] / (fs * l);
    }
    out
}

/// One march of the state of `sol` with the transition columns, recording them after the
/// jump at each arc length of `at` (increasing; each a break of the model, or its length).
fn transition(sol: &StaticsSolution, at: &[f64]) -> Result<Transition> {
    let model = &*sol.model;
    let (l, fs) = (model.length(), model.force_scale());
    let x = crate::cosserat::statics::scaled(model, &sol.base_wrench);
    let pressures = sol.pressures();
    let eq = sol.equations(&pressures, sol.stats.load_factor);
    let mut plan = Vec::new();
    let stops = interior(&sol.s_out, l);
    let scheme = scheme_of(&sol.options.integrator, model, &mut plan);
    let mut ws = Workspace::new(model.tendons().len());
    ws.set_columns(&[Column::Free; NCOL], &[]);
    // The base-wrench columns are seeded by `initial`; then the base translation (per rod
    // length) and rotation: `Φ(0) = I` in the scaled coordinates.
    let mut y0: [f64; WIDTH] = eq.initial(&x);
    let r0 = model.rod().base_pose().rotation();
    for k in 0..3 {
        let b = STATE + COLUMN * (6 + k);
        y0[b + k] = l;
        let b = STATE + COLUMN * (9 + k);
        let dr = hat(&Vector3::ith(k, 1.0)) * r0;
        y0[b + DR..b + DR + 9].copy_from_slice(dr.as_slice());
    }
    let mut phi = vec![SMatrix::<f64, NCOL, NCOL>::zeros(); at.len()];
    let mut rotation = vec![Matrix3::identity(); at.len()];
    let mut seen = vec![false; at.len()];
    let mut ev = Evaluator { eq, ws: &mut ws };
    let y = march(&mut ev, model.breaks(), &stops, y0, scheme, |_, s, _, y| {
        // At a break the node comes before and after the jump: the last copy is kept.
        if let Ok(a) = at.binary_search_by(|p| p.total_cmp(&s)) {
            for c in 0..NCOL {
                let col = scaled_column(y, c, l, fs);
                for (r, v) in col.iter().enumerate() {
                    phi[a][(r, c)] = *v;
                }
            }
            rotation[a] = rot(y);
            seen[a] = true;
        }
    })?;
    if !y.iter().all(|v| v.is_finite()) || seen.iter().any(|s| !s) {
        return Err(Error::NotConverged {
            what: "guides: the linearised rod at the guides is not finite".into(),
            iterations: 0,
            residual: f64::INFINITY,
            load_factor: 1.0,
        });
    }
    let (_, d) = eq.residual(&y, NCOL);
    let tip = SMatrix::<f64, 6, NCOL>::from_fn(|r, c| d[c][r]);
    Ok(Transition {
        at: at.to_vec(),
        phi,
        rotation,
        tip,
        length: l,
        force: fs,
    })
}

/// A point-load unknown: its anchor's arc length (m) and the tendon's offset there (m, body).
struct Load {
    s: f64,
    offset: Vector3<f64>,
}

impl Transition {
    fn index(&self, s: f64) -> usize {
        self.at.partition_point(|&a| a < s)
    }

    /// Per unknown (three per load: the body-frame force components, per N), the pose
    /// variation `(δp, δθ)` (m, rad; world) at every arc length of `at`.
    fn responses(&self, loads: &[Load]) -> Result<Vec<Vec<Vector6<f64>>>> {
        let (l, fs) = (self.length, self.force);
        let singular = || Error::NotConverged {
            what: "guides: the linearised rod's transition or tip balance is singular".into(),
            iterations: 0,
            residual: f64::INFINITY,
            load_factor: 1.0,
        };
        let base = self.tip.fixed_columns::<6>(0).into_owned().lu();
        let lus: Vec<_> = self.phi.iter().map(|p| p.lu()).collect();
        let mut out = Vec::with_capacity(3 * loads.len());
        for load in loads {
            let a = self.index(load.s);
            let r = self.rotation[a];
            let at_tip = load.s >= l;
            for q in 0..3 {
                let e = Vector3::ith(q, 1.0);
                let (f, m) = (-(r * e) / fs, -(r * load.offset.cross(&e)) / (fs * l));
                let jump = SMatrix::<f64, NCOL, 1>::from_fn(|i, _| match i {
                    6..=8 => f[i - 6],
                    9..=11 => m[i - 9],
                    _ => 0.0,
                });
                // The variation started after the jump, and what it leaves at the tip.
                let (c, residual) = if at_tip {
                    let d = Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z);
                    (SMatrix::<f64, NCOL, 1>::zeros(), d)
                } else {
                    let c = lus[a].solve(&jump).ok_or_else(singular)?;
                    (c, self.tip * c)
                };
                let dx = base.solve(&(-residual)).ok_or_else(singular)?;
                let pose = self
                    .at
                    .iter()
                    .zip(&self.phi)
                    .map(|(&s, phi)| {
                        // The load's own variation acts beyond its anchor only.
                        let mut total = if s > load.s { c } else { SMatrix::zeros() };
                        for k in 0..6 {
                            total[k] += dx[k];
                        }
                        let v = phi.fixed_rows::<6>(0) * total;
                        Vector6::new(v[0] * l, v[1] * l, v[2] * l, v[3], v[4], v[5])
                    })
                    .collect();
                out.push(pose);
            }
        }
        Ok(out)
    }
}

impl Guided<'_> {
    /// Whether the exact Jacobian applies: the rod solve of an evaluation has no friction
    /// and no held tendon of its own.
    pub(super) fn exact_jacobian_applies(&self) -> bool {
        let model = self.model;
        (0..model.tendons().len())
            .all(|i| model.tendons()[i].is_guided() || model.tendons()[i].friction() == 0.0)
            && self
                .act
                .tendons
                .iter()
                .all(|t| matches!(t, TendonInput::Tension(_)))
    }

    /// The capstan forces (N, body; its anchors after the base hole) of guided tendon `k`
    /// (model tendon `i`) at the anchor poses `pose` (position (m) and rotation per anchor)
    /// and base tension `base`, each guide on the branch `branch` of the stick/slip rule if
    /// given (see [`states`]), and the slip states.
    fn tendon_forces(
        &self,
        k: usize,
        i: usize,
        pose: &[(Vector3<f64>, Matrix3<f64>)],
        base: f64,
        branch: Option<&[Slip]>,
    ) -> (Vec<f64>, Vec<Slip>) {
        let model = self.model;
        let s = anchors(model, i);
        let mut x = Vec::with_capacity(3 * s.len());
        for (&sg, (p, r)) in s.iter().zip(pose) {
            let props = model.rod().section_at(sg);
            let (o, _) = model.tendons()[i].routing().offset(sg, &props);
            x.extend_from_slice((p + r * Vector3::new(o[0], o[1], 0.0)).as_slice());
        }
        let st = states(model, i, &x, base, self.prev_states(k), branch);
        let mut z = Vec::with_capacity(3 * (s.len() - 1));
        for (a, (_, r)) in st.iter().zip(pose).skip(1) {
            z.extend_from_slice((r.transpose() * Vector3::from(a.force)).as_slice());
        }
        (z, st.iter().map(|a| a.slip).collect())
    }

    /// The derivative (3 per anchor after the base hole, by 6 per anchor after it) of the
    /// capstan forces of guided tendon `k` (model tendon `i`) with respect to the twists
    /// `(δp, δθ)` (m, rad; world) of its anchors at the poses `pose`: central differences,
    /// every guide held on the branch of the stick/slip rule it takes at `pose` (a sticking
    /// guide keeps its previous tension, whose derivative is zero; a sliding one the bound
    /// of its interval). The rule has a kink where a guide's previous tension sits at a
    /// bound, as every sticking guide beyond the slip front of an unloading step does (the
    /// rod beyond it carries the same loads, so it is the previous shape moved rigidly, its
    /// wraps unchanged); differences across the kink would mix the branches.
    fn tendon_force_derivative(
        &self,
        k: usize,
        i: usize,
        pose: &[(Vector3<f64>, Matrix3<f64>)],
        base: f64,
    ) -> DMatrix<f64> {
        let na = pose.len();
        let l = self.model.length();
        let mut d = DMatrix::zeros(3 * (na - 1), 6 * (na - 1));
        let fixed = self.frozen.as_ref().map(|f| f[k].clone());
        let branch = fixed.unwrap_or_else(|| self.tendon_forces(k, i, pose, base, None).1);
        let mut moved = pose.to_vec();
        for g in 1..na {
            for q in 0..6 {
                let h = if q < 3 { POSE_STEP * l } else { POSE_STEP };
                let mut at = |eps: f64| {
                    let (p, r) = pose[g];
                    moved[g] = if q < 3 {
                        (p + Vector3::ith(q, eps), r)
                    } else {
                        (p, Rotation3::new(Vector3::ith(q - 3, eps)).matrix() * r)
                    };
                    let (z, _) = self.tendon_forces(k, i, &moved, base, Some(&branch));
                    moved[g] = pose[g];
                    z
                };
                let (plus, minus) = (at(h), at(-h));
                for r in 0..plus.len() {
                    d[(r, 6 * (g - 1) + q)] = (plus[r] - minus[r]) / (2.0 * h);
                }
            }
        }
        d
    }

    /// The exact Jacobian of the residual `z' − z` at the evaluation `cur` (see the module
    /// documentation).
    pub(super) fn exact_jacobian(
        &self,
        cur: &Evaluation,
        base: &[f64],
        active: &[bool],
        c: &mut Counters,
    ) -> Result<DMatrix<f64>> {
        let model = self.model;
        let st = &cur.sol.statics;
        // The anchors of the active tendons, and the unknowns' loads.
        let mut at: Vec<f64> = Vec::new();
        let mut loads = Vec::new();
        let mut index: Vec<Vec<usize>> = Vec::new();
        for (k, &i) in self.guided.iter().enumerate() {
            let s = anchors(model, i);
            if active[k] {
                for &sg in &s[1..] {
                    let props = model.rod().section_at(sg);
                    let (o, _) = model.tendons()[i].routing().offset(sg, &props);
                    loads.push(Load {
                        s: sg,
                        offset: Vector3::new(o[0], o[1], 0.0),
                    });
                }
            }
            at.extend_from_slice(&s);
            index.push(Vec::new());
        }
        at.sort_by(f64::total_cmp);
        at.dedup();
        for (k, &i) in self.guided.iter().enumerate() {
            index[k] = anchors(model, i)
                .iter()
                .map(|&s| at.partition_point(|&a| a < s))
                .collect();
        }
        let lin = transition(st, &at)?;
        c.iterations += 1;
        let response = lin.responses(&loads)?;
        // The anchors' poses on the current shape (as the evaluation reads them).
        let poses: Vec<(Vector3<f64>, Matrix3<f64>)> = at
            .iter()
            .map(|&s| {
                let j = node_at(&st.s, s);
                (
                    Vector3::from(st.position[j]),
                    Matrix3::from_fn(|a, b| st.rotation[j][a][b]),
                )
            })
            .collect();
        // Per active tendon, its capstan forces' derivative with respect to its anchors'
        // twists, chained with the twists per unknown.
        let n = response.len();
        let mut jac = DMatrix::zeros(n, n);
        let mut row = 0;
        for (k, &i) in self.guided.iter().enumerate() {
            if !active[k] {
                continue;
            }
            let pose: Vec<_> = index[k].iter().map(|&a| poses[a]).collect();
            let d = self.tendon_force_derivative(k, i, &pose, base[i]);
            let na = pose.len();
            let mut twists = DMatrix::zeros(6 * (na - 1), n);
            for (u, resp) in response.iter().enumerate() {
                for g in 1..na {
                    for q in 0..6 {
                        twists[(6 * (g - 1) + q, u)] = resp[index[k][g]][q];
                    }
                }
            }
            jac.rows_mut(row, d.nrows()).copy_from(&(d * twists));
            row += 3 * (na - 1);
        }
        for u in 0..n {
            jac[(u, u)] -= 1.0;
        }
        Ok(jac)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use std::sync::Arc;

    use super::super::{points_on, Counters, Guided};
    use crate::cosserat::friction::{solve_frictional, FrictionOptions, Slip};
    use crate::{Actuation, LinearElastic, Loads, RobotModel, Rod, Section, Tendon};

    /// The two-segment NiTi robot (0.4 m, radius 0.7 mm, E = 54 GPa; tendons at 10 mm, three
    /// ending at 0.2 m) with its tendons through `per` equally spaced disks per 0.2 m.
    fn guided_niti(mu: f64, per: usize) -> Arc<RobotModel> {
        let rod = Rod::new(
            0.4,
            Section::circular(0.7e-3).unwrap(),
            LinearElastic::new(54e9, 0.3).unwrap(),
        )
        .unwrap();
        let tendons = (0..6)
            .map(|i| {
                let ang = [90.0f64, -30.0, 210.0][i % 3].to_radians();
                let end = if i < 3 { 0.2 } else { 0.4 };
                let n = (per as f64 * end / 0.2).round() as usize;
                let guides = (1..n).map(|g| end * g as f64 / n as f64).collect();
                Tendon::constant([0.01 * ang.cos(), 0.01 * ang.sin()], Some(end))
                    .unwrap()
                    .with_guides(guides, &[mu])
                    .unwrap()
            })
            .collect();
        RobotModel::new(rod, tendons, Vec::new(), Loads::default()).unwrap()
    }

    /// The exact Jacobian of the guide-force residual against central differences of the
    /// residual (two rod solves per unknown, step 1e-6 of the tension), at the first Newton
    /// iterate from rest and at the solution of an unloading step. There every guide beyond
    /// the slip front sticks exactly at the lower bound of its capstan interval (the rod
    /// beyond the front carries the loads of the previous step: its wraps are unchanged), a
    /// kink of the stick/slip rule: the exact Jacobian is that of the branch each guide is on
    /// (sticking: the previous tension, derivative zero), and the differences are taken of
    /// the residual with those branches held (plain differences straddle the kink and mix
    /// the branches: 0.12 relative off in the worst entry).
    #[test]
    fn exact_jacobian_matches_central_differences() {
        let mut opts = FrictionOptions::default();
        opts.statics.newton.tolerance = 1e-14;
        let act = |tau: f64| Actuation::tensions(&[tau, 0.0, 0.3 * tau, 0.0, 0.5 * tau, 0.1 * tau]);
        for (mu, tau, from) in [(0.0, 1.0, None), (0.2, 4.0, None), (0.2, 3.6, Some(4.0))] {
            let model = guided_niti(mu, 8);
            let previous = from.map(|t| solve_frictional(&model, &act(t), &opts, None).unwrap());
            let a = act(tau);
            let mut problem = Guided::new(&model, &a, &opts, previous.as_ref()).unwrap();
            assert!(problem.exact_jacobian_applies());
            let mut c = Counters::default();
            let base = a.tension_values(6);
            let active = problem.active(&base, &base);
            // From rest: the first iterate, the capstan forces of the channel shape. On the
            // unloading step its solution.
            let (z, warm) = if previous.is_none() {
                let start = problem.start(&mut c).unwrap();
                let x = points_on(&model, &problem.guided, &start);
                let st = problem.states_at(&x, &base);
                (problem.body_forces(&st, &start, &active), start)
            } else {
                let sol = solve_frictional(&model, &a, &opts, previous.as_ref()).unwrap();
                let st: Vec<_> = problem
                    .guided
                    .iter()
                    .map(|&i| sol.guides[i].clone())
                    .collect();
                (problem.body_forces(&st, &sol, &active), sol)
            };
            let cur = problem.evaluate(&z, &base, &active, &warm, &mut c).unwrap();
            let exact = problem
                .exact_jacobian(&cur, &base, &active, &mut c)
                .unwrap();
            // The guides sticking at a bound of their interval (within rounding), and the
            // branches held in the differences.
            let mut kinks = 0;
            for st in &cur.states {
                for g in st
                    .iter()
                    .filter(|g| g.slip == Slip::Stick && g.tension_out > 0.0)
                {
                    let lo = g.tension_in * (-g.friction * g.wrap).exp();
                    if (g.tension_out - lo).abs() <= 1e-12 * g.tension_out {
                        kinks += 1;
                    }
                }
            }
            if previous.is_some() {
                assert!(kinks > 0, "the unloading step sticks at a bound");
                problem.frozen = Some(
                    cur.states
                        .iter()
                        .map(|st| st.iter().map(|g| g.slip).collect())
                        .collect(),
                );
            }
            let h = 1e-6 * tau;
            let n = z.len();
            let mut worst: f64 = 0.0;
            let mut size: f64 = 0.0;
            let mut zk = z.clone();
            for k in 0..n {
                zk[k] = z[k] + h;
                let plus = problem
                    .evaluate(&zk, &base, &active, &cur.sol, &mut c)
                    .unwrap();
                zk[k] = z[k] - h;
                let minus = problem
                    .evaluate(&zk, &base, &active, &cur.sol, &mut c)
                    .unwrap();
                zk[k] = z[k];
                for r in 0..n {
                    let fd = (plus.residual[r] - minus.residual[r]) / (2.0 * h);
                    worst = worst.max((fd - exact[(r, k)]).abs());
                    size = size.max(fd.abs());
                }
            }
            eprintln!(
                "μ = {mu}, τ = {tau} N (from {from:?}): {n} unknowns, {kinks} guides sticking \
                 at a bound, exact vs central differences {:e} relative (largest entry {size:e})",
                worst / size
            );
            assert!(worst <= 1e-6 * size, "{:e}", worst / size);
        }
    }
}
