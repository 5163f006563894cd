//! Actuation sweeps of fixed robot models: the core of design studies.
//!
//! A [`SweepJob`] is one validated [`RobotModel`] (one design point), its solve options and a
//! table of actuations (tendon tensions, chamber pressures and, optionally, tip loads), one
//! row per sample. [`sweep`] solves every sample of every job and measures what a
//! [`SweepRequest`] asks for: the tip pose, tendon path lengths, and at chosen arc lengths the
//! backbone pose, the integrated compliance and stiffness (world frame), `γ_c`, the
//! eigenstiffnesses and the principal translational compliances ([`super::arc`] gives the
//! values between mesh nodes). Every sample is solved under the mesh control of
//! [`solve_at_output`] (a default mesh too coarse for the shape is refined, a chosen one too
//! coarse fails the sample naming `steps`). The convergence of every sample is recorded; a sample that
//! fails is reported with its status and error, never dropped.
//!
//! A job with obstacles or a held tip solves every sample by [`solve_constrained`] (under the
//! same mesh control) and starts every row cold, as a single solve of that robot does: a
//! contact solve warm-started from another actuation may find its contacts on another
//! branch.
//!
//! # Determinism: the warm-start rule
//! The rows of a job are cut into blocks of `block` consecutive rows aligned to the row index
//! (rows `[k block, (k + 1) block)`). The first row of a block starts cold (the core's
//! default start); every other row is warm-started from the converged solution of the row
//! before it, or starts cold if that row did not converge. A sample's result therefore
//! depends only on its block, never on how the rows are split between threads, tasks or
//! machines, as long as every split falls on a block boundary: the blocks run in parallel
//! (rayon) and the results are bit for bit those of a sequential run.

use std::sync::Arc;

use nalgebra::{Matrix6, Vector3};
use rayon::prelude::*;

use super::arc::{pose_at, ComplianceAt};
use crate::compliance::eigenscrew::{eigenscrews, MatrixKind};
use crate::compliance::gamma_c;
use crate::compliance::{compliance, compliance_at};
use crate::contact::{solve_constrained, ContactSolution, Obstacle, TipConstraint};
use crate::cosserat::mesh::{solve_at_output, with_mesh_control};
use crate::cosserat::statics::{Integrator, SolveOptions, StaticsSolution};
use crate::error::{Error, Result};
use crate::math::linalg::invert_spd;
use crate::model::chamber::check_pressure;
use crate::model::loads::Loads;
use crate::model::{Actuation, RobotModel};
use crate::solve::SolverStats;

/// Default number of rows per warm-started block.
pub const DEFAULT_WARM_BLOCK: usize = 32;

/// What a sweep measures at every sample (the convergence is always recorded).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SweepRequest {
    /// Tip position and orientation quaternion.
    pub tip_pose: bool,
    /// Path length of every tendon (m).
    pub tendon_lengths: bool,
    /// Backbone position and orientation at the arc lengths of the job.
    pub backbone: bool,
    /// Integrated compliance `C_world` at the arc lengths.
    pub compliance: bool,
    /// Stiffness `K_world = C_world⁻¹` at the arc lengths (NaN where `C` is singular, e.g.
    /// at `s = 0`).
    pub stiffness: bool,
    /// Dimensionless flexural compliance `γ_c` (body axes) at the arc lengths.
    pub gamma_c: bool,
    /// The six eigenstiffnesses of `K_world` at the arc lengths, decreasing.
    pub eigen_stiffness: bool,
    /// Principal translational compliances (eigenvalues of the force-to-translation block
    /// of `C_world`, m/N) at the arc lengths, decreasing.
    pub translational_compliance: bool,
    /// The contacts: their number, their total force on the rod and the tip constraint's
    /// reaction (jobs with obstacles or a held tip).
    pub contacts: bool,
}

impl SweepRequest {
    /// Whether any quantity at the arc lengths needs the compliance.
    fn needs_compliance(&self) -> bool {
        self.compliance
            || self.stiffness
            || self.gamma_c
            || self.eigen_stiffness
            || self.translational_compliance
    }

    /// Whether anything is measured at the arc lengths.
    fn needs_arcs(&self) -> bool {
        self.backbone || self.needs_compliance()
    }
}

