//! Robots as the tests write them: tendons with their tensions and chambers with their
//! pressures, split into the model and the actuation by [`solve`]; and the one fixture of the
//! two-segment NiTi tendon robot (also used by the benches and examples, through
//! `#[path = "../tests/common/robot.rs"]`).
#![allow(dead_code, missing_docs, clippy::unwrap_used)]

use std::sync::Arc;

use softrod::{
    solve_statics, Actuation, Chamber, ChamberArea, Integrator, LinearElastic, Loads, Obstacle,
    Result, RobotModel, Rod, Routing, Section, SolveOptions, StaticsSolution, Tendon,
};

/// A tendon and the tension it is pulled with (N).
#[derive(Clone, Debug)]
pub struct Tensioned {
    pub tendon: Tendon,
    pub tension: f64,
}

impl Tensioned {
    pub fn tension(&self) -> f64 {
        self.tension
    }
    pub fn with_tension(&self, tension: f64) -> Result<Self> {
        Ok(Self {
            tendon: self.tendon.clone(),
            tension,
        })
    }
}

/// A tendon at the constant offset `(x, y)` (m) with `tension` (N).
pub fn tendon(offset: [f64; 2], tension: f64, end: Option<f64>) -> Result<Tensioned> {
    tendon_with(Routing::Constant(offset), tension, end)
}

/// A tendon of any routing with `tension` (N).
pub fn tendon_with(routing: Routing, tension: f64, end: Option<f64>) -> Result<Tensioned> {
    Ok(Tensioned {
        tendon: Tendon::new(routing, end)?,
        tension,
    })
}

/// A chamber and its gauge pressure (Pa).
#[derive(Clone, Debug)]
pub struct Pressurised {
    pub chamber: Chamber,
    pub pressure: f64,
}

pub fn chamber(
    pressure: f64,
    area: ChamberArea,
    offset: [f64; 2],
    start: f64,
    end: Option<f64>,
) -> Result<Pressurised> {
    softrod::model::chamber::check_pressure("pressure", pressure)?;
    Ok(Pressurised {
        chamber: Chamber::new(area, offset, start, end)?,
        pressure,
    })
}

pub fn constant_chamber(pressure: f64, area: f64, offset: [f64; 2]) -> Result<Pressurised> {
    chamber(pressure, ChamberArea::Constant(area), offset, 0.0, None)
}

/// The model and actuation of a rod with tensioned tendons and pressurised chambers.
pub fn split(
    rod: &Rod,
    tendons: &[Tensioned],
    chambers: &[Pressurised],
    loads: &Loads,
) -> Result<(Arc<RobotModel>, Actuation)> {
    let model = RobotModel::new(
        rod.clone(),
        tendons.iter().map(|t| t.tendon.clone()).collect(),
        chambers.iter().map(|c| c.chamber.clone()).collect(),
        loads.clone(),
    )?;
    let t: Vec<f64> = tendons.iter().map(|t| t.tension).collect();
    let p: Vec<f64> = chambers.iter().map(|c| c.pressure).collect();
    Ok((model, Actuation::tensions(&t).with_pressures(&p)))
}

/// Solves a rod with tensioned tendons under loads.
pub fn solve(
    rod: &Rod,
    tendons: &[Tensioned],
    loads: &Loads,
    options: &SolveOptions,
) -> Result<StaticsSolution> {
    solve_with_chambers(rod, tendons, &[], loads, options)
}

/// Solves a rod with tensioned tendons and pressurised chambers under loads.
pub fn solve_with_chambers(
    rod: &Rod,
    tendons: &[Tensioned],
    chambers: &[Pressurised],
    loads: &Loads,
    options: &SolveOptions,
) -> Result<StaticsSolution> {
    let (model, act) = split(rod, tendons, chambers, loads)?;
    solve_statics(&model, &act, options)
}

