//! Configuration-dependent compliance and stiffness along a solved rod (seed 001).
//!
//! Conventions ([`crate::math::se3`]): twists `[δp; δθ]`, wrenches `[f; m]`, `t = C w`, `w = K t`.
//! At a node `s` the **world** compliance relates a wrench applied at the node's position with
//! world components to the node's twist in world components (`δθ` with `δR = δθ̂ R`); the
//! **body** compliance does the same in the node's body axes (`δR = R δθ̂`):
//! `C_body = blockdiag(Rᵀ, Rᵀ) C_world blockdiag(R, R)`.
//!
//! * [`element_compliance`]: `c(s) = diag[1/(kGA), 1/(kGA), 1/(EA), 1/(EIx), 1/(EIy), 1/(GJ)]`
//!   (seed eq. 1 with the torsion erratum), the material's tangent at the solved wrench.
//! * [`compliance`]: the seed's integrated compliance (eqs. 6–7), the serial sum of the
//!   element compliances frozen in the solved configuration,
//!   `C_world(s) = ∫₀ˢ Ad_{h(σ)} c(σ) Ad_{h(σ)}ᵀ dσ`, `h(σ) = (R(σ), p(σ) - p(s))`.
//!   Since `Ad_{h(σ)} = Ad_{(I, p(0) - p(s))} Ad_{(R(σ), p(σ) - p(0))}`, one cumulative
//!   integral `Q(s) = ∫₀ˢ Ad_{(R, p - p(0))} c Ad_{(R, p - p(0))}ᵀ dσ` gives every node:
//!   `C_world(s) = Ad_{(I, p(0) - p(s))} Q(s) Ad_{(I, p(0) - p(s))}ᵀ`. The integrand does not
//!   feed back into the kinematics, so instead of appending it to the ODE state (which would
//!   re-run the constitutive solves) it is integrated on the solved mesh by a fourth-order
//!   cumulative quadrature (per panel, the cubic through the four nearest nodes of the same
//!   interval): the same order as RK4, exact for the straight rod, and free of new solves.
//!   [`compliance`] and [`pcc_compliance`] both build a [`Configuration`] (nodes with arc
//!   length, pose and element compliance) and call the same integration: the PCC path samples
//!   the arcs of a [`PccStaticsSolution`] with the rod's section and material.
//! * [`tangent_compliance`]: the exact tangent of the loaded, actuated equilibrium, from the
//!   linearised boundary-value problem (variational equations of the shooting method, plus
//!   columns for the applied wrench and, with tendons held at fixed length, for the tensions
//!   and the path lengths), after Oliver-Butler, Till & Rucker (2019).
//! * [`gamma_c`]: the dimensionless flexural compliance.
//!
//! # References
//! K. Oliver-Butler, J. Till, C. Rucker, "Continuum robot stiffness under external loads and
//! prescribed tendon displacements", IEEE Trans. Robotics 35(2), 2019.

use nalgebra::{DMatrix, DVector, Matrix3, Matrix6, Vector3, Vector6};

use crate::cosserat::equations::{put3, rot, v3, Evaluator, Model, FULL, STATE};
use crate::error::{Error, Result};
use crate::integrate::{dp54, rk4_step};
use crate::model::loads::Loads;
use crate::pcc::statics::{PccRobot, PccStaticsSolution};
use crate::model::rod::Rod;
use crate::math::se3::rotation_adjoint;
use crate::math::so3::hat;
use crate::cosserat::statics::{build_model, project, rk4_plan, Integrator, SolveOptions, StaticsSolution};
use crate::model::tendon::Tendon;

/// Most tendons that can be held at fixed length by [`tangent_compliance`].
pub const MAX_HELD_TENDONS: usize = 8;

/// The integrated compliance and stiffness at every node of a solution.
#[derive(Debug, Clone, PartialEq)]
pub struct Compliance {
    /// Undeformed arc length of each node (m), as in the solution (break nodes twice).
    pub s: Vec<f64>,
    /// Element compliance `c(s)` (body; 1/N for the first three, 1/(N m²) for the last three).
    pub element: Vec<[f64; 6]>,
    /// `C_world(s)` (m/N, 1/N, rad/(N m) blocks), twist `[δp; δθ]` = C `[f; m]`.
    pub world: Vec<Matrix6<f64>>,
    /// `C_body(s)`.
    pub body: Vec<Matrix6<f64>>,
    /// Dimensionless flexural compliance per body axis (see [`gamma_c`]).
    pub gamma_c: Vec<[f64; 3]>,
}

impl Compliance {
    /// Compliance at the tip, world frame.
    pub fn tip_world(&self) -> Matrix6<f64> {
        self.world
            .last()
            .copied()
            .unwrap_or(Matrix6::repeat(f64::NAN))
    }
    /// Compliance at the tip, body frame.
    pub fn tip_body(&self) -> Matrix6<f64> {
        self.body
            .last()
            .copied()
            .unwrap_or(Matrix6::repeat(f64::NAN))
    }
    /// `K_world = C_world⁻¹` at every node where `C_world` is positive definite, NaN
    /// otherwise (e.g. at `s = 0`, or with shear and stretch off), with the 1-norm condition
    /// number `‖C‖₁ ‖K‖₁` of `C_world` (SI units; infinite where not positive definite).
    /// Computed on demand (Cholesky per node).
    pub fn stiffness_world(&self) -> (Vec<Matrix6<f64>>, Vec<f64>) {
        self.world.iter().map(invert_spd).unzip()
    }
    /// `K_body = C_body⁻¹` at every node (NaN where not positive definite); the condition
    /// numbers are those of [`Compliance::stiffness_world`] (the frames differ by a rotation).
    pub fn stiffness_body(&self) -> Vec<Matrix6<f64>> {
        self.body.iter().map(|c| invert_spd(c).0).collect()
    }
}