/// The actuation of every sample of a job, as row-major tables (one row per sample).
#[derive(Debug, Clone, Copy)]
pub struct ActuationTable<'a> {
    /// Number of samples (rows).
    pub samples: usize,
    /// Tendon tensions (N), `samples × n_tendons` (empty for a model without tendons).
    pub tensions: &'a [f64],
    /// Chamber pressures (Pa, gauge), `samples × n_chambers` (empty without chambers).
    pub pressures: &'a [f64],
    /// Tip force (N) per sample, `samples × 3`, in the frame of the model's tip loads;
    /// `None` keeps the model's.
    pub tip_force: Option<&'a [f64]>,
    /// Tip moment (N m) per sample, `samples × 3`; `None` keeps the model's.
    pub tip_moment: Option<&'a [f64]>,
}

/// One design point of a sweep: a model, its options, its actuations and the arc lengths at
/// which to measure (m; values outside `[0, L]` give NaN).
#[derive(Debug, Clone)]
pub struct SweepJob<'a> {
    /// The robot model.
    pub model: Arc<RobotModel>,
    /// Solve options (`warm_start` is set by the sweep; `throw` is ignored).
    pub options: SolveOptions,
    /// The samples.
    pub actuations: ActuationTable<'a>,
    /// Arc lengths of the per-arc-length outputs (m).
    pub arc_lengths: Vec<f64>,
    /// Obstacles the rod is kept out of (none: the free rod).
    pub obstacles: Vec<Obstacle>,
    /// The tip's constraint, if held.
    pub tip_constraint: Option<TipConstraint>,
}

impl SweepJob<'_> {
    /// Whether its samples are contact solves.
    fn constrained(&self) -> bool {
        !self.obstacles.is_empty() || self.tip_constraint.is_some()
    }
}

/// How a sample ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleStatus {
    /// The statics converged; every requested output is filled in.
    Converged,
    /// The solver did not reach its tolerance (outputs NaN; the stats say how far it got).
    NotConverged,
    /// The solve failed with an error (e.g. a hyperelastic fibre compressed to zero length).
    Failed,
}

/// Outputs at one arc length (NaN where not requested or not defined).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcSample {
    /// Backbone position (m, world).
    pub position: [f64; 3],
    /// Orientation quaternion `[x, y, z, w]` (body → world, `w >= 0`).
    pub quaternion: [f64; 4],
    /// `C_world` (twist `[δp; δθ]` = C `[f; m]`; m/N, 1/N, rad/(N m) blocks).
    pub compliance: Matrix6<f64>,
    /// `K_world = C_world⁻¹`.
    pub stiffness: Matrix6<f64>,
    /// `γ_c` per body axis `(x, y, z)`.
    pub gamma_c: [f64; 3],
    /// Eigenstiffnesses of `K_world`, decreasing (N/m and N m/rad mixed by screw pitch).
    pub eigen_stiffness: [f64; 6],
    /// Principal translational compliances (m/N), decreasing.
    pub translational_compliance: [f64; 3],
}

impl ArcSample {
    fn nan() -> Self {
        Self {
            position: [f64::NAN; 3],
            quaternion: [f64::NAN; 4],
            compliance: Matrix6::repeat(f64::NAN),
            stiffness: Matrix6::repeat(f64::NAN),
            gamma_c: [f64::NAN; 3],
            eigen_stiffness: [f64::NAN; 6],
            translational_compliance: [f64::NAN; 3],
        }
    }
}

/// The result of one sample.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepSample {
    /// How the solve ended.
    pub status: SampleStatus,
    /// The error of a failed or non-converged solve, if one was raised.
    pub error: Option<Error>,
    /// Solver statistics (default values when the solve raised an error).
    pub stats: SolverStats,
    /// Tip position (m, world).
    pub tip_position: [f64; 3],
    /// Tip quaternion `[x, y, z, w]`.
    pub tip_quaternion: [f64; 4],
    /// Tendon path lengths (m), empty unless requested.
    pub tendon_lengths: Vec<f64>,
    /// One entry per arc length of the job (empty unless an arc-length output is requested).
    pub arcs: Vec<ArcSample>,
    /// Whether the converged equilibrium is stable ([`StaticsSolution::stable`], judged by
    /// the solve itself: always recorded, no extra cost); `None` when it did not converge.
    pub stable: Option<bool>,
    /// Active contacts (0 for a free rod; with [`SweepRequest::contacts`], else 0).
    pub contact_count: usize,
    /// Total force of the contacts on the rod (N, world), normal and tangential (NaN unless
    /// requested and converged).
    pub contact_force: [f64; 3],
    /// Reaction wrench `[f; m]` of the tip constraint on the rod (N, N m; world; NaN without
    /// one, unless requested, or not converged).
    pub tip_reaction: [f64; 6],
}

