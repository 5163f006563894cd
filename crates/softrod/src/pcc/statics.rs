//! Statics of piecewise-constant-curvature (PCC) robots: arc parameters of every segment from
//! tendon tensions, chamber pressures and an external tip wrench.
//!
//! # Formulation: stationary potential energy over the PCC ansatz
//! Each segment `i` is a Cosserat rod of rest length `ℓ0`, bending stiffness `E I` and axial
//! stiffness `E A` (or inextensible), *restricted* to constant-curvature, twist-free,
//! shear-free shapes. Its configuration is the bending vector `θ = ℓ u = (θ_x, θ_y)` (rad, body
//! frame; `u` the curvature vector per deformed length,
//! [`ArcCoordinates::CurvatureVector`](crate::pcc::ArcCoordinates::CurvatureVector)) and the
//! length `ℓ`. The Cosserat energy of such a shape is, with the curvature per *undeformed*
//! length `θ/ℓ0` (as in the Cosserat engine) and the axial strain `ℓ/ℓ0 - 1`,
//!
//! ```text
//! U_i = E I |θ|² / (2 ℓ0) + E A (ℓ - ℓ0)² / (2 ℓ0).
//! ```
//!
//! A tendon pulled with tension `τ` at the base has potential `τ L` with `L` its path length; a
//! chamber at gauge pressure `p` does work `p A L_c`. For a straight tendon at the constant
//! body offset `d (cos β, sin β)` through segments `0..=k` (and a chamber in one segment),
//! the length on segment `j` is exact for an arc:
//! `L_j = ℓ_j - d (θ_y cos β - θ_x sin β)`. An external tip force `F` and moment `M` (world
//! frame, dead loads) do the virtual work `F·δp_tip + M·δω`. Equilibrium is stationarity,
//!
//! ```text
//! g(q) = ∂U/∂q + Σ τ ∂L/∂q - Σ p A ∂L_c/∂q - J_h(q)ᵀ [F; M] = 0,
//! ```
//!
//! with `J_h` the tip's hybrid Jacobian
//! ([`JacobianFrame::Hybrid`](crate::pcc::JacobianFrame::Hybrid)). In `θ` coordinates the
//! energy is quadratic and the actuator terms are constant: only the tip load is nonlinear.
//!
//! **Why energy and not a moment balance per segment.** Without external loads every section
//! of a segment carries the same actuator moment, and the two agree. Under a tip load the
//! moment varies along the segment and no arc balances it everywhere; a per-segment moment
//! balance must pick a section (base, middle, tip) arbitrarily. The stationarity condition
//! picks the *mean*: for a constant-curvature variation, the virtual work of the tip wrench is
//! `∫ m_b(s)·δũ ds0`, so `E I θ / ℓ0 = m_act + mean over the segment of the tip load's body
//! moment` (and the same for the axial force), the Galerkin (Ritz) projection of the Cosserat
//! rod onto the PCC shapes. Consequences that the tests check: without external loads, a
//! tendon-driven segment (or chain, distal tendons passing through proximal segments) is the
//! Cosserat solution exactly, extensible or not; a tip moment about the bending axis is exact
//! too; a small tip force on a straight segment gives the exact tip *rotation* `F L²/(2 E I)`
//! and 3/4 of the beam's tip deflection.
//!
//! The equilibrium equations are solved by damped Newton in the curvature-vector coordinates
//! `(u_x, u_y, ℓ)` of every segment with the exact Jacobian (second derivatives of the chain
//! kinematics in closed form; the dead moment makes it unsymmetric), starting from the
//! actuator-only solution, which is closed form. If the direct solve fails, the tip load is
//! applied in steps (continuation). For an inextensible segment the equation for `ℓ` is
//! replaced by the constraint `ℓ = ℓ0`.
//!
//! The tension map [`arc_from_tendon_tensions`](crate::pcc::arc_from_tendon_tensions) takes
//! `κ` per deformed length (the planar cable-arm paper's convention); this module takes the Cosserat engine's.
//! They agree for inextensible segments and differ by the factor `1 + ε` on `κ` otherwise.
//!
//! # References
//! R. J. Webster III, B. A. Jones, IJRR 29(13), 2010 (PCC kinematics, tendon lengths).
//! D. C. Rucker, R. J. Webster III, IEEE T-RO 27(6), 2011 (the Cosserat model it is compared
//! with). P. Rao, Q. Peyron, S. Lilge, J. Burgner-Kahrs, "How to model tendon-driven
//! continuum robots and benchmark modelling performance", Front. Robot. AI 7, 2021
//! (constant-curvature vs. Cosserat statics of tendon-driven robots).

use nalgebra::{DMatrix, DVector, Matrix3, Matrix4, Vector3};