/// The two-segment NiTi robot: a 0.4 m superelastic NiTi backbone (E = 54 GPa, nu = 0.3,
/// radius 0.7 mm).
pub fn niti_rod() -> Rod {
    Rod::new(
        0.4,
        Section::circular(0.7e-3).expect("radius"),
        LinearElastic::new(54e9, 0.3).expect("material"),
    )
    .expect("rod")
}

/// Its six tendons at 10 mm, at 90°, -30°, 210° in each segment; the first three end at
/// 0.2 m, the others at the tip; with the given tensions (N).
pub fn niti_tendons(tensions: &[f64; 6]) -> Vec<Tensioned> {
    (0..6)
        .map(|i| {
            let ang = [90.0f64, -30.0, 210.0][i % 3].to_radians();
            tendon(
                [0.01 * ang.cos(), 0.01 * ang.sin()],
                tensions[i],
                Some(if i < 3 { 0.2 } else { 0.4 }),
            )
            .expect("tendon")
        })
        .collect()
}

/// The two-segment NiTi robot as a model (its tendons, without tensions) under `loads`, with
/// the rod's `density` (kg/m³) if given and the friction coefficient `friction` on every
/// tendon (0: frictionless).
pub fn niti_model(loads: Loads, density: Option<f64>, friction: f64) -> Arc<RobotModel> {
    let mut rod = niti_rod();
    if let Some(d) = density {
        rod = rod.with_density(d).expect("density");
    }
    let tendons = niti_tendons(&[0.0; 6])
        .into_iter()
        .map(|t| {
            if friction == 0.0 {
                t.tendon
            } else {
                t.tendon.with_friction(friction).expect("friction")
            }
        })
        .collect();
    RobotModel::new(rod, tendons, Vec::new(), loads).expect("model")
}

/// The tensions (N) of the inverse-statics reference pose of the NiTi robot: both segments
/// bent, one tendon slack in each.
pub const NITI_REFERENCE_TENSIONS: [f64; 6] = [3.0, 0.0, 1.0, 0.0, 2.0, 0.5];

/// The tip position (m, world) of `model` at [`NITI_REFERENCE_TENSIONS`]: the target the
/// inverse-statics tests, bench and example start from.
pub fn niti_reference_tip(
    model: &Arc<RobotModel>,
    options: &SolveOptions,
) -> softrod::nalgebra::Vector3<f64> {
    let act = Actuation::tensions(&NITI_REFERENCE_TENSIONS);
    softrod::nalgebra::Vector3::from(
        solve_statics(model, &act, options)
            .expect("reference solve")
            .tip_position(),
    )
}

/// A 1 m NiTi rod (radius 1 mm, 6450 kg/m³) with four tendons at 10 mm, 90° apart, ending at
/// the tip, horizontal base (gravity along -x), under its own weight.
pub fn four_tendon_gravity() -> Arc<RobotModel> {
    let rod = Rod::new(
        1.0,
        Section::circular(1e-3).expect("radius"),
        LinearElastic::new(54e9, 0.3).expect("material"),
    )
    .expect("rod")
    .with_density(6450.0)
    .expect("density");
    let tendons = (0..4)
        .map(|i| {
            let a = (90.0 * i as f64).to_radians();
            Tendon::constant([0.01 * a.cos(), 0.01 * a.sin()], None).expect("tendon")
        })
        .collect();
    let g = Loads {
        gravity: softrod::nalgebra::Vector3::new(-9.81, 0.0, 0.0),
        ..Default::default()
    };
    RobotModel::new(rod, tendons, Vec::new(), g).expect("model")
}

/// The beam of the contact and end-constraint tests: length 1 m (m), E = 2 GPa (Pa),
/// ν = 0.3.
pub const BEAM_LENGTH: f64 = 1.0;
pub const BEAM_E: f64 = 2e9;
pub const BEAM_NU: f64 = 0.3;

