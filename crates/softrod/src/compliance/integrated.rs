//! Configuration-dependent compliance and stiffness along a solved rod (the compliance-methodology paper).
//!
//! Conventions ([`crate::math::se3`]): twists `[δp; δθ]`, wrenches `[f; m]`, `t = C w`, `w = K t`.
//! At a node `s` the **world** compliance relates a wrench applied at the node's position with
//! world components to the node's twist in world components (`δθ` with `δR = δθ̂ R`); the
//! **body** compliance does the same in the node's body axes (`δR = R δθ̂`):
//! `C_body = blockdiag(Rᵀ, Rᵀ) C_world blockdiag(R, R)`.
//!
//! * [`element_compliance`]: `c(s) = diag[1/(kGA), 1/(kGA), 1/(EA), 1/(EIx), 1/(EIy), 1/(GJ)]`
//!   (eq. 1 of the compliance-methodology paper, with its torsion correction), the material's tangent at the solved wrench.
//! * [`compliance`]: the paper's integrated compliance (eqs. 6–7), the serial sum of the
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

use nalgebra::{Matrix3, Matrix6, Vector3};

use crate::cosserat::statics::{Integrator, StaticsSolution};
use crate::error::{Error, Result};
use crate::math::linalg::invert_spd;
use crate::math::so3::hat;
use crate::model::rod::Rod;
use crate::pcc::statics::{PccRobot, PccStaticsSolution};

use super::controlled::march_compliance;

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
    /// The compliance at the nodes `s` (m) with their element compliances `element` and
    /// world and body blocks (as the fields), [`Self::gamma_c`] from the body blocks scaled
    /// by `rod` (one scale for all nodes, see [`gamma_c`]).
    fn of_rod(
        rod: &Rod,
        s: Vec<f64>,
        element: Vec<[f64; 6]>,
        world: Vec<Matrix6<f64>>,
        body: Vec<Matrix6<f64>>,
    ) -> Self {
        let gk = gamma_c(rod, &Matrix6::identity())[0];
        let gamma_c = body
            .iter()
            .map(|b| [b[(0, 0)] * gk, b[(1, 1)] * gk, b[(2, 2)] * gk])
            .collect();
        Self {
            s,
            element,
            world,
            body,
            gamma_c,
        }
    }

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
pub fn element_compliance(solution: &StaticsSolution) -> Vec<[f64; 6]> {
    let rod = solution.model.rod();
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
    let n = x.len();
    let m = n.min(4);
    let start = j.saturating_sub(1).min(n - m);
    let mut nodes = [0usize; 4];
    for k in 0..m {
        nodes[k] = start + k;
    }
    let (a, b) = (x[j], x[j + 1]);
    let mut weights = [0.0f64; 4];
    let at = |k: usize| x[start + k];
    match m {
        4 => weights = lagrange_integrals([at(0), at(1), at(2), at(3)], a, b),
        3 => weights[..3].copy_from_slice(&lagrange_integrals([at(0), at(1), at(2)], a, b)),
        _ => weights[..2].copy_from_slice(&lagrange_integrals([at(0), at(1)], a, b)),
    }
    (nodes, weights, m)
}