use crate::error::{check_finite, check_positive, Error, Result};
use crate::limits::check_load;
use crate::pcc::actuation::{ElasticSegment, PccChambers, PccTendons};
use crate::pcc::kinematics::{chain_pose, PccChain, PccSegment};
pub(crate) use crate::pcc::kinematics::{seg_kin, SegKin};
use crate::solve::{
    continuation, newton, Armijo, ContinuationSettings, Evaluated, LineSearch, NewtonOptions,
    NewtonSettings, Problem, SolverStats,
};

/// Default tolerance on the scaled residual (max norm): bending residual `|g_θ| ℓ0 / E I`
/// (rad) and axial residual `|g_ℓ| / E A` (strain).
pub const DEFAULT_TOLERANCE: f64 = 1e-12;
/// Default cap on Newton iterations (per load step under continuation).
pub const DEFAULT_MAX_ITERATIONS: usize = 50;
/// Default cap on load steps under continuation.
pub const DEFAULT_MAX_LOAD_STEPS: usize = 64;
/// Most step halvings of the Newton line search.
pub const MAX_LINE_SEARCH_HALVINGS: usize = 20;

/// A tendon of a multi-segment robot: straight, at the constant body offset
/// `distance (cos angle, sin angle)` (m, rad from body x toward body y) in every segment it
/// passes through, pulled at the base and fixed at the tip of segment `last_segment`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoutedTendon {
    distance: f64,
    angle: f64,
    last_segment: usize,
    cos: f64,
    sin: f64,
}

impl RoutedTendon {
    /// A tendon at `distance` (m, > 0) and `angle` (rad), terminated at the tip of segment
    /// `last_segment` (0-based; checked against the robot when added).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `distance` or `angle`.
    pub fn new(distance: f64, angle: f64, last_segment: usize) -> Result<Self> {
        check_positive("distance", distance, "m")?;
        check_finite("angle", angle)?;
        let (sin, cos) = angle.sin_cos();
        Ok(Self {
            distance,
            angle,
            last_segment,
            cos,
            sin,
        })
    }
    /// Distance from the backbone (m).
    pub fn distance(&self) -> f64 {
        self.distance
    }
    /// Angle from body x toward body y (rad).
    pub fn angle(&self) -> f64 {
        self.angle
    }
    /// Index of the segment at whose tip the tendon is fixed.
    pub fn last_segment(&self) -> usize {
        self.last_segment
    }
}

/// A PCC robot (immutable, validated): elastic segments base to tip, tendons routed through
/// them, and pneumatic chambers per segment.
#[derive(Debug, Clone, PartialEq)]
pub struct PccRobot {
    bodies: Vec<ElasticSegment>,
    tendons: Vec<RoutedTendon>,
    /// `(segment, chambers)` in the order the pressures are given.
    chambers: Vec<(usize, PccChambers)>,
}

impl PccRobot {
    /// A robot of at least one segment, base to tip, without actuators.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `segments` if empty.
    pub fn new(segments: Vec<ElasticSegment>) -> Result<Self> {
        if segments.is_empty() {
            return Err(Error::invalid("segments", "[]", "at least one segment"));
        }
        Ok(Self {
            bodies: segments,
            tendons: Vec::new(),
            chambers: Vec::new(),
        })
    }

    /// Adds a tendon (its index is the number of tendons added before it).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `last_segment` if it is not a segment of the robot.
    pub fn with_tendon(mut self, tendon: RoutedTendon) -> Result<Self> {
        self.check_segment("last_segment", tendon.last_segment)?;
        self.check_offsets(&[tendon.distance])?;
        self.tendons.push(tendon);
        Ok(self)
    }

    /// Adds every tendon of `tendons`, terminated at the tip of `segment` (and passing through
    /// the segments before it at the same body offsets).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `segment` if it is not a segment of the robot.
    pub fn with_segment_tendons(mut self, segment: usize, tendons: &PccTendons) -> Result<Self> {
        self.check_segment("segment", segment)?;
        self.check_offsets(tendons.distances())?;
        for (&d, &b) in tendons.distances().iter().zip(tendons.angles()) {
            self.tendons.push(RoutedTendon::new(d, b, segment)?);
        }
        Ok(self)
    }

    /// Adds pneumatic `chambers` to `segment` (their pressures follow those of the chambers
    /// added before).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `segment` if it is not a segment of the robot, or
    /// `distances[i]` beyond [`MAX_OFFSET_RATIO`](crate::limits::MAX_OFFSET_RATIO) of its length.
    pub fn with_chambers(mut self, segment: usize, chambers: PccChambers) -> Result<Self> {
        self.check_segment("segment", segment)?;
        self.check_offsets(chambers.distances())?;
        self.chambers.push((segment, chambers));
        Ok(self)
    }