impl SweepSample {
    fn failed(
        status: SampleStatus,
        error: Option<Error>,
        stats: SolverStats,
        job: &SweepJob,
    ) -> Self {
        let nt = job.model.tendons().len();
        Self {
            status,
            error,
            stats,
            tip_position: [f64::NAN; 3],
            tip_quaternion: [f64::NAN; 4],
            tendon_lengths: vec![f64::NAN; nt],
            arcs: vec![ArcSample::nan(); job.arc_lengths.len()],
            stable: None,
            contact_count: 0,
            contact_force: [f64::NAN; 3],
            tip_reaction: [f64::NAN; 6],
        }
    }

    /// The contact outputs of a converged contact solution.
    fn with_contacts(mut self, c: &ContactSolution) -> Self {
        self.contact_count = c.contacts.len();
        let mut f = [0.0; 3];
        for contact in &c.contacts {
            for (k, fk) in f.iter_mut().enumerate() {
                *fk += contact.normal[k] * contact.normal_force + contact.tangential_force[k];
            }
        }
        self.contact_force = f;
        if let Some(r) = c.tip_reaction {
            self.tip_reaction = r;
        }
        self
    }
}

fn check_table(k: usize, job: &SweepJob<'_>) -> Result<()> {
    let name = |what: &str| {
        if k == 0 {
            what.to_string()
        } else {
            format!("jobs[{k}].{what}")
        }
    };
    let a = &job.actuations;
    let (nt, nc) = (job.model.tendons().len(), job.model.chambers().len());
    for (what, values, width) in [
        ("tensions", a.tensions, nt),
        ("pressures", a.pressures, nc),
        ("tip_force", a.tip_force.unwrap_or(&[]), 3),
        ("tip_moment", a.tip_moment.unwrap_or(&[]), 3),
    ] {
        let given = match what {
            "tip_force" => a.tip_force.is_some(),
            "tip_moment" => a.tip_moment.is_some(),
            _ => true,
        };
        if given && values.len() != a.samples * width {
            return Err(Error::invalid(
                name(&format!("{what}.len()")),
                values.len(),
                format!("samples x {width} = {}", a.samples * width),
            ));
        }
        for (i, &v) in values.iter().enumerate() {
            let at = name(&format!("{what}[{}, {}]", i / width, i % width));
            match what {
                "tensions" if !(v.is_finite() && v >= 0.0) => {
                    return Err(Error::invalid(at, v, "finite and >= 0 N"));
                }
                "pressures" => {
                    check_pressure(&at, v)?;
                }
                _ if !v.is_finite() => return Err(Error::invalid(at, v, "finite")),
                _ => {}
            }
        }
    }
    for (i, s) in job.arc_lengths.iter().enumerate() {
        if !s.is_finite() {
            return Err(Error::invalid(
                name(&format!("arc_lengths[{i}]")),
                s,
                "finite (m)",
            ));
        }
    }
    job.options.validate()
}