/// Element compliance `c(s)` at every node: the material's tangent compliance at the solved
/// body wrench of the rod (same shear coefficient as the statics).
pub fn element_compliance(rod: &Rod, solution: &StaticsSolution) -> Vec<[f64; 6]> {
    let k = rod.shear_coefficient();
    solution
        .s
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            let (n, m) = (solution.n_body[i], solution.m_body[i]);
            let wb = [n[0], n[1], n[2], m[0], m[1], m[2]];
            rod.material()
                .elastic_strain(&rod.section_at(s), k, rod.inextensible(), &wb)
                .1
        })
        .collect()
}

/// Nodes and weights (`m` of them) of the fourth-order integral over the panel
/// `[x_j, x_{j+1}]` of the cubic through the (up to) four nearest nodes.
fn panel_weights(x: &[f64], j: usize) -> ([usize; 4], [f64; 4], usize) {
    const G: [(f64, f64); 3] = [
        (0.112_701_665_379_258_31, 5.0 / 18.0),
        (0.5, 8.0 / 18.0),
        (0.887_298_334_620_741_7, 5.0 / 18.0),
    ];
    let n = x.len();
    let m = n.min(4);
    let start = j.saturating_sub(1).min(n - m);
    let mut nodes = [0usize; 4];
    let mut weights = [0.0f64; 4];
    for k in 0..m {
        nodes[k] = start + k;
    }
    let (a, b) = (x[j], x[j + 1]);
    for k in 0..m {
        let i = nodes[k];
        let mut w = 0.0;
        for (c, g) in G {
            let t = a + c * (b - a);
            let mut l = 1.0;
            for &q in &nodes[..m] {
                if q != i {
                    l *= (t - x[q]) / (x[i] - x[q]);
                }
            }
            w += g * (b - a) * l;
        }
        weights[k] = w;
    }
    (nodes, weights, m)
}

/// `blockdiag(Rᵀ, Rᵀ) M blockdiag(R, R)` (world to body components of a 6×6 compliance or
/// stiffness), block by block; exactly symmetric.
fn rotate_blocks(m: &Matrix6<f64>, r: &Matrix3<f64>) -> Matrix6<f64> {
    let rt = r.transpose();
    let b = |i: usize, j: usize| rt * m.fixed_view::<3, 3>(i, j) * r;
    blocks(&b(0, 0), &b(0, 3), &b(3, 3))
}

/// The symmetric matrix `[[tt, tr], [trᵀ, rr]]` (symmetrising the diagonal blocks).
fn blocks(tt: &Matrix3<f64>, tr: &Matrix3<f64>, rr: &Matrix3<f64>) -> Matrix6<f64> {
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&((tt + tt.transpose()) * 0.5));
    m.fixed_view_mut::<3, 3>(0, 3).copy_from(tr);
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(&tr.transpose());
    m.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&((rr + rr.transpose()) * 0.5));
    m
}

/// `C⁻¹` if `C` is symmetric positive definite (Cholesky), NaN otherwise; and the 1-norm
/// condition number `‖C‖₁ ‖C⁻¹‖₁` (infinite if `C` is not positive definite).
pub fn invert_spd(c: &Matrix6<f64>) -> (Matrix6<f64>, f64) {
    match cholesky_inverse(c) {
        Some(k) => {
            let cond = norm1(c) * norm1(&k);
            if cond.is_finite() {
                (k, cond)
            } else {
                (Matrix6::repeat(f64::NAN), f64::INFINITY)
            }
        }
        None => (Matrix6::repeat(f64::NAN), f64::INFINITY),
    }
}

/// Inverse of a symmetric positive definite 6×6 matrix by Cholesky `C = L Lᵀ`,
/// `C⁻¹ = L⁻ᵀ L⁻¹` (plain arrays: several times faster than the generic routine at this
/// size); `None` if a pivot is not positive.
fn cholesky_inverse(c: &Matrix6<f64>) -> Option<Matrix6<f64>> {
    let mut l = [[0.0f64; 6]; 6];
    for j in 0..6 {
        let mut d = c[(j, j)];
        for k in 0..j {
            d -= l[j][k] * l[j][k];
        }
        if !(d > 0.0 && d.is_finite()) {
            return None;
        }
        let dj = d.sqrt();
        l[j][j] = dj;
        for i in j + 1..6 {
            let mut v = c[(i, j)];
            for k in 0..j {
                v -= l[i][k] * l[j][k];
            }
            l[i][j] = v / dj;
        }
    }
    // W = L⁻¹ (lower triangular), by forward substitution.
    let mut w = [[0.0f64; 6]; 6];
    for j in 0..6 {
        w[j][j] = 1.0 / l[j][j];
        for i in j + 1..6 {
            let mut v = 0.0;
            for k in j..i {
                v -= l[i][k] * w[k][j];
            }
            w[i][j] = v / l[i][i];
        }
    }
    // C⁻¹ = Wᵀ W.
    let mut out = Matrix6::zeros();
    for i in 0..6 {
        for j in 0..=i {
            let mut v = 0.0;
            for k in i..6 {
                v += w[k][i] * w[k][j];
            }
            out[(i, j)] = v;
            out[(j, i)] = v;
        }
    }
    Some(out)
}