    /// Distances from the backbone within [`MAX_OFFSET_RATIO`](crate::limits::MAX_OFFSET_RATIO)
    /// of the robot's total rest length (as for the Cosserat rod's tendons).
    fn check_offsets(&self, distances: &[f64]) -> Result<()> {
        let l: f64 = self.bodies.iter().map(ElasticSegment::rest_length).sum();
        let max = crate::limits::MAX_OFFSET_RATIO * l;
        for (i, &d) in distances.iter().enumerate() {
            if d.is_nan() || d > max {
                return Err(Error::invalid(
                    format!("distances[{i}]"),
                    d,
                    format!(
                        "at most {} x the rest length = {max} m",
                        crate::limits::MAX_OFFSET_RATIO
                    ),
                ));
            }
        }
        Ok(())
    }

    fn check_segment(&self, name: &str, segment: usize) -> Result<()> {
        if segment < self.bodies.len() {
            Ok(())
        } else {
            Err(Error::invalid(
                name,
                segment,
                format!("a segment index < {}", self.bodies.len()),
            ))
        }
    }

    /// The segments' elastic properties, base to tip.
    pub fn segments(&self) -> &[ElasticSegment] {
        &self.bodies
    }
    /// The tendons, in the order of their tensions.
    pub fn tendons(&self) -> &[RoutedTendon] {
        &self.tendons
    }
    /// The chamber groups `(segment, chambers)`, in the order of their pressures.
    pub fn chambers(&self) -> &[(usize, PccChambers)] {
        &self.chambers
    }
    /// Number of tensions expected.
    pub fn n_tendons(&self) -> usize {
        self.tendons.len()
    }
    /// Number of pressures expected.
    pub fn n_chambers(&self) -> usize {
        self.chambers.iter().map(|(_, c)| c.len()).sum()
    }
}

/// Actuation and external loads of one configuration.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PccLoads {
    /// One tension per tendon (N, >= 0); empty: all zero.
    pub tensions: Vec<f64>,
    /// One gauge pressure per chamber (Pa); empty: all zero.
    pub pressures: Vec<f64>,
    /// Force at the tip (N, world frame, dead load).
    pub tip_force: Vector3<f64>,
    /// Moment at the tip (N m, world frame, dead load).
    pub tip_moment: Vector3<f64>,
}

/// Options of [`solve_pcc_statics`].
#[derive(Debug, Clone, PartialEq)]
pub struct PccSolveOptions {
    /// Nonlinear solve; the tolerance is on the scaled residual (bending `|g_θ| ℓ0 / E I` in
    /// rad, axial `|g_ℓ| / E A`); continuation steps the tip load.
    pub newton: NewtonOptions,
    /// Initial guess, one segment per robot segment; `None` starts from the actuator-only
    /// solution (exact without a tip load).
    pub warm_start: Option<Vec<PccSegment>>,
}

impl Default for PccSolveOptions {
    fn default() -> Self {
        Self {
            newton: NewtonOptions {
                tolerance: DEFAULT_TOLERANCE,
                max_iterations: DEFAULT_MAX_ITERATIONS,
                continuation: true,
                max_load_steps: DEFAULT_MAX_LOAD_STEPS,
                throw: true,
            },
            warm_start: None,
        }
    }
}

/// A solved PCC robot.
#[derive(Debug, Clone, PartialEq)]
pub struct PccStaticsSolution {
    /// Arc parameters of every segment, base to tip (segment `i` in the tip frame of `i - 1`).
    pub segments: Vec<PccSegment>,
    /// Tip pose (4×4, tip frame → world).
    pub tip_pose: Matrix4<f64>,
    /// Path length of every tendon from the base to its termination (m).
    pub tendon_lengths: Vec<f64>,
    /// Solver statistics.
    pub stats: SolverStats,
}

impl PccStaticsSolution {
    /// The solved shape as a chain (backbone frames, Jacobians).
    pub fn chain(&self) -> PccChain {
        // Never empty: a robot has at least one segment.
        PccChain::new(self.segments.clone()).unwrap_or_else(|_| unreachable!())
    }

    /// Curvature-vector coordinates `(u_x, u_y, ℓ)` (1/m, 1/m, m) of every segment.
    pub fn coordinates(&self) -> Vec<[f64; 3]> {
        self.segments
            .iter()
            .map(|s| {
                let u = s.curvature_vector();
                [u.x, u.y, s.length()]
            })
            .collect()
    }

    /// Warm start for a nearby problem.
    pub fn warm_start(&self) -> Vec<PccSegment> {
        self.segments.clone()
    }
}

/// The equilibrium equations at one configuration, in curvature-vector coordinates
/// `(u_x, u_y, ℓ)` per segment (3n rows, segment-major).
#[derive(Debug, Clone, PartialEq)]
pub struct PccEquilibrium {
    /// `g = ∂U/∂q + Σ τ ∂L/∂q - Σ p A ∂L_c/∂q - J_hᵀ [F; M]`: N m² for `u_x, u_y`, N for
    /// `ℓ`. For an inextensible segment the `ℓ` row is `(E I/ℓ0²) (ℓ - ℓ0)` instead.
    pub residual: DVector<f64>,
    /// Exact Jacobian `∂g/∂q` (3n × 3n, unsymmetric under a tip moment).
    pub jacobian: DMatrix<f64>,
    /// Scaled residual (max norm), as compared with the tolerance of [`PccSolveOptions::newton`].
    pub scaled_residual: f64,
}