/// The integrals over `[a, b]` of the Lagrange polynomials of the nodes `xs` (exact up to
/// cubics: three-point Gauss–Legendre), `prod (t - x_q) / prod (x_i - x_q)` over `q != i`.
fn lagrange_integrals<const M: usize>(xs: [f64; M], a: f64, b: f64) -> [f64; M] {
    const G: [(f64, f64); 3] = [
        (0.112_701_665_379_258_31, 5.0 / 18.0),
        (0.5, 8.0 / 18.0),
        (0.887_298_334_620_741_7, 5.0 / 18.0),
    ];
    let mut w = [0.0; M];
    for (c, g) in G {
        let t = a + c * (b - a);
        for i in 0..M {
            let mut l = 1.0;
            for q in 0..M {
                if q != i {
                    l *= t - xs[q];
                }
            }
            w[i] += g * l;
        }
    }
    for i in 0..M {
        let mut denominator = 1.0;
        for q in 0..M {
            if q != i {
                denominator *= xs[i] - xs[q];
            }
        }
        w[i] *= (b - a) / denominator;
    }
    w
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

/// The integrated compliance at the tip only (world frame), as [`compliance`]; for an RK4
/// solution without the per-node inverses (the cheap path of
/// [`crate::batch::workspace::workspace_map`]).
///
/// # Errors
/// As [`compliance`].
pub fn tip_compliance_world(solution: &StaticsSolution) -> Result<Matrix6<f64>> {
    if marched(solution) {
        let length = solution.model.length();
        return Ok(compliance_at(solution, &[length])?.world[0]);
    }
    compliance_matrices(&Configuration::from_statics(solution)?, true).map(|(w, _)| w[w.len() - 1])
}

/// Whether [`compliance`] of `solution` is marched under step-size control (adaptive
/// solutions) rather than integrated on the solution's mesh (RK4 solutions).
fn marched(solution: &StaticsSolution) -> bool {
    matches!(solution.options.integrator, Integrator::Adaptive(_))
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
    /// The solved mesh of a Cosserat solution, with the material's tangent at the solved
    /// wrench ([`element_compliance`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `solution` if it has no nodes or its arrays differ
    /// in length.
    pub fn from_statics(solution: &StaticsSolution) -> Result<Self> {
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
            element: element_compliance(solution),
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
    let mut q: Vec<Matrix6<f64>> = Vec::with_capacity(n);
    q.push(Matrix6::zeros());
    let mut start = 0;
    while start < n {
        let mut end = start + 1;
        while end < n && config.s[end] != config.s[end - 1] {
            end += 1;
        }
        if start > 0 {
            q.push(q[start - 1]);
        }
        let x = &config.s[start..end];
        for j in 0..x.len() - 1 {
            let (nodes, weights, m) = panel_weights(x, j);
            let mut acc = q[start + j];
            for k in 0..m {
                acc += integrand[start + nodes[k]] * weights[k];
            }
            q.push(acc);
        }
        start = end;
    }
    let first = if tip_only { n - 1 } else { 0 };
    Ok(transport(&p0, (first..n).map(|i| (pos(i), rotm(i), q[i]))))
}

/// `C_world(s) = T Q(s) Tᵀ`, `T = [[I, P], [0, I]]`, `P = (p(0) - p(s))^`, and
/// `C_body = blockdiag(Rᵀ) C_world blockdiag(R)`, node by node, from `(p(s), R(s), Q(s))`.
fn transport(
    p0: &Vector3<f64>,
    nodes: impl Iterator<Item = (Vector3<f64>, Matrix3<f64>, Matrix6<f64>)>,
) -> WorldBody {
    let n = nodes.size_hint().0;
    let (mut world, mut body) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for (p, r, qi) in nodes {
        let p = hat(&(p0 - p));
        let qtt = qi.fixed_view::<3, 3>(0, 0).into_owned();
        let qtr = qi.fixed_view::<3, 3>(0, 3).into_owned();
        let qrr = qi.fixed_view::<3, 3>(3, 3).into_owned();
        let ctr = qtr + p * qrr;
        let ctt = qtt + p * qtr.transpose() + ctr * p.transpose();
        let w = blocks(&ctt, &ctr, &qrr);
        body.push(rotate_blocks(&w, &r));
        world.push(w);
    }
    (world, body)
}

/// The paper's integrated compliance (eqs. 6–7) at every node of a configuration of `rod`
/// (see the module documentation for the formula and the quadrature); `rod` scales
/// [`Compliance::gamma_c`].
///
/// # Errors
/// [`Error::InvalidParameter`] naming `configuration` if it has no nodes or its arrays
/// differ in length.
pub fn configuration_compliance(rod: &Rod, config: Configuration) -> Result<Compliance> {
    let (world, body) = compliance_matrices(&config, false)?;
    Ok(Compliance::of_rod(
        rod,
        config.s,
        config.element,
        world,
        body,
    ))
}

/// The paper's integrated compliance (eqs. 6-7) at every node of `solution`. For an adaptive
/// solution it is integrated under step-size control to the solution's own tolerances
/// ([`compliance_at`]); for an RK4 solution by the composite quadrature on the solution's
/// mesh, or, for a solution at the default steps where the mesh's estimated rotational
/// truncation error exceeds
/// [`super::MESH_ROTATION_TARGET`] (strongly curved rods), on a finer nested mesh re-solved
/// from the solution ([`super::refine`]): about 1e-7 relative on stress-free arcs up to 2π.
/// [`compliance_at`] with `solution.s` gives the values under step-size control at
/// [`super::COMPLIANCE_RTOL`].
///
/// # Errors
/// [`Error::InvalidParameter`] naming `solution` if it has no nodes or its arrays differ in
/// length; as [`compliance_at`] for an adaptive solution.
pub fn compliance(solution: &StaticsSolution) -> Result<Compliance> {
    if marched(solution) {
        return compliance_at(solution, &solution.s);
    }
    let rod = solution.model.rod();
    let Some((fine, map)) = super::refine::refined(solution) else {
        return configuration_compliance(rod, Configuration::from_statics(solution)?);
    };
    // On the finer mesh, reported at the solution's nodes.
    let all = configuration_compliance(rod, Configuration::from_statics(&fine)?)?;
    Ok(Compliance {
        s: solution.s.clone(),
        element: map.iter().map(|&j| all.element[j]).collect(),
        world: map.iter().map(|&j| all.world[j]).collect(),
        body: map.iter().map(|&j| all.body[j]).collect(),
        gamma_c: map.iter().map(|&j| all.gamma_c[j]).collect(),
    })
}

/// The integrated compliance at the arc lengths `s_out` (m, any values in `[0, L]`, in any order; a
/// value repeated at a break gives the values before, then after, the jump). Every `s_out` is
/// a stop of the compliance march: exact, not interpolated.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `solution` if it has no nodes, or `s_out[i]` outside
/// `[0, L]`; [`Error::NotConverged`] if the march fails.
pub fn compliance_at(solution: &StaticsSolution, s_out: &[f64]) -> Result<Compliance> {
    if solution.s.is_empty() {
        return Err(Error::invalid(
            "solution",
            "0 nodes",
            "a solution with nodes",
        ));
    }
    let nodes = march_compliance(solution, s_out)?;
    let rod = solution.model.rod();
    let p0 = rod.base_pose().position();
    // At the solution's own nodes the body blocks are in its frames (they differ from the
    // march's by the solution's truncation error), so that its rotations relate the world and
    // body blocks; the world blocks are the march's.
    let frame = |n: &super::controlled::MarchedNode| {
        let rotation = match solution.s.iter().position(|&s| s == n.s) {
            Some(i) => Matrix3::from_fn(|a, b| solution.rotation[i][a][b]),
            None => n.rotation,
        };
        (n.position, rotation, n.q)
    };
    let (world, body) = transport(&p0, nodes.iter().map(frame));
    Ok(Compliance::of_rod(
        rod,
        nodes.iter().map(|n| n.s).collect(),
        nodes.iter().map(|n| n.element).collect(),
        world,
        body,
    ))
}

/// The paper's integrated compliance along the arcs of a PCC solution (same computation as
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
}