/// Matrix 1-norm (largest column sum of absolute values).
fn norm1(m: &Matrix6<f64>) -> f64 {
    m.column_iter()
        .map(|c| c.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// `C⁻¹` by LU (NaN if singular) and the 1-norm condition number of `C`, for matrices that
/// need not be symmetric (tangents under follower loads).
pub fn invert_general(c: &Matrix6<f64>) -> (Matrix6<f64>, f64) {
    match c.try_inverse() {
        Some(k) => (k, norm1(c) * norm1(&k)),
        None => (Matrix6::repeat(f64::NAN), f64::INFINITY),
    }
}

/// The integrated compliance at the last node only (world frame, at the tip), without the
/// per-node inverses: the cheap path of [`crate::batch::workspace::workspace_map`].
pub fn tip_compliance_world(rod: &Rod, solution: &StaticsSolution) -> Result<Matrix6<f64>> {
    compliance_matrices(&Configuration::from_statics(rod, solution)?, true)
        .map(|(w, _)| w[w.len() - 1])
}

/// Dimensionless flexural compliance `γ_c = diag(C_body,tt) · 3 E I(0) / L³` per body axis
/// `(x, y, z)`: the three translational diagonal entries of the body compliance scaled by the
/// base bending stiffness `E I(0) = E min(Ix, Iy)` at `s = 0` and the total undeformed length
/// `L`. A straight uniform Euler–Bernoulli cantilever has `γ_c = (1, 1, ·)` at its tip.
pub fn gamma_c(rod: &Rod, body: &Matrix6<f64>) -> [f64; 3] {
    let l = rod.length();
    let ei = rod.material().bending_stiffness(&rod.section_at(0.0));
    let k = 3.0 * ei / (l * l * l);
    [body[(0, 0)] * k, body[(1, 1)] * k, body[(2, 2)] * k]
}

/// Largest bending angle per quadrature panel (rad) of the PCC path ([`pcc_compliance`]):
/// on an arc the fourth-order quadrature converges as `0.06 (θ/n)⁴` relative (measured against
/// Castigliano, see docs/pcc.md), so 0.005 rad per panel is below 1e-10 of each block's scale
/// (and ~1e-9 of its smaller entries).
pub const PCC_PANEL_ANGLE: f64 = 0.005;

/// Fewest quadrature panels per PCC segment (a straight segment's integrand is a quadratic
/// in `s`, integrated exactly by any number of panels).
pub const PCC_MIN_PANELS: usize = 8;

/// A configuration to integrate the compliance along, as nodes (the one input of the
/// integrated compliance, provided by the Cosserat and the PCC models alike).
///
/// `s` is the undeformed arc length (m, non-decreasing; a repeated value starts a new
/// interval, e.g. at a load or a segment break); at each node, the backbone position (m,
/// world), the rotation (body → world) and the element compliance `c(s)` (body, per
/// undeformed length).
#[derive(Debug, Clone, PartialEq)]
pub struct Configuration {
    /// Undeformed arc length of each node (m).
    pub s: Vec<f64>,
    /// Backbone position of each node (m, world).
    pub position: Vec<Vector3<f64>>,
    /// Rotation of each node (body → world).
    pub rotation: Vec<Matrix3<f64>>,
    /// Element compliance `c(s)` of each node (body).
    pub element: Vec<[f64; 6]>,
}

impl Configuration {
    /// The solved mesh of a Cosserat solution of `rod`, with the material's tangent at the
    /// solved wrench ([`element_compliance`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `solution` if it has no nodes or its arrays differ
    /// in length.
    pub fn from_statics(rod: &Rod, solution: &StaticsSolution) -> Result<Self> {
        let n = solution.s.len();
        if n == 0 || solution.position.len() != n || solution.rotation.len() != n {
            return Err(Error::invalid(
                "solution",
                format!("{n} nodes"),
                "a solution with nodes",
            ));
        }
        Ok(Self {
            s: solution.s.clone(),
            position: solution
                .position
                .iter()
                .map(|p| Vector3::from(*p))
                .collect(),
            rotation: solution
                .rotation
                .iter()
                .map(|r| {
                    Matrix3::new(
                        r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1],
                        r[2][2],
                    )
                })
                .collect(),
            element: element_compliance(rod, solution),
        })
    }

    /// The arcs of a PCC solution of `robot`, sampled at `panels + 1` nodes per segment
    /// (default: `max(PCC_MIN_PANELS, ⌈θ / PCC_PANEL_ANGLE⌉)` for a bending angle `θ`; the
    /// segment's junction nodes repeated), placed at the base pose of `rod`, with the
    /// element compliance of `rod`'s section and (linear) material.
    ///
    /// A segment of rest length `ℓ0` and deformed length `ℓ` is uniformly stretched, so the
    /// node at undeformed `σ` of the segment is at deformed arc length `σ ℓ / ℓ0`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `rod` if its material is not linear or its length
    /// differs from the robot's total rest length (relative 1e-9), `solution` if its segment
    /// count differs from the robot's, `panels` if zero.
    pub fn from_pcc(
        rod: &Rod,
        robot: &PccRobot,
        solution: &PccStaticsSolution,
        panels: Option<usize>,
    ) -> Result<Self> {
        if !rod.material().is_linear() {
            return Err(Error::invalid(
                "rod",
                "a hyperelastic material",
                "a linear elastic rod (the PCC statics is linear)",
            ));
        }
        let segs = robot.segments();
        if solution.segments.len() != segs.len() {
            return Err(Error::invalid(
                "solution",
                format!("{} segments", solution.segments.len()),
                format!("a solution of the robot ({} segments)", segs.len()),
            ));
        }
        let total: f64 = segs.iter().map(|s| s.rest_length()).sum();
        if (total - rod.length()).abs() > 1e-9 * total {
            return Err(Error::invalid(
                "rod",
                format!("length {} m", rod.length()),
                format!("the robot's total rest length, {total} m"),
            ));
        }
        if panels == Some(0) {
            return Err(Error::invalid("panels", 0, ">= 1"));
        }
        let base = rod.base_pose();
        let (rb, pb) = (base.rotation(), base.position());
        let k = rod.shear_coefficient();
        let mut out = Self {
            s: Vec::new(),
            position: Vec::new(),
            rotation: Vec::new(),
            element: Vec::new(),
        };
        let (mut s0, mut frame_r, mut frame_p) = (0.0, rb, pb);
        for (seg, body) in solution.segments.iter().zip(segs) {
            let l0 = body.rest_length();
            let panels = panels.unwrap_or_else(|| {
                let n = (seg.bending_angle().abs() / PCC_PANEL_ANGLE).ceil();
                (n as usize).max(PCC_MIN_PANELS)
            });
            for j in 0..=panels {
                let f = j as f64 / panels as f64;
                let t = seg.pose_at(f * seg.length())?;
                let r = t.fixed_view::<3, 3>(0, 0).into_owned();
                let p = Vector3::new(t[(0, 3)], t[(1, 3)], t[(2, 3)]);
                let sigma = if j == panels { s0 + l0 } else { s0 + f * l0 };
                out.s.push(sigma);
                out.position.push(frame_p + frame_r * p);
                out.rotation.push(frame_r * r);
                out.element.push(rod.material().compliance(
                    &rod.section_at(sigma.min(rod.length())),
                    k,
                    rod.inextensible(),
                ));
            }
            s0 += l0;
            frame_p = out.position[out.position.len() - 1];
            frame_r = out.rotation[out.rotation.len() - 1];
        }
        Ok(out)
    }
}

/// World and body compliances, node by node.
type WorldBody = (Vec<Matrix6<f64>>, Vec<Matrix6<f64>>);

/// World and body compliances (all nodes, or only the last with `tip_only`) of a
/// configuration: the one integrated-compliance computation of both models.
fn compliance_matrices(config: &Configuration, tip_only: bool) -> Result<WorldBody> {
    let n = config.s.len();
    if n == 0
        || config.position.len() != n
        || config.rotation.len() != n
        || config.element.len() != n
    {
        return Err(Error::invalid(
            "configuration",
            format!("{n} nodes"),
            "nodes with equally long arrays",
        ));
    }
    let pos = |i: usize| config.position[i];
    let rotm = |i: usize| config.rotation[i];
    let p0 = pos(0);
    // Integrand Ad c Adᵀ with Ad = [[R, P R], [0, R]], P = (p - p(0))^: with
    // A = R c_v Rᵀ and B = R c_u Rᵀ it is [[A + P B Pᵀ, P B], [B Pᵀ, B]].
    let integrand: Vec<Matrix6<f64>> = (0..n)
        .map(|i| {
            let r = rotm(i);
            let e = &config.element[i];
            let a = r * Matrix3::from_diagonal(&Vector3::new(e[0], e[1], e[2])) * r.transpose();
            let b = r * Matrix3::from_diagonal(&Vector3::new(e[3], e[4], e[5])) * r.transpose();
            let pb = hat(&(pos(i) - p0)) * b;
            let mut m = Matrix6::zeros();
            m.fixed_view_mut::<3, 3>(0, 0)
                .copy_from(&(a + pb * hat(&(pos(i) - p0)).transpose()));
            m.fixed_view_mut::<3, 3>(0, 3).copy_from(&pb);
            m.fixed_view_mut::<3, 3>(3, 0).copy_from(&pb.transpose());
            m.fixed_view_mut::<3, 3>(3, 3).copy_from(&b);
            m
        })
        .collect();
    // Cumulative Q over the intervals (a repeated s starts a new interval; Q is continuous).
    let mut q = vec![Matrix6::zeros(); n];
    let mut start = 0;
    while start < n {
        let mut end = start + 1;
        while end < n && config.s[end] != config.s[end - 1] {
            end += 1;
        }
        if start > 0 {
            q[start] = q[start - 1];
        }
        let x = &config.s[start..end];
        for j in 0..x.len() - 1 {
            let (nodes, weights, m) = panel_weights(x, j);
            let mut acc = q[start + j];
            for k in 0..m {
                acc += integrand[start + nodes[k]] * weights[k];
            }
            q[start + j + 1] = acc;
        }
        start = end;
    }
    let (mut world, mut body) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let first = if tip_only { n - 1 } else { 0 };
    for (i, qi) in q.iter().enumerate().skip(first) {
        // C_world = T Q Tᵀ with T = [[I, P], [0, I]], P = (p(0) - p(s))^.
        let p = hat(&(p0 - pos(i)));
        let qtt = qi.fixed_view::<3, 3>(0, 0).into_owned();
        let qtr = qi.fixed_view::<3, 3>(0, 3).into_owned();
        let qrr = qi.fixed_view::<3, 3>(3, 3).into_owned();
        let ctr = qtr + p * qrr;
        let ctt = qtt + p * qtr.transpose() + ctr * p.transpose();
        let w = blocks(&ctt, &ctr, &qrr);
        // C_body = blockdiag(Rᵀ) C_world blockdiag(R).
        body.push(rotate_blocks(&w, &rotm(i)));
        world.push(w);
    }
    Ok((world, body))
}

/// The seed's integrated compliance (eqs. 6–7) at every node of a configuration of `rod`
/// (see the module documentation for the formula and the quadrature); `rod` scales
/// [`Compliance::gamma_c`].
///
/// # Errors
/// [`Error::InvalidParameter`] naming `configuration` if it has no nodes or its arrays
/// differ in length.
pub fn configuration_compliance(rod: &Rod, config: Configuration) -> Result<Compliance> {
    let (world, body) = compliance_matrices(&config, false)?;
    let gk = gamma_c(rod, &Matrix6::identity())[0];
    let gamma = body
        .iter()
        .map(|b| [b[(0, 0)] * gk, b[(1, 1)] * gk, b[(2, 2)] * gk])
        .collect();
    Ok(Compliance {
        s: config.s,
        element: config.element,
        world,
        body,
        gamma_c: gamma,
    })
}

/// The seed's integrated compliance (eqs. 6–7) at every node of `solution`, a solution of
/// `rod` (see the module documentation for the formula and the quadrature).
///
/// # Errors
/// [`Error::InvalidParameter`] naming `solution` if it has no nodes or its arrays differ in
/// length.
pub fn compliance(rod: &Rod, solution: &StaticsSolution) -> Result<Compliance> {
    configuration_compliance(rod, Configuration::from_statics(rod, solution)?)
}

/// The seed's integrated compliance along the arcs of a PCC solution (same computation as
/// [`compliance`], on [`Configuration::from_pcc`] with `panels` per segment, default from
/// [`PCC_PANEL_ANGLE`]); `rod` gives the section and material of `c(s)` and the base
/// pose. The nodes' `s` is the undeformed arc length, junctions repeated.
///
/// # Errors
/// As [`Configuration::from_pcc`].
pub fn pcc_compliance(
    rod: &Rod,
    robot: &PccRobot,
    solution: &PccStaticsSolution,
    panels: Option<usize>,
) -> Result<Compliance> {
    configuration_compliance(rod, Configuration::from_pcc(rod, robot, solution, panels)?)
}

// ------------------------------------------------------------------------ tangent compliance

/// How the tendons behave under the extra wrench of [`tangent_compliance`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TendonControl {
    /// Tensions held fixed (force-controlled actuators).
    #[default]
    Tension,
    /// Path lengths of all tendons held fixed (displacement-controlled actuators): the
    /// tensions change; the linearisation treats the tendons as bilateral (a tension may go
    /// negative, i.e. slack, without the model noticing).
    Length,
}