// ---------------------------------------------------------------------------------------------
// The equilibrium equations.
// ---------------------------------------------------------------------------------------------

/// Validated loads with per-segment actuator terms (constant in θ coordinates).
struct Prepared {
    /// Per segment: generalized actuator force on `(θ_x, θ_y, ℓ)` (N m, N m, N).
    actuation: Vec<[f64; 3]>,
    force: Vector3<f64>,
    moment: Vector3<f64>,
}

fn check_vector(name: &str, v: &Vector3<f64>) -> Result<()> {
    for k in 0..3 {
        if !v[k].is_finite() {
            return Err(Error::invalid(format!("{name}[{k}]"), v[k], "finite"));
        }
    }
    Ok(())
}

/// The loads within [`MAX_LOAD_NUMBER`](crate::limits::MAX_LOAD_NUMBER), with the robot's
/// total rest length `L` and smallest bending stiffness `EI` (as for the Cosserat rod: a
/// tension `T` at distance `d` by `T (1 + d / L) L² / EI`, a chamber force `p A` likewise, a
/// tip force by `F L² / EI`, a tip moment by `M L / EI`).
fn check_load_limits(robot: &PccRobot, loads: &PccLoads) -> Result<()> {
    let l: f64 = robot.bodies.iter().map(ElasticSegment::rest_length).sum();
    let ei = robot
        .bodies
        .iter()
        .map(ElasticSegment::bending_stiffness)
        .fold(f64::INFINITY, f64::min);
    let f0 = ei / (l * l);
    for (i, (t, &tau)) in robot.tendons.iter().zip(&loads.tensions).enumerate() {
        let scale = f0 / (1.0 + t.distance / l);
        check_load(format_args!("tensions[{i}]"), tau, tau.abs(), scale, "N")?;
    }
    let mut k = 0;
    for (_, ch) in &robot.chambers {
        for i in 0..ch.len() {
            if let Some(&p) = loads.pressures.get(k) {
                let scale = f0 / (ch.areas()[i] * (1.0 + ch.distances()[i] / l));
                check_load(format_args!("pressures[{k}]"), p, p.abs(), scale, "Pa")?;
            }
            k += 1;
        }
    }
    let (f, m) = (loads.tip_force.norm(), loads.tip_moment.norm());
    check_load("tip_force", f, f, f0, "N")?;
    check_load("tip_moment", m, m, f0 * l, "N m")
}

fn prepare(robot: &PccRobot, loads: &PccLoads) -> Result<Prepared> {
    let (nt, nc) = (robot.n_tendons(), robot.n_chambers());
    // The same inputs as the Cosserat statics, checked the same way.
    crate::model::actuation::validate_values(&loads.tensions, &loads.pressures, nt, nc)?;
    check_vector("tip_force", &loads.tip_force)?;
    check_vector("tip_moment", &loads.tip_moment)?;
    check_load_limits(robot, loads)?;
    let mut actuation = vec![[0.0; 3]; robot.bodies.len()];
    for (t, &tau) in robot.tendons.iter().zip(&loads.tensions) {
        // -τ ∂L/∂(θ_x, θ_y, ℓ) = τ (-d sin β, d cos β, -1) on every segment passed.
        for act in actuation.iter_mut().take(t.last_segment + 1) {
            act[0] -= tau * t.distance * t.sin;
            act[1] += tau * t.distance * t.cos;
            act[2] -= tau;
        }
    }
    let mut k = 0;
    for (seg, ch) in &robot.chambers {
        for i in 0..ch.len() {
            let p = loads.pressures.get(k).copied().unwrap_or(0.0);
            k += 1;
            let (a, r, b) = (ch.areas()[i], ch.distances()[i], ch.angles()[i]);
            let (sb, cb) = b.sin_cos();
            // p A ∂L_c/∂(θ_x, θ_y, ℓ) = p A (r sin β, -r cos β, 1).
            actuation[*seg][0] += p * a * r * sb;
            actuation[*seg][1] -= p * a * r * cb;
            actuation[*seg][2] += p * a;
        }
    }
    Ok(Prepared {
        actuation,
        force: loads.tip_force,
        moment: loads.tip_moment,
    })
}

/// Per-segment scratch of one evaluation (world frame unless noted).
#[derive(Debug, Clone, Copy)]
struct SegWork {
    kin: SegKin,
    /// Rotation of the segment's base frame.
    base_r: Matrix3<f64>,
    /// Position of the segment's tip.
    tip: Vector3<f64>,
    /// Residual in `(θ_x, θ_y, ℓ)`.
    g_theta: [f64; 3],
    /// Columns `P` (tip of this segment), `Ω` (rotation) and `V = P + Ω × d` (chain tip)
    /// per unit rate of `(θ_x, θ_y, ℓ)`; `d` from this segment's tip to the chain tip, `μ`
    /// the tip load's moment about this segment's tip.
    pc: [Vector3<f64>; 3],
    oc: [Vector3<f64>; 3],
    vc: [Vector3<f64>; 3],
    dd: Vector3<f64>,
    mu: Vector3<f64>,
}

