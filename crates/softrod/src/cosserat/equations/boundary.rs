//! The boundary and the external loads of the equations: the initial state at the base, the
//! distributed loads, the jumps of the internal wrench at point loads, the scaled tip
//! residual and its derivatives.

use nalgebra::{Vector3, Vector6};

use super::{col_rot, put3, rot, v3, Equations, COLUMN, DM, DN, FULL, STATE};
use crate::model::loads::Frame;
use crate::model::section::SectionProperties;

impl<'e> Equations<'e> {
    /// Distributed force `λ (f(s) + rho A(s) g)` (N/m, world).
    #[inline]
    pub fn distributed_force(&self, s: f64, props: &SectionProperties) -> Vector3<f64> {
        let loads = self.model.loads();
        let mut f = match &loads.distributed_force {
            Some(p) => p.at(s),
            None => Vector3::zeros(),
        };
        if let Some(g) = self.model.rho_g() {
            f += g * props.area;
        }
        f * self.load_factor
    }

    #[inline]
    pub(super) fn distributed_moment(&self, s: f64) -> Vector3<f64> {
        match &self.model.loads().distributed_moment {
            Some(p) => p.at(s) * self.load_factor,
            None => Vector3::zeros(),
        }
    }

    /// Initial state for the scaled base wrench `x` (`N(0) = f_ref x[0..3]`,
    /// `M(0) = f_ref L x[3..6]`), with identity seeds for the first six columns when they
    /// fit in `N`.
    pub fn initial<const N: usize>(&self, x: &[f64]) -> [f64; N] {
        let mut y = [0.0; N];
        let pose = self.model.rod().base_pose();
        put3(&mut y, 0, &pose.position());
        y[3..12].copy_from_slice(pose.rotation().as_slice());
        let f_ref = self.model.force_scale();
        let fm = f_ref * self.model.length();
        for k in 0..3 {
            y[12 + k] = f_ref * x[k];
            y[15 + k] = fm * x[3 + k];
        }
        if N >= FULL {
            for k in 0..3 {
                y[STATE + COLUMN * k + DN + k] = f_ref;
                y[STATE + COLUMN * (k + 3) + DM + k] = fm;
            }
        }
        y
    }

    /// World-frame force and moment (and, for the first `ncol` columns, their sensitivities)
    /// of a load given in `frame`, applied where the state is `y`.
    #[inline]
    fn applied<const N: usize>(
        &self,
        y: &[f64; N],
        ncol: usize,
        force: &Vector3<f64>,
        moment: &Vector3<f64>,
        frame: Frame,
        d: &mut [[Vector3<f64>; 2]],
    ) -> (Vector3<f64>, Vector3<f64>) {
        let (f, m) = (force * self.load_factor, moment * self.load_factor);
        match frame {
            Frame::World => (f, m),
            Frame::Body => {
                let r = rot(y);
                for (k, dk) in d.iter_mut().enumerate().take(ncol) {
                    let dr = col_rot(y, STATE + COLUMN * k);
                    dk[0] += dr * f;
                    dk[1] += dr * m;
                }
                (r * f, r * m)
            }
        }
    }

    /// Applies the point loads at the interior break `sigma` (crossing it toward the tip) to
    /// the state and its first `ncol` columns.
    pub fn jump<const N: usize>(&self, sigma: f64, y: &mut [f64; N], ncol: usize) {
        let loads = self.model.loads();
        let mut d = vec![[Vector3::zeros(); 2]; ncol];
        for pl in loads.point_loads.iter().filter(|p| p.s == sigma) {
            d.iter_mut().for_each(|x| *x = [Vector3::zeros(); 2]);
            let (f, m) = self.applied(y, ncol, &pl.force, &pl.moment, pl.frame, &mut d);
            let (n1, m1) = (v3(y, 12) - f, v3(y, 15) - m);
            put3(y, 12, &n1);
            put3(y, 15, &m1);
            for (k, dk) in d.iter().enumerate() {
                let b = STATE + COLUMN * k;
                let (dn1, dm1) = (v3(y, b + DN) - dk[0], v3(y, b + DM) - dk[1]);
                put3(y, b + DN, &dn1);
                put3(y, b + DM, &dm1);
            }
        }
    }

    /// Scaled tip residual `[(N(L) - F)/f_ref; (M(L) - M)/(f_ref L)]` and its derivative
    /// along each of the first `ncol` columns.
    pub fn residual<const N: usize>(
        &self,
        y: &[f64; N],
        ncol: usize,
    ) -> (Vector6<f64>, Vec<Vector6<f64>>) {
        let lw = self.model.loads();
        let mut d = vec![[Vector3::zeros(); 2]; ncol];
        let (mut f, mut m) =
            self.applied(y, ncol, &lw.tip_force, &lw.tip_moment, lw.tip_frame, &mut d);
        let l = self.model.length();
        for pl in lw.point_loads.iter().filter(|p| p.s == l) {
            let (f2, m2) = self.applied(y, ncol, &pl.force, &pl.moment, pl.frame, &mut d);
            f += f2;
            m += m2;
        }
        let f_ref = self.model.force_scale();
        let fm = f_ref * l;
        let rf = (v3(y, 12) - f) / f_ref;
        let rm = (v3(y, 15) - m) / fm;
        let r = Vector6::new(rf.x, rf.y, rf.z, rm.x, rm.y, rm.z);
        let cols = (0..ncol)
            .map(|k| {
                let b = STATE + COLUMN * k;
                let jf = (v3(y, b + DN) - d[k][0]) / f_ref;
                let jm = (v3(y, b + DM) - d[k][1]) / fm;
                Vector6::new(jf.x, jf.y, jf.z, jm.x, jm.y, jm.z)
            })
            .collect();
        (r, cols)
    }

    /// `∂r/∂λ` of the scaled tip residual at fixed unknowns, when the external loads do not
    /// change the internal force along the rod (world-frame tip and point moments, tip force):
    /// minus the scaled applied tip wrench. `None` otherwise.
    pub fn load_derivative_force_free(&self) -> Option<Vector6<f64>> {
        let lw = self.model.loads();
        if !self.model.force_free() || lw.tip_frame == Frame::Body {
            return None;
        }
        if lw
            .point_loads
            .iter()
            .any(|p| p.frame == Frame::Body && p.moment != Vector3::zeros())
        {
            return None;
        }
        if lw.distributed_moment.is_some() {
            return None;
        }
        let l = self.model.length();
        let mut m = lw.tip_moment;
        let f = lw.tip_force;
        // A world-frame moment applied along the rod reaches the tip unchanged (N ≡ const).
        for p in lw.point_loads.iter() {
            m += p.moment;
        }
        let f_ref = self.model.force_scale();
        let fm = f_ref * l;
        Some(Vector6::new(
            -f.x / f_ref,
            -f.y / f_ref,
            -f.z / f_ref,
            -m.x / fm,
            -m.y / fm,
            -m.z / fm,
        ))
    }
}