/// The exact tangent compliance at one node.
#[derive(Debug, Clone, PartialEq)]
pub struct TangentCompliance {
    /// Index of the node in the solution.
    pub node: usize,
    /// Its undeformed arc length (m).
    pub s: f64,
    /// `d[δp; δθ]/d[f; m]`, world components, wrench applied at the node.
    pub world: Matrix6<f64>,
    /// The same in the node's body axes.
    pub body: Matrix6<f64>,
    /// `world⁻¹` (NaN if not positive definite).
    pub stiffness_world: Matrix6<f64>,
    /// `body⁻¹` (NaN if not positive definite).
    pub stiffness_body: Matrix6<f64>,
    /// 1-norm condition number (SI units).
    pub condition: f64,
    /// Whether the tangent is symmetric to 1e-6 relative (it is at equilibria of conservative
    /// loads; follower loads make it non-symmetric).
    pub symmetric: bool,
    /// `dτ_i/d[f; m]` (N/N, N/(N m)), one row per tendon; zero rows under
    /// [`TendonControl::Tension`].
    pub tension_rate: Vec<[f64; 6]>,
}

/// Columns of the tangent pass: 6 base-wrench, up to `MAX_HELD_TENDONS` tension, 6 load.
const MAX_COLUMNS: usize = 12 + MAX_HELD_TENDONS;
/// Offset of the tendon-length sensitivities (column-major, `MAX_HELD_TENDONS` per column).
const LENGTHS: usize = STATE + 12 * MAX_COLUMNS;
/// Size of the tangent pass state.
const TN: usize = LENGTHS + MAX_COLUMNS * MAX_HELD_TENDONS;