/// Scratch of one solve, allocated once.
struct Work {
    segs: Vec<SegWork>,
    /// `∂g_θ/∂θ` as n×n blocks of 3×3 (block `(i, j)` at `i n + j`).
    blocks: Vec<Matrix3<f64>>,
    g: DVector<f64>,
    h: DMatrix<f64>,
}

impl Work {
    fn new(n: usize) -> Self {
        Self {
            segs: Vec::with_capacity(n),
            blocks: Vec::new(),
            g: DVector::zeros(3 * n),
            h: DMatrix::zeros(0, 0),
        }
    }
}

/// Evaluates the residual (and, if `jacobian`, its Jacobian) at `q` (`(u_x, u_y, ℓ)` per
/// segment) with the tip load scaled by `factor`. Returns the scaled max-norm residual.
fn evaluate(
    robot: &PccRobot,
    prep: &Prepared,
    q: &[[f64; 3]],
    factor: f64,
    jacobian: bool,
    w: &mut Work,
) -> f64 {
    let n = q.len();
    w.segs.clear();
    let (mut gr, mut gp) = (Matrix3::identity(), Vector3::zeros());
    for qi in q {
        let l = qi[2];
        let kin = seg_kin(l * qi[0], l * qi[1], l);
        let base_r = gr;
        gp += gr * kin.p;
        gr *= kin.r;
        let z = Vector3::zeros();
        w.segs.push(SegWork {
            kin,
            base_r,
            tip: gp,
            g_theta: [0.0; 3],
            pc: [z; 3],
            oc: [z; 3],
            vc: [z; 3],
            dd: z,
            mu: z,
        });
    }
    let p_tip = gp;
    let f = prep.force * factor;
    let m = prep.moment * factor;
    let loaded = f != Vector3::zeros() || m != Vector3::zeros();

    let mut scaled = 0.0f64;
    for (i, sw) in w.segs.iter_mut().enumerate() {
        let body = &robot.bodies[i];
        let (l0, ei) = (body.rest_length(), body.bending_stiffness());
        let (a, b) = (q[i][2] * q[i][0], q[i][2] * q[i][1]);
        let act = prep.actuation[i];
        let mut gq = [
            ei / l0 * a - act[0],
            ei / l0 * b - act[1],
            match body.axial_stiffness() {
                Some(ea) => ea / l0 * (q[i][2] - l0) - act[2],
                None => 0.0,
            },
        ];
        if loaded {
            // Generalized force of the tip wrench: F·P + μ·Ω per coordinate.
            sw.dd = p_tip - sw.tip;
            sw.mu = m + sw.dd.cross(&f);
            for c in 0..3 {
                sw.pc[c] = sw.base_r * sw.kin.dp[c];
                if c < 2 {
                    sw.oc[c] = sw.base_r * sw.kin.w[c];
                }
                sw.vc[c] = sw.pc[c] + sw.oc[c].cross(&sw.dd);
                gq[c] -= f.dot(&sw.pc[c]) + sw.mu.dot(&sw.oc[c]);
            }
        }
        sw.g_theta = gq;
        scaled = scaled.max(gq[0].abs().max(gq[1].abs()) * l0 / ei);
        if let Some(ea) = body.axial_stiffness() {
            scaled = scaled.max(gq[2].abs() / ea);
        }
    }
    if !scaled.is_finite() {
        scaled = f64::INFINITY;
    }

    // To curvature-vector coordinates: g_u = Jᵀ g_θ, H_u = Jᵀ H_θ J + Σ g_θ ∂²θ/∂q², with
    // J = ∂(θ_x, θ_y, ℓ)/∂(u_x, u_y, ℓ) = [ℓ 0 u_x; 0 ℓ u_y; 0 0 1] per segment.
    for (i, sw) in w.segs.iter().enumerate() {
        let (ux, uy, l) = (q[i][0], q[i][1], q[i][2]);
        let [ga, gb, gl] = sw.g_theta;
        w.g[3 * i] = l * ga;
        w.g[3 * i + 1] = l * gb;
        w.g[3 * i + 2] = ux * ga + uy * gb + gl;
    }
    if jacobian {
        assemble_jacobian(robot, q, &f, loaded, w);
    }
    // Inextensible segments: the ℓ row is the constraint ℓ = ℓ0.
    for (i, body) in robot.bodies.iter().enumerate() {
        if body.axial_stiffness().is_none() {
            let l0 = body.rest_length();
            let kc = body.bending_stiffness() / (l0 * l0);
            w.g[3 * i + 2] = kc * (q[i][2] - l0);
            if jacobian {
                for c in 0..3 * n {
                    w.h[(3 * i + 2, c)] = 0.0;
                }
                w.h[(3 * i + 2, 3 * i + 2)] = kc;
            }
        }
    }
    scaled
}