/// Solves every sample of every job (see the module documentation for the warm-start rule)
/// and measures the requested outputs. Blocks run in parallel across cores when `parallel`.
///
/// Returns one vector of samples per job, in row order.
///
/// # Errors
/// [`Error::InvalidParameter`] before any solve if `block == 0`, a table has the wrong size,
/// a tension is negative or not finite, a pressure below vacuum, a tip load or an arc length
/// not finite, or the options are invalid (names prefixed by `jobs[k].` after the first
/// job). Failures of single solves are not errors: they are reported per sample.
pub fn sweep(
    jobs: &[SweepJob<'_>],
    request: &SweepRequest,
    block: usize,
    parallel: bool,
) -> Result<Vec<Vec<SweepSample>>> {
    if block == 0 {
        return Err(Error::invalid("block", block, ">= 1"));
    }
    for (k, job) in jobs.iter().enumerate() {
        check_table(k, job)?;
    }
    let work: Vec<(usize, usize, usize)> = jobs
        .iter()
        .enumerate()
        .flat_map(|(k, job)| {
            let n = job.actuations.samples;
            (0..n.div_ceil(block)).map(move |b| (k, b * block, ((b + 1) * block).min(n)))
        })
        .collect();
    let run = |&(k, start, end): &(usize, usize, usize)| solve_block(&jobs[k], start, end, request);
    let blocks: Vec<Vec<SweepSample>> = if parallel {
        work.par_iter().map(run).collect()
    } else {
        work.iter().map(run).collect()
    };
    let mut out: Vec<Vec<SweepSample>> = jobs
        .iter()
        .map(|j| Vec::with_capacity(j.actuations.samples))
        .collect();
    for ((k, _, _), samples) in work.iter().zip(blocks) {
        out[*k].extend(samples);
    }
    Ok(out)
}

/// The actuation and, with per-sample tip loads, the model of row `i` of a job.
fn sample_problem(job: &SweepJob<'_>, i: usize) -> Result<(Arc<RobotModel>, Actuation)> {
    let a = &job.actuations;
    let (nt, nc) = (job.model.tendons().len(), job.model.chambers().len());
    let actuation = Actuation::tensions(&a.tensions[i * nt..(i + 1) * nt])
        .with_pressures(&a.pressures[i * nc..(i + 1) * nc]);
    if a.tip_force.is_none() && a.tip_moment.is_none() {
        return Ok((Arc::clone(&job.model), actuation));
    }
    let row = |v: &[f64]| Vector3::new(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    let base = job.model.loads();
    let loads = Loads {
        tip_force: a.tip_force.map_or(base.tip_force, row),
        tip_moment: a.tip_moment.map_or(base.tip_moment, row),
        ..base.clone()
    };
    Ok((job.model.with_loads(loads)?, actuation))
}

/// Solves rows `[start, end)` of a job in order, each warm-started from the converged row
/// before it (`start` is a block start: its row starts cold; every row of a contact job
/// starts cold).
fn solve_block(
    job: &SweepJob<'_>,
    start: usize,
    end: usize,
    request: &SweepRequest,
) -> Vec<SweepSample> {
    let length = job.model.length();
    let beyond = job
        .arc_lengths
        .iter()
        .enumerate()
        .find(|(_, &s)| request.needs_arcs() && !(0.0..=length).contains(&s));
    if let Some((i, &s)) = beyond {
        // A design whose rod is shorter than an arc length asked: nothing to measure there.
        let e = Error::invalid(
            format!("arc_lengths[{i}]"),
            s,
            format!("in [0, {length}] m, the rod of this job"),
        );
        return (start..end)
            .map(|_| {
                SweepSample::failed(
                    SampleStatus::Failed,
                    Some(e.clone()),
                    SolverStats::default(),
                    job,
                )
            })
            .collect();
    }
    let mut quiet = job.options;
    quiet.newton.throw = false;
    quiet.warm_start = None;
    let mut warm = None;
    let mut out = Vec::with_capacity(end - start);
    for i in start..end {
        let opts = SolveOptions {
            warm_start: warm.take(),
            ..quiet
        };
        let result =
            sample_problem(job, i).and_then(|(model, act)| solve_sample(job, &model, &act, &opts));
        let sample = match result.as_ref().map(Solved::statics) {
            Ok(sol) if sol.stats.converged => {
                if !job.constrained() {
                    warm = Some(sol.warm_start());
                }
                let sample = measure(sol, job, request);
                match &result {
                    Ok(Solved::Contact(c)) if request.contacts => sample.with_contacts(c),
                    _ => sample,
                }
            }
            Ok(sol) => SweepSample::failed(
                SampleStatus::NotConverged,
                Some(Error::NotConverged {
                    what: if job.constrained() {
                        "contact statics (Cosserat rod with obstacles or a held tip)".into()
                    } else {
                        "shooting Newton (Cosserat rod statics)".into()
                    },
                    iterations: sol.stats.iterations,
                    residual: sol.stats.residual,
                    load_factor: sol.stats.load_factor,
                }),
                sol.stats,
                job,
            ),
            Err(e) => {
                let status = match e {
                    Error::NotConverged { .. } => SampleStatus::NotConverged,
                    _ => SampleStatus::Failed,
                };
                SweepSample::failed(status, Some(e.clone()), SolverStats::default(), job)
            }
        };
        out.push(sample);
    }
    out
}

/// The solution of one sample: of the free rod, or with its contacts.
enum Solved {
    Free(StaticsSolution),
    Contact(ContactSolution),
}

impl Solved {
    fn statics(&self) -> &StaticsSolution {
        match self {
            Self::Free(s) => s,
            Self::Contact(c) => &c.solution,
        }
    }
}

/// The solution of one sample (a contact solve for a job with obstacles or a held tip), under
/// mesh control.
fn solve_sample(
    job: &SweepJob<'_>,
    model: &Arc<RobotModel>,
    actuation: &Actuation,
    options: &SolveOptions,
) -> Result<Solved> {
    if !job.constrained() {
        return solve_at_output(model, actuation, options, &[]).map(Solved::Free);
    }
    let tip = job.tip_constraint.as_ref();
    with_mesh_control(
        options,
        options.integrator.is_default_mesh(),
        |o| solve_constrained(model, actuation, o, tip, &job.obstacles),
        |c| &c.solution,
    )
    .map(Solved::Contact)
}

/// Eigenvalues of a symmetric 3×3 block, decreasing.
fn principal(m: &nalgebra::Matrix3<f64>) -> [f64; 3] {
    let sym = (m + m.transpose()) * 0.5;
    let mut e: Vec<f64> = sym.symmetric_eigen().eigenvalues.iter().copied().collect();
    e.sort_by(|a, b| b.total_cmp(a));
    [e[0], e[1], e[2]]
}

/// The requested outputs of a converged solution.
fn measure(sol: &StaticsSolution, job: &SweepJob<'_>, request: &SweepRequest) -> SweepSample {
    let nt = job.model.tendons().len();
    let mut sample = SweepSample {
        status: SampleStatus::Converged,
        error: None,
        stats: sol.stats,
        tip_position: [f64::NAN; 3],
        tip_quaternion: [f64::NAN; 4],
        tendon_lengths: if request.tendon_lengths {
            sol.tendon_lengths.clone()
        } else {
            vec![f64::NAN; nt]
        },
        arcs: vec![ArcSample::nan(); job.arc_lengths.len()],
        stable: Some(sol.stable),
        contact_count: 0,
        contact_force: [f64::NAN; 3],
        tip_reaction: [f64::NAN; 6],
    };
    if request.tip_pose {
        sample.tip_position = sol.tip_position();
        sample.tip_quaternion = sol.quaternion.last().copied().unwrap_or([f64::NAN; 4]);
    }
    if !request.needs_arcs() || job.arc_lengths.is_empty() {
        return sample;
    }
    // An adaptive solution's compliance is marched under step-size control, with a stop at
    // each arc length asked (its value there exact); an RK4 solution's is the quadrature at
    // its nodes, interpolated between them.
    let adaptive = matches!(sol.options.integrator, Integrator::Adaptive(_));
    let (stops, nodes) = match request.needs_compliance() {
        false => (None, None),
        true if adaptive => (compliance_at(sol, &job.arc_lengths).ok(), None),
        true => (None, compliance(sol).ok()),
    };
    let at = nodes.as_ref().map(|c| ComplianceAt::new(sol, c));
    let rod = sol.model.rod();
    for (i, (arc, &s)) in sample.arcs.iter_mut().zip(&job.arc_lengths).enumerate() {
        let (p, q) = pose_at(sol, s);
        if request.backbone {
            arc.position = p;
            arc.quaternion = q;
        }
        let (c, body) = match (&stops, &at) {
            (Some(stops), _) => (stops.world[i], stops.body[i]),
            (None, Some(at)) => {
                let c = at.world(s, &p);
                (c, at.body(s, &c, &q))
            }
            (None, None) => continue,
        };
        if request.compliance {
            arc.compliance = c;
        }
        if request.gamma_c {
            arc.gamma_c = gamma_c(rod, &body);
        }
        if request.translational_compliance && c.iter().all(|v| v.is_finite()) {
            arc.translational_compliance = principal(&c.fixed_view::<3, 3>(0, 0).into_owned());
        }
        if request.stiffness || request.eigen_stiffness {
            let (k, _) = invert_spd(&c);
            if request.stiffness {
                arc.stiffness = k;
            }
            if request.eigen_stiffness {
                if let Ok(d) = eigenscrews(&k, MatrixKind::Stiffness) {
                    for (e, screw) in arc.eigen_stiffness.iter_mut().zip(&d.screws) {
                        *e = screw.value;
                    }
                }
            }
        }
    }
    sample
}