struct TangentPass<'m, 'a> {
    ev: Evaluator<'m, 'a>,
    /// Indices of the held tendons.
    held: Vec<usize>,
    /// Current interval.
    interval: usize,
}

impl TangentPass<'_, '_> {
    fn ncol(&self) -> usize {
        12 + self.held.len()
    }

    /// `(t, r × t)` of tendon `i` (body) at strains `(v, u)`.
    fn tendon_direction(
        &self,
        i: usize,
        s: f64,
        v: &Vector3<f64>,
        u: &Vector3<f64>,
    ) -> Vector6<f64> {
        let model = self.ev.model;
        let props = model.rod.section_at(s);
        let (r, rp) = model.tendons[i].tendon.routing().offset(s, &props);
        let r = Vector3::new(r[0], r[1], 0.0);
        let w = v + u.cross(&r) + Vector3::new(rp[0], rp[1], 0.0);
        let t = w / w.norm();
        let q = r.cross(&t);
        Vector6::new(t.x, t.y, t.z, q.x, q.y, q.z)
    }

    fn rhs(&mut self, s: f64, y: &[f64; TN]) -> [f64; TN] {
        let mut yf = [0.0; FULL];
        yf[..STATE].copy_from_slice(&y[..STATE]);
        let d = self.ev.rhs::<FULL>(s, &yf);
        let sm = self.ev.tangent();
        let mut out = [0.0; TN];
        out[..STATE].copy_from_slice(&d[..STATE]);
        let r = rot(y);
        let ri = r.try_inverse().unwrap_or_else(|| r.transpose());
        let pd = v3(&d, 0);
        let v = ri * pd;
        let uh = ri * Matrix3::from_column_slice(&d[3..12]);
        let u = Vector3::new(
            0.5 * (uh[(2, 1)] - uh[(1, 2)]),
            0.5 * (uh[(0, 2)] - uh[(2, 0)]),
            0.5 * (uh[(1, 0)] - uh[(0, 1)]),
        );
        let (nw, mw) = (v3(y, 12), v3(y, 15));
        let (nb, mb) = (r.tr_mul(&nw), r.tr_mul(&mw));
        let b_end = self.ev.model.breaks[self.interval + 1];
        let dirs: Vec<Option<Vector6<f64>>> = self
            .held
            .iter()
            .map(|&i| {
                (self.ev.model.tendons[i].end >= b_end).then(|| self.tendon_direction(i, s, &v, &u))
            })
            .collect();
        let nh = self.held.len();
        for c in 0..self.ncol() {
            let b = STATE + 12 * c;
            let w = v3(y, b + 3);
            let dn = v3(y, b + 6);
            let dm = v3(y, b + 9);
            let dnb = nb.cross(&w) + r.tr_mul(&dn);
            let dmb = mb.cross(&w) + r.tr_mul(&dm);
            let mut e = Vector6::new(dnb.x, dnb.y, dnb.z, dmb.x, dmb.y, dmb.z);
            if (6..6 + nh).contains(&c) {
                if let Some(t) = &dirs[c - 6] {
                    e -= t;
                }
            }
            let e = sm * e;
            let (dv, du) = (
                e.fixed_rows::<3>(0).into_owned(),
                e.fixed_rows::<3>(3).into_owned(),
            );
            let dpd = r * (w.cross(&v) + dv);
            let wd = w.cross(&u) + du;
            let dmd = -(dpd.cross(&nw) + pd.cross(&dn));
            put3(&mut out, b, &dpd);
            put3(&mut out, b + 3, &wd);
            put3(&mut out, b + 9, &dmd);
            for (h, t) in dirs.iter().enumerate() {
                if let Some(t) = t {
                    out[LENGTHS + c * MAX_HELD_TENDONS + h] = t.dot(&e);
                }
            }
        }
        out
    }