/// `∂g/∂q` in curvature-vector coordinates into `w.h`: the elastic blocks, the load stiffness
/// of the tip wrench (force `f`, when `loaded`), mapped from `θ` coordinates.
fn assemble_jacobian(
    robot: &PccRobot,
    q: &[[f64; 3]],
    f: &Vector3<f64>,
    loaded: bool,
    w: &mut Work,
) {
    let n = q.len();
    if w.h.nrows() != 3 * n {
        w.blocks = vec![Matrix3::zeros(); n * n];
        w.h = DMatrix::zeros(3 * n, 3 * n);
    }
    for (i, body) in robot.bodies.iter().enumerate() {
        let l0 = body.rest_length();
        let kb = body.bending_stiffness() / l0;
        let ka = body.axial_stiffness().map_or(0.0, |ea| ea / l0);
        for j in 0..n {
            w.blocks[i * n + j] = if i == j {
                Matrix3::from_diagonal(&Vector3::new(kb, kb, ka))
            } else {
                Matrix3::zeros()
            };
        }
    }
    if loaded {
        load_stiffness(w, f);
    }
    for i in 0..n {
        let (uxi, uyi, li) = (q[i][0], q[i][1], q[i][2]);
        for j in 0..n {
            let (uxj, uyj, lj) = (q[j][0], q[j][1], q[j][2]);
            let b = &w.blocks[i * n + j];
            // B J: columns ℓ_j b0, ℓ_j b1, u_x b0 + u_y b1 + b2.
            let mut bj = Matrix3::zeros();
            for r in 0..3 {
                bj[(r, 0)] = lj * b[(r, 0)];
                bj[(r, 1)] = lj * b[(r, 1)];
                bj[(r, 2)] = uxj * b[(r, 0)] + uyj * b[(r, 1)] + b[(r, 2)];
            }
            // Jᵀ (B J): rows ℓ_i r0, ℓ_i r1, u_x r0 + u_y r1 + r2.
            let mut blk = Matrix3::zeros();
            for c in 0..3 {
                blk[(0, c)] = li * bj[(0, c)];
                blk[(1, c)] = li * bj[(1, c)];
                blk[(2, c)] = uxi * bj[(0, c)] + uyi * bj[(1, c)] + bj[(2, c)];
            }
            if i == j {
                let [ga, gb, _] = w.segs[i].g_theta;
                blk[(0, 2)] += ga;
                blk[(2, 0)] += ga;
                blk[(1, 2)] += gb;
                blk[(2, 1)] += gb;
            }
            w.h.fixed_view_mut::<3, 3>(3 * i, 3 * j).copy_from(&blk);
        }
    }
}

/// Adds `-∂(J_hᵀ W)/∂θ` (the load stiffness of the dead tip wrench) to `w.blocks`, from the
/// world columns of `evaluate`.
fn load_stiffness(w: &mut Work, f: &Vector3<f64>) {
    let n = w.segs.len();
    // Each entry is one dot product with the other segment's column (rows k of block (i, j)):
    // j < i: Ω_j·a_ik, a = P_ik × F + d_i × (F × Ω_ik) + Ω_ik × μ_i (proximal rotation);
    // j > i: V_j·b_ik, b = F × Ω_ik (distal motion of the tip);
    // j = i: second derivatives of the segment plus Ω_i·(d_i × b_ik).
    for i in 0..n {
        let si = &w.segs[i];
        let k = &si.kin;
        let rt = si.base_r.transpose();
        let (fl, ml) = (rt * f, rt * si.mu);
        let mut a_t = Matrix3::zeros();
        let mut b_t = Matrix3::zeros();
        let mut db_t = Matrix3::zeros();
        for kk in 0..3 {
            let b = f.cross(&si.oc[kk]);
            let db = si.dd.cross(&b);
            let a = si.pc[kk].cross(f) + db + si.oc[kk].cross(&si.mu);
            a_t.set_row(kk, &a.transpose());
            b_t.set_row(kk, &b.transpose());
            db_t.set_row(kk, &db.transpose());
        }
        let mut own = db_t * Matrix3::from_columns(&si.oc);
        for kk in 0..3 {
            for mm in 0..3 {
                let mut v = fl.dot(&k.ddp[kk][mm]);
                if kk < 2 && mm < 2 {
                    v += ml.dot(&k.dw[kk][mm]);
                }
                own[(kk, mm)] += v;
            }
        }
        for j in 0..n {
            let delta = if j < i {
                a_t * Matrix3::from_columns(&w.segs[j].oc)
            } else if j > i {
                b_t * Matrix3::from_columns(&w.segs[j].vc)
            } else {
                own
            };
            w.blocks[i * n + j] -= delta;
        }
    }
}