/// That beam with a solid circular section of `radius` (m).
pub fn beam(radius: f64) -> Rod {
    circular_rod(BEAM_LENGTH, radius, BEAM_E, BEAM_NU)
}

/// A linear elastic rod of `length` (m) with a solid circular section of `radius` (m),
/// Young's modulus `e` (Pa) and Poisson's ratio `nu`.
pub fn circular_rod(length: f64, radius: f64, e: f64, nu: f64) -> Rod {
    Rod::new(
        length,
        Section::circular(radius).expect("radius"),
        LinearElastic::new(e, nu).expect("material"),
    )
    .expect("rod")
}

/// Default solver options with RK4 on `steps` fixed steps.
pub fn rk4_options(steps: usize) -> SolveOptions {
    SolveOptions {
        integrator: Integrator::Rk4 { steps },
        ..SolveOptions::default()
    }
}

/// The two-segment NiTi robot with its tendons through `per_segment` equally spaced disks per
/// 0.2 m (coefficient `mu` at each), as the Python tests build it.
pub fn guided_niti(mu: f64, per_segment: usize) -> Arc<RobotModel> {
    let tendons = niti_tendons(&[0.0; 6])
        .into_iter()
        .enumerate()
        .map(|(i, t)| {
            let end = if i < 3 { 0.2 } else { 0.4 };
            let n = (per_segment as f64 * end / 0.2).round() as usize;
            let guides = (1..n).map(|g| end * g as f64 / n as f64).collect();
            t.tendon.with_guides(guides, &[mu]).unwrap()
        })
        .collect();
    RobotModel::new(niti_rod(), tendons, Vec::new(), Loads::default()).unwrap()
}

/// A small deterministic generator (xorshift64*), so random samples are reproducible.
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Tensions of the NiTi robot with each segment pulled by two of its three tendons (N,
    /// each up to 3): admissible for a minimum-norm inverse (no antagonist pair).
    pub fn admissible(&mut self) -> [f64; 6] {
        let mut t = [0.0; 6];
        for seg in 0..2 {
            let o = ((self.uniform() * 3.0) as usize).min(2);
            t[3 * seg + o] = 3.0 * self.uniform();
            t[3 * seg + (o + 1) % 3] = 3.0 * self.uniform();
        }
        t
    }
}

/// Length (m) of the soft arm of [`soft_arm`].
pub const SOFT_ARM_LENGTH: f64 = 0.3;
/// Radius (m) of the soft arm of [`soft_arm`].
pub const SOFT_ARM_RADIUS: f64 = 0.005;
/// Radius (m) of the cylinder of [`soft_arm_cylinder`].
pub const CYLINDER_RADIUS: f64 = 0.03;

/// The soft arm of docs/contact.md ("An arm bent onto a cylinder"): a rod of 0.3 m, circular
/// radius 5 mm, E = 1 MPa, ν = 0.45, one tendon at the constant offset (4 mm, 0) bending it
/// toward +x.
pub fn soft_arm() -> Arc<RobotModel> {
    let rod = Rod::new(
        SOFT_ARM_LENGTH,
        Section::circular(SOFT_ARM_RADIUS).unwrap(),
        LinearElastic::new(1e6, 0.45).unwrap(),
    )
    .unwrap();
    let tendon = Tendon::new(Routing::Constant([0.004, 0.0]), None).unwrap();
    RobotModel::new(rod, vec![tendon], vec![], Loads::default()).unwrap()
}

/// The cylinder across the soft arm's bending plane: radius 30 mm, axis along `y` (from
/// y = -0.1 to 0.1 m) through x = 37 mm, z = 0.14 m (2 mm clear of the straight rod).
pub fn soft_arm_cylinder() -> Obstacle {
    let xc = CYLINDER_RADIUS + SOFT_ARM_RADIUS + 0.002;
    Obstacle::cylinder([xc, -0.1, 0.14], [xc, 0.1, 0.14], CYLINDER_RADIUS).unwrap()
}