    /// Packs the state and columns `c0..c0 + 6` into a FULL-layout array.
    fn pack(y: &[f64; TN], c0: usize) -> [f64; FULL] {
        let mut f = [0.0; FULL];
        f[..STATE].copy_from_slice(&y[..STATE]);
        for k in 0..6 {
            let (src, dst) = (STATE + 12 * (c0 + k), STATE + 12 * k);
            if c0 + k < MAX_COLUMNS {
                f[dst..dst + 12].copy_from_slice(&y[src..src + 12]);
            }
        }
        f
    }

    /// Point-load jumps at the interior break `b`, for the state and every column.
    fn jump(&self, b: f64, y: &mut [f64; TN]) {
        let model: &Model<'_> = self.ev.model;
        let ncol = self.ncol();
        let mut state = [0.0; STATE];
        let mut c0 = 0;
        while c0 < ncol {
            let mut f = Self::pack(y, c0);
            model.jump(b, &mut f);
            if c0 == 0 {
                state.copy_from_slice(&f[..STATE]);
            }
            for k in 0..6.min(ncol - c0) {
                let (src, dst) = (STATE + 12 * k, STATE + 12 * (c0 + k));
                y[dst..dst + 12].copy_from_slice(&f[src..src + 12]);
            }
            c0 += 6;
        }
        y[..STATE].copy_from_slice(&state);
    }