fn check_coordinates(robot: &PccRobot, q: &[[f64; 3]]) -> Result<()> {
    if q.len() != robot.bodies.len() {
        return Err(Error::invalid(
            "coordinates.len()",
            q.len(),
            format!("the number of segments, {}", robot.bodies.len()),
        ));
    }
    for (i, qi) in q.iter().enumerate() {
        for (k, name) in ["u_x", "u_y", "length"].iter().enumerate() {
            let ok = qi[k].is_finite() && (k < 2 || qi[k] > 0.0);
            if !ok {
                return Err(Error::invalid(
                    format!("coordinates[{i}].{name}"),
                    qi[k],
                    if k < 2 {
                        "finite (1/m)"
                    } else {
                        "finite and > 0 m"
                    },
                ));
            }
        }
    }
    Ok(())
}

/// The equilibrium residual and its exact Jacobian at the configuration `coordinates`
/// (`(u_x, u_y, ℓ)` per segment: 1/m, 1/m, m) of `robot` under `loads`; see the module
/// documentation. Zero residual is equilibrium.
///
/// # Errors
/// [`Error::InvalidParameter`] naming the invalid load (`tensions[i]`, `tip_force[k]`, ...)
/// or coordinate (`coordinates[i].length`, ...).
pub fn pcc_equilibrium(
    robot: &PccRobot,
    loads: &PccLoads,
    coordinates: &[[f64; 3]],
) -> Result<PccEquilibrium> {
    let prep = prepare(robot, loads)?;
    check_coordinates(robot, coordinates)?;
    let mut w = Work::new(coordinates.len());
    let scaled = evaluate(robot, &prep, coordinates, 1.0, true, &mut w);
    Ok(PccEquilibrium {
        residual: w.g,
        jacobian: w.h,
        scaled_residual: scaled,
    })
}

/// The PCC equilibrium as a [`Problem`] in `(u_x, u_y, ℓ)` per segment (unknowns) with the
/// tip load scaled by the load factor; its norm is the scaled residual.
struct Equilibrium<'a> {
    robot: &'a PccRobot,
    prep: &'a Prepared,
    work: Work,
    /// The unknowns of the last evaluation, per segment.
    q: Vec<[f64; 3]>,
    /// Scaled residual of the last evaluation.
    scaled: f64,
    evaluations: usize,
}

impl Problem for Equilibrium<'_> {
    fn dim(&self) -> usize {
        3 * self.q.len()
    }

    fn evaluate(
        &mut self,
        x: &[f64],
        lambda: f64,
        jacobian: Option<&mut [f64]>,
        r: &mut [f64],
    ) -> Evaluated {
        for (qi, xi) in self.q.iter_mut().zip(x.chunks_exact(3)) {
            *qi = [xi[0], xi[1], xi[2]];
            if qi[2].is_nan() || qi[2] <= 0.0 {
                return Evaluated::Failed;
            }
        }
        self.evaluations += 1;
        let want = jacobian.is_some();
        self.scaled = evaluate(self.robot, self.prep, &self.q, lambda, want, &mut self.work);
        r.copy_from_slice(self.work.g.as_slice());
        if !self.scaled.is_finite() {
            return Evaluated::Failed;
        }
        match jacobian {
            Some(j) => {
                j.copy_from_slice(self.work.h.as_slice());
                Evaluated::Jacobian
            }
            None => Evaluated::Residual,
        }
    }

    fn norm(&self, _r: &[f64]) -> f64 {
        self.scaled
    }
}

fn check_options(robot: &PccRobot, opts: &PccSolveOptions) -> Result<()> {
    opts.newton.validate()?;
    if let Some(ws) = &opts.warm_start {
        if ws.len() != robot.bodies.len() {
            return Err(Error::invalid(
                "warm_start.len()",
                ws.len(),
                format!("the number of segments, {}", robot.bodies.len()),
            ));
        }
        for (i, s) in ws.iter().enumerate() {
            if s.length() <= 0.0 {
                return Err(Error::invalid(
                    format!("warm_start[{i}].length"),
                    s.length(),
                    "> 0 m",
                ));
            }
        }
    }
    Ok(())
}

/// The actuator-only equilibrium (exact, closed form) in `(u_x, u_y, ℓ)`.
fn actuated(robot: &PccRobot, prep: &Prepared, loads: &PccLoads) -> Result<Vec<[f64; 3]>> {
    robot
        .bodies
        .iter()
        .zip(&prep.actuation)
        .map(|(body, act)| {
            let l0 = body.rest_length();
            let l = match body.axial_stiffness() {
                Some(ea) => l0 * (1.0 + act[2] / ea),
                None => l0,
            };
            if !(l > 0.0 && l.is_finite()) {
                let (name, values) = if loads.pressures.is_empty() {
                    ("tensions", format!("{:?}", loads.tensions))
                } else {
                    ("pressures", format!("{:?}", loads.pressures))
                };
                return Err(Error::invalid(
                    name,
                    values,
                    format!("an axial strain > -1 (net axial force {:e} N)", act[2]),
                ));
            }
            let th = l0 / body.bending_stiffness();
            Ok([th * act[0] / l, th * act[1] / l, l])
        })
        .collect()
}

