//! Workspace maps: sweep the tendon tensions, solve every configuration (warm-started from its
//! neighbour, in parallel across cores) and report the tip position with scalar stiffness
//! measures of the integrated tip compliance (the compliance-methodology paper, Fig. 1d).
//!
//! The samples are cut into contiguous chunks; each chunk is solved in order on one thread,
//! every solve warm-started from the previous converged one (so order the samples along a
//! path, e.g. grid rows in boustrophedon order); chunks run in parallel (rayon).

use rayon::prelude::*;

use std::sync::Arc;

use crate::compliance::eigenscrew::{eigenscrews, MatrixKind};
use crate::compliance::{tangent_compliance, tip_compliance_world, TendonControl};
use crate::cosserat::mesh::solve_at_output;
use crate::cosserat::statics::{solve_statics, SolveOptions, StaticsSolution};
use crate::error::{Error, Result};
use crate::math::linalg::invert_spd;
use crate::model::{Actuation, RobotModel};

/// Default number of samples per warm-started chunk.
pub const DEFAULT_CHUNK: usize = 64;

/// One configuration of a workspace map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorkspaceSample {
    /// Whether the statics converged (the other fields are NaN otherwise).
    pub converged: bool,
    /// Tip position (m, world).
    pub tip_position: [f64; 3],
    /// Largest translational compliance at the tip (m/N): largest eigenvalue of the
    /// force-to-translation block of the integrated tip compliance.
    pub max_translational_compliance: f64,
    /// Smallest translational compliance at the tip (m/N).
    pub min_translational_compliance: f64,
    /// Eigenstiffnesses of the tip stiffness (world frame at the tip), decreasing.
    pub eigen_stiffness: [f64; 6],
    /// 1-norm condition number of the tip compliance (SI units).
    pub condition: f64,
    /// Largest translational compliance (m/N) of the exact tangent tip compliance, when
    /// requested (NaN otherwise).
    pub tangent_max_translational_compliance: f64,
}

impl WorkspaceSample {
    fn failed() -> Self {
        Self {
            converged: false,
            tip_position: [f64::NAN; 3],
            max_translational_compliance: f64::NAN,
            min_translational_compliance: f64::NAN,
            eigen_stiffness: [f64::NAN; 6],
            condition: f64::NAN,
            tangent_max_translational_compliance: f64::NAN,
        }
    }
}

/// Solves `model` for every row of `tensions` (row-major, `n_samples × n_tendons`, N), with
/// the chamber pressures of `base` (Pa) in every sample, and measures the tip compliance.
/// `chunk` samples (>= 1) are solved in order per thread with warm starts, each under the mesh
/// control of [`solve_at_output`] (a default mesh too coarse for the shape is refined; a
/// chosen one too coarse is a failed sample). With `tangent`, the
/// exact tangent tip compliance (tendons at fixed tension or length) is computed too.
/// Non-converged samples are reported with `converged == false`.
///
/// # Errors
/// [`Error::InvalidParameter`] if `tensions.len()` is not a multiple of the number of tendons,
/// a tension is negative or not finite, `chunk == 0`, or the problem data are invalid.
pub fn workspace_map(
    model: &Arc<RobotModel>,
    base: &Actuation,
    tensions: &[f64],
    options: &SolveOptions,
    chunk: usize,
    tangent: Option<TendonControl>,
) -> Result<Vec<WorkspaceSample>> {
    let nt = model.tendons().len();
    if nt == 0 || !tensions.len().is_multiple_of(nt) {
        return Err(Error::invalid(
            "tensions",
            format!("{} values for {nt} tendons", tensions.len()),
            "n_samples x n_tendons values (at least one tendon)",
        ));
    }
    if chunk == 0 {
        return Err(Error::invalid("chunk", chunk, ">= 1"));
    }
    if tensions.is_empty() {
        return Ok(Vec::new());
    }
    for (i, t) in tensions.iter().enumerate() {
        if !(t.is_finite() && *t >= 0.0) {
            return Err(Error::invalid(
                format!("tensions[{}, {}]", i / nt, i % nt),
                t,
                "finite and >= 0 N",
            ));
        }
    }
    let pressures = base.pressure_values(model.chambers().len());
    let actuation = |row: &[f64]| Actuation::tensions(row).with_pressures(&pressures);
    // Every row within the load limits, named by its row (a map to 1e308 N solved every
    // sample to its failure, and a summary of the few that stayed below).
    for (k, row) in tensions.chunks(nt).enumerate() {
        model
            .check_actuation(&actuation(row))
            .map_err(|e| e.map_name(|n| n.replacen("tensions[", &format!("tensions[{k}, "), 1)))?;
    }
    // Validate the problem once (errors here are the user's, not a sample's).
    let mut quiet = *options;
    quiet.newton.throw = false;
    solve_statics(model, &actuation(&tensions[..nt]), &quiet)?;
    let rows: Vec<&[f64]> = tensions.chunks(nt).collect();
    let out: Vec<Vec<WorkspaceSample>> = rows
        .par_chunks(chunk)
        .map(|block| {
            let mut warm = None;
            let mut local = Vec::with_capacity(block.len());
            for row in block {
                let opts = SolveOptions {
                    warm_start: warm,
                    ..quiet
                };
                let sample = match solve_at_output(model, &actuation(row), &opts, &[]) {
                    Ok(sol) if sol.stats.converged => {
                        warm = Some(sol.warm_start());
                        let mut m = measure(&sol);
                        if let Some(ctl) = tangent {
                            if let Ok(t) = tangent_compliance(&sol, ctl, None) {
                                let b = t.world.fixed_view::<3, 3>(0, 0).into_owned();
                                let b = (b + b.transpose()) * 0.5;
                                m.tangent_max_translational_compliance =
                                    b.symmetric_eigen().eigenvalues.max();
                            }
                        }
                        m
                    }
                    _ => WorkspaceSample::failed(),
                };
                local.push(sample);
            }
            local
        })
        .collect();
    Ok(out.into_iter().flatten().collect())
}

fn measure(sol: &StaticsSolution) -> WorkspaceSample {
    let Ok(c) = tip_compliance_world(sol) else {
        return WorkspaceSample::failed();
    };
    let ctt = c.fixed_view::<3, 3>(0, 0).into_owned().symmetric_eigen();
    let (kmat, condition) = invert_spd(&c);
    let mut eig = [f64::NAN; 6];
    if let Ok(d) = eigenscrews(&kmat, MatrixKind::Stiffness) {
        for (k, s) in d.screws.iter().enumerate() {
            eig[k] = s.value;
        }
    }
    WorkspaceSample {
        converged: true,
        tip_position: sol.tip_position(),
        max_translational_compliance: ctt.eigenvalues.max(),
        min_translational_compliance: ctt.eigenvalues.min(),
        eigen_stiffness: eig,
        condition,
        tangent_max_translational_compliance: f64::NAN,
    }
}