    /// Residual Jacobian columns (scaled as the shooting residual) of every column.
    fn residual_columns(&self, y: &[f64; TN]) -> Vec<Vector6<f64>> {
        let ncol = self.ncol();
        let mut cols = Vec::with_capacity(ncol);
        let mut c0 = 0;
        while c0 < ncol {
            let f = Self::pack(y, c0);
            if let (_, Some(j)) = self.ev.model.residual(&f) {
                for k in 0..6.min(ncol - c0) {
                    cols.push(j.column(k).into_owned());
                }
            }
            c0 += 6;
        }
        cols
    }
}

/// The exact tangent compliance of the equilibrium `solution` of `rod`, `tendons` and `loads`
/// (solved with `options`) at node `node` (default: the tip): the derivative of the node's
/// twist `[δp; δθ]` with respect to a dead wrench `[f; m]` applied at the node's position,
/// with the tendons held at fixed tension or at fixed length.
///
/// The linearised boundary-value problem is integrated once with the solver's integrator and
/// mesh: the six shooting columns (base wrench), one column per held tendon (tension), six
/// columns for the applied wrench (started at the node), with the tendon path-length
/// sensitivities `δℓ_i = ∫ t_iᵀ (δv + δu × r_i) ds` appended; the unknowns (base wrench, held
/// tensions) solve the linearised tip conditions and `δℓ_i = 0`.
///
/// # Errors
/// [`Error::InvalidParameter`] for a node out of range, more than [`MAX_HELD_TENDONS`]
/// tendons under [`TendonControl::Length`], or problem data the solver rejects;
/// [`Error::NotConverged`] if the integration fails or the linear system is singular.
pub fn tangent_compliance(
    rod: &Rod,
    tendons: &[Tendon],
    loads: &Loads,
    solution: &StaticsSolution,
    options: &SolveOptions,
    control: TendonControl,
    node: Option<usize>,
) -> Result<TangentCompliance> {
    let held: Vec<usize> = match control {
        TendonControl::Tension => Vec::new(),
        TendonControl::Length => (0..tendons.len()).collect(),
    };
    tangent_compliance_held(rod, tendons, loads, solution, options, &held, node)
}

