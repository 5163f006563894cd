//! One cell of the frictional variational march (see [`super::friction_linear`]): the cell
//! step of the state and the columns with the tension profile's variation over the cell,
//! the linearisation at a node (tendon directions, constitutive tangent), and the
//! piecewise-linear capstan rule of the cell with its slip branches.

use nalgebra::{DMatrix, Matrix3, Vector3, Vector6};

use super::equations::{
    col_rot, mul_hat, project, rot, v3, Column, Evaluator, Tangent, COLUMN, DM, DN, DR, STATE,
};
use super::friction_linear::Frozen;
use crate::error::{Error, Result};
use crate::integrate::System;

/// The branch an element takes under the change.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Branch {
    /// Slides on at the lower bound: `δτ_k+1 = δlo`.
    Lower,
    /// Slides on at the upper bound: `δτ_k+1 = δhi`.
    Upper,
    /// Sticks: `δτ_k+1 = 0`.
    Stick,
}

/// Which bounds an element's tension is at.
#[derive(Debug, Clone, Copy)]
pub(super) struct Bounds {
    pub(super) lower: bool,
    pub(super) upper: bool,
}

impl Bounds {
    /// The branch the values `δlo`, `δhi` give.
    pub(super) fn branch(self, dlo: f64, dhi: f64) -> Branch {
        if self.lower && dlo > 0.0 {
            Branch::Lower
        } else if self.upper && dhi < 0.0 {
            Branch::Upper
        } else {
            Branch::Stick
        }
    }
}

/// One cell step of the state and the columns: the [`Evaluator`] plus, per column, the
/// variation of the tension profile over the cell (and of a pressure).
pub(super) struct CellSystem<'e, 'w, 'c> {
    pub(super) ev: Evaluator<'e, 'w>,
    pub(super) a: f64,
    pub(super) b: f64,
    /// Per tendon, the tensions at the cell's ends (N) and whether it carries a profile.
    pub(super) ends: &'c [[f64; 2]],
    pub(super) profiled: &'c [bool],
    /// Per column and tendon, `(δτ_k, δτ_k+1)`.
    pub(super) dtau: &'c [Vec<[f64; 2]>],
    /// Per column, a chamber's pressure change (per Pa).
    pub(super) pressure: &'c [Option<(usize, f64)>],
    pub(super) dirs: Vec<Option<Vector6<f64>>>,
}

impl CellSystem<'_, '_, '_> {
    /// `δτ_i(s)` of the interpolated profile at the cell fraction `w` (`TensionProfile::at`:
    /// geometric between two positive tensions, linear otherwise).
    #[inline]
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
#[inline]
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
pub(super) struct NodeLin {
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
    pub(super) fn at(
        fr: &Frozen<'_>,
        ev: &mut Evaluator<'_, '_>,
        s: f64,
        y: &[f64],
    ) -> Result<Self> {
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
    pub(super) fn tangents(&self) -> Vec<Option<Vector3<f64>>> {
        self.w
            .iter()
            .map(|w| w.map(|(w, _)| (self.r * w).normalize()))
            .collect()
    }

    /// The change of the path tangents (world) of the column at `b0` of `y` with the
    /// tension changes `dtau` at the node (and a pressure change).
    pub(super) fn variation(
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
pub(super) fn angle_variation(
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
pub(super) struct CellRule {
    pub(super) bounds: Vec<Bounds>,
    pub(super) l: DMatrix<f64>,
    pub(super) h: DMatrix<f64>,
}

impl CellRule {
    /// The distal tension changes `z` on the branches `branches` for the constant parts
    /// `lo`, `hi`.
    pub(super) fn solve(&self, branches: &[Branch], lo: &[f64], hi: &[f64]) -> Result<Vec<f64>> {
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
    pub(super) fn branches(&self, lo: &[f64], hi: &[f64]) -> Result<(Vec<Branch>, Vec<f64>)> {
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