/// Solves the statics of `robot` under `loads` (tensions, pressures, world-frame tip wrench)
/// by damped Newton with the exact Jacobian; see the module documentation for the model.
///
/// # Errors
/// [`Error::InvalidParameter`] naming the invalid load (`tensions.len()`, `tensions[i]`,
/// `pressures[i]`, `tip_force[k]`, `tip_moment[k]`), option or warm start, or the actuation
/// (`tensions`/`pressures`) if it would compress a segment to zero length;
/// [`Error::NotConverged`] if Newton (with continuation) fails and `options.throw` is true.
pub fn solve_pcc_statics(
    robot: &PccRobot,
    loads: &PccLoads,
    options: &PccSolveOptions,
) -> Result<PccStaticsSolution> {
    check_options(robot, options)?;
    let prep = prepare(robot, loads)?;
    let q_act = actuated(robot, &prep, loads)?;
    let warm: Option<Vec<f64>> = options.warm_start.as_ref().map(|ws| {
        ws.iter()
            .flat_map(|s| {
                let u = s.curvature_vector();
                [u.x, u.y, s.length()]
            })
            .collect()
    });
    let x0: &[f64] = warm.as_deref().unwrap_or(q_act.as_flattened());
    let unloaded = prep.force == Vector3::zeros() && prep.moment == Vector3::zeros();
    let opts = &options.newton;
    if unloaded && options.warm_start.is_none() {
        // Without a tip load the actuator-only start is exact: its residual alone checks it
        // (what Newton's first evaluation would do, without its set-up).
        let mut work = Work::new(robot.bodies.len());
        let scaled = evaluate(robot, &prep, &q_act, 1.0, false, &mut work);
        if scaled <= opts.tolerance {
            let stats = SolverStats {
                load_factor: 1.0,
                residual: scaled,
                converged: true,
                function_evaluations: 1,
                ..SolverStats::default()
            };
            return solution(robot, q_act.as_flattened(), stats);
        }
    }
    let mut p = Equilibrium {
        robot,
        prep: &prep,
        work: Work::new(robot.bodies.len()),
        q: vec![[0.0; 3]; robot.bodies.len()],
        scaled: f64::INFINITY,
        evaluations: 0,
    };
    let mut stats = SolverStats {
        load_factor: 1.0,
        ..SolverStats::default()
    };
    let settings = NewtonSettings {
        line_search: LineSearch {
            factor: 0.5,
            max_halvings: MAX_LINE_SEARCH_HALVINGS,
        },
        condition: Armijo::default(),
        first_step_limit: None,
        // Without a tip load the actuator-only start is exact: check it without the Jacobian.
        residual_first: unloaded && options.warm_start.is_none(),
        broyden: false,
        jacobian: None,
        exact_at_solution: false,
    };
    let mut result = newton(&mut p, x0, 1.0, opts, &settings);
    stats.iterations = result.iterations;
    if !result.converged && opts.continuation {
        let x_act = q_act.as_flattened();
        let start = ContinuationSettings {
            x0: x_act,
            jacobian0: None,
            first_increment: 0.25,
            max_increment: 0.5,
        };
        let c = continuation(
            &mut p,
            &start,
            opts,
            &NewtonSettings {
                residual_first: false,
                ..settings
            },
        );
        stats.iterations += c.iterations;
        stats.load_steps = c.steps;
        stats.load_factor = c.load_factor;
        if c.load_factor >= 1.0 {
            result = c.outcome;
        }
    }
    stats.residual = result.residual;
    stats.converged = result.converged;
    stats.function_evaluations = p.evaluations;
    if !result.converged && opts.throw {
        return Err(Error::not_converged(
            "PCC statics Newton",
            stats.iterations,
            result.residual,
        ));
    }
    solution(robot, &result.x, stats)
}

/// The solution at the coordinates `x` (`(u_x, u_y, ℓ)` per segment, flat) with `stats`.
fn solution(robot: &PccRobot, x: &[f64], stats: SolverStats) -> Result<PccStaticsSolution> {
    let segments = x
        .chunks_exact(3)
        .map(|qi| PccSegment::from_curvature_vector(qi[0], qi[1], qi[2]))
        .collect::<Result<Vec<_>>>()?;
    let tendon_lengths = robot
        .tendons
        .iter()
        .map(|t| {
            x[..3 * (t.last_segment + 1)]
                .chunks_exact(3)
                .map(|qi| {
                    let (a, b) = (qi[2] * qi[0], qi[2] * qi[1]);
                    qi[2] - t.distance * (b * t.cos - a * t.sin)
                })
                .sum()
        })
        .collect();
    Ok(PccStaticsSolution {
        tip_pose: chain_pose(&segments),
        segments,
        tendon_lengths,
        stats,
    })
}