/// [`tangent_compliance`] with only the tendons `held` (indices into `tendons`) at fixed
/// length, the others at fixed tension (e.g. hold only the tensioned tendons: a slack tendon
/// cannot push).
///
/// # Errors
/// As [`tangent_compliance`]; [`Error::InvalidParameter`] naming `held` for an index out of
/// range or repeated.
pub fn tangent_compliance_held(
    rod: &Rod,
    tendons: &[Tendon],
    loads: &Loads,
    solution: &StaticsSolution,
    options: &SolveOptions,
    held: &[usize],
    node: Option<usize>,
) -> Result<TangentCompliance> {
    let n = solution.s.len();
    let node = node.unwrap_or(n.saturating_sub(1));
    if node >= n {
        return Err(Error::invalid("node", node, format!("in [0, {n})")));
    }
    for (k, &i) in held.iter().enumerate() {
        if i >= tendons.len() || held[..k].contains(&i) {
            return Err(Error::invalid(
                format!("held[{k}]"),
                i,
                format!("distinct tendon indices in [0, {})", tendons.len()),
            ));
        }
    }
    let held = held.to_vec();
    if held.len() > MAX_HELD_TENDONS {
        return Err(Error::invalid(
            "tendons",
            held.len(),
            format!("at most {MAX_HELD_TENDONS} tendons held at fixed length"),
        ));
    }
    let model = build_model(rod, tendons, loads)?;
    let target = solution.s[node];
    let nh = held.len();
    let mut tension_rate = vec![[0.0; 6]; tendons.len()];
    if target <= 0.0 {
        let z = Matrix6::zeros();
        let nan = Matrix6::repeat(f64::NAN);
        return Ok(TangentCompliance {
            node,
            s: target,
            world: z,
            body: z,
            stiffness_world: nan,
            stiffness_body: nan,
            condition: f64::INFINITY,
            symmetric: true,
            tension_rate,
        });
    }
    let fm = model.f_ref * model.length;
    let bw = solution.base_wrench;
    let x = Vector6::new(
        bw[0] / model.f_ref,
        bw[1] / model.f_ref,
        bw[2] / model.f_ref,
        bw[3] / fm,
        bw[4] / fm,
        bw[5] / fm,
    );
    let mut pass = TangentPass {
        ev: Evaluator::new(&model),
        held,
        interval: 0,
    };
    let ncol = pass.ncol();
    let mut y = [0.0; TN];
    y[..FULL].copy_from_slice(&model.initial::<FULL>(&x));
    let load0 = 6 + nh;
    // Pose columns (δp, R w) of the unknowns at the node and its rotation.
    let mut recorded: Option<(Vec<Vector6<f64>>, Matrix3<f64>)> = None;
    let mut at_node = |s: f64, y: &mut [f64; TN]| {
        if recorded.is_none() && s == target {
            let r = rot(y);
            let cols = (0..load0)
                .map(|c| {
                    let b = STATE + 12 * c;
                    let (dp, w) = (v3(y, b), r * v3(y, b + 3));
                    Vector6::new(dp.x, dp.y, dp.z, w.x, w.y, w.z)
                })
                .collect();
            recorded = Some((cols, r));
            for k in 0..6 {
                let b = STATE + 12 * (load0 + k) + if k < 3 { 6 + k } else { 9 + k - 3 };
                y[b] = -1.0;
            }
        }
    };
    let breaks = model.breaks.clone();
    let fail = |what: &str| Error::NotConverged {
        what: format!("tangent compliance: {what}"),
        iterations: 0,
        residual: f64::INFINITY,
    };
    match options.integrator {
        Integrator::Rk4 { steps } => {
            let plan = rk4_plan(&breaks, steps);
            for k in 0..breaks.len() - 1 {
                let (a, b) = (breaks[k], breaks[k + 1]);
                pass.ev.set_interval(k);
                pass.interval = k;
                let m = plan[k];
                let h = (b - a) / m as f64;
                for i in 0..m {
                    let t = a + h * i as f64;
                    let mut f = |s: f64, yy: &[f64; TN]| pass.rhs(s, yy);
                    y = rk4_step(&mut f, t, &y, h);
                    project(&mut y);
                    if !y.iter().all(|v| v.is_finite()) {
                        return Err(fail("non-finite state"));
                    }
                    at_node(if i + 1 == m { b } else { t + h }, &mut y);
                }
                if k + 2 < breaks.len() {
                    pass.jump(b, &mut y);
                }
            }
        }
        Integrator::Adaptive(opts) => {
            for k in 0..breaks.len() - 1 {
                let (a, b) = (breaks[k], breaks[k + 1]);
                pass.ev.set_interval(k);
                pass.interval = k;
                let mut pieces = vec![a];
                if target > a && target < b {
                    pieces.push(target);
                }
                pieces.push(b);
                for w in pieces.windows(2) {
                    let sol = dp54(
                        |s, yy: &[f64; TN]| pass.rhs(s, yy),
                        w[0],
                        y,
                        w[1],
                        opts,
                        STATE,
                        project,
                    )?;
                    y = sol.y[sol.y.len() - 1];
                    at_node(w[1], &mut y);
                }
                if k + 2 < breaks.len() {
                    pass.jump(b, &mut y);
                }
            }
        }
    }
    let Some((pose_cols, r_node)) = recorded else {
        return Err(Error::invalid(
            "node",
            node,
            "a node of the solution's mesh (solve and tangent with the same integrator)",
        ));
    };
    let jcols = pass.residual_columns(&y);
    if jcols.len() != ncol {
        return Err(fail("residual Jacobian"));
    }
    // Linear system in z = [δx (scaled base wrench); δτ (held)].
    let dim = 6 + nh;
    let mut a = DMatrix::zeros(dim, dim);
    let mut rhs = DMatrix::zeros(dim, 6);
    for c in 0..ncol {
        let mut col = DVector::zeros(dim);
        for i in 0..6 {
            col[i] = jcols[c][i];
        }
        for h in 0..nh {
            col[6 + h] = y[LENGTHS + c * MAX_HELD_TENDONS + h];
        }
        if c < load0 {
            a.set_column(c, &col);
        } else {
            rhs.set_column(c - load0, &(-col));
        }
    }
    let z = a
        .lu()
        .solve(&rhs)
        .ok_or_else(|| fail("singular linearised problem"))?;
    let mut world = Matrix6::zeros();
    for i in 0..6 {
        let mut t = Vector6::zeros();
        for (c, p) in pose_cols.iter().enumerate() {
            t += p * z[(c, i)];
        }
        world.set_column(i, &t);
    }
    for (h, &ti) in pass.held.iter().enumerate() {
        for i in 0..6 {
            tension_rate[ti][i] = z[(6 + h, i)];
        }
    }
    let rt = rotation_adjoint(&r_node.transpose());
    let body = rt * world * rt.transpose();
    let asym = (world - world.transpose()).amax();
    let symmetric = asym <= 1e-6 * world.amax();
    let (kw, condition) = invert_general(&world);
    let (kb, _) = invert_general(&body);
    Ok(TangentCompliance {
        node,
        s: target,
        world,
        body,
        stiffness_world: kw,
        stiffness_body: kb,
        condition,
        symmetric,
        tension_rate,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panel_weights_integrate_cubics_exactly_on_uneven_nodes() {
        let x = [0.0, 0.1, 0.25, 0.3, 0.55, 0.6, 0.9];
        let f = |t: f64| 2.0 - 3.0 * t + 0.5 * t * t + 4.0 * t * t * t;
        let big_f = |t: f64| 2.0 * t - 1.5 * t * t + t.powi(3) / 6.0 + t.powi(4);
        for j in 0..x.len() - 1 {
            let (nodes, w, m) = panel_weights(&x, j);
            let q: f64 = (0..m).map(|k| w[k] * f(x[nodes[k]])).sum();
            let exact = big_f(x[j + 1]) - big_f(x[j]);
            assert!((q - exact).abs() < 1e-14, "panel {j}: {q} vs {exact}");
        }
    }

    #[test]
    fn cholesky_inverse_inverts_and_rejects_indefinite() {
        let a = Matrix6::from_fn(|i, j| 1.0 / (1.0 + i as f64 + j as f64));
        let c = a * a.transpose() + Matrix6::identity() * 1e-3;
        let (k, cond) = invert_spd(&c);
        assert!((k * c - Matrix6::identity()).amax() < 1e-9);
        assert!(cond.is_finite() && cond > 1.0);
        let (k, cond) = invert_spd(&(-c));
        assert!(k[(0, 0)].is_nan() && cond.is_infinite());
    }
}
