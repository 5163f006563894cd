//! Exact sensitivities (linearised boundary-value problem) against central finite differences
//! of the nonlinear solve, parameter by parameter, on tendon robots (unloaded, tip-loaded,
//! under gravity) and on a hyperelastic tube with chambers and a tendon.

#![allow(clippy::unwrap_used, clippy::too_many_lines)]

/// RK4 steps of the solves (the pneumatic arm file uses 100, the NiTi file 50).
const STEPS: usize = 100;

use std::f64::consts::PI;
use std::sync::Arc;

use softrod::nalgebra::{Matrix3, Vector3};
use softrod::{
    actuation_jacobian, sensitivities, solve_statics, Actuation, Chamber, ChamberArea,
    LinearElastic, Linearisation, Loads, Parameter, Pose, RobotModel, Rod, Routing, Section,
    Silicone, SolveOptions, StaticsSolution, Tendon, UniaxialModel,
};

/// A robot as the finite differences rebuild it: every parameter explicit.
#[derive(Clone)]
struct Build {
    length: f64,
    radius: f64,
    youngs: f64,
    hyperelastic: bool,
    /// (offset, end) per tendon.
    tendons: Vec<([f64; 2], f64)>,
    tensions: Vec<f64>,
    /// (area, offset) per chamber.
    chambers: Vec<(f64, [f64; 2])>,
    pressures: Vec<f64>,
    loads: Loads,
    density: Option<f64>,
    base: (Vector3<f64>, Matrix3<f64>),
}

fn axis_rotation(k: usize, angle: f64) -> Matrix3<f64> {
    softrod::nalgebra::Rotation3::from_axis_angle(&Vector3::ith_axis(k), angle).into_inner()
}

impl Build {
    fn model(&self) -> Arc<RobotModel> {
        let section = if self.hyperelastic {
            Section::tube(self.radius, 0.2 * self.radius).unwrap()
        } else {
            Section::circular(self.radius).unwrap()
        };
        let mut rod = if self.hyperelastic {
            Rod::new(
                self.length,
                section,
                UniaxialModel::from(Silicone::DragonSkin10.yeoh()),
            )
            .unwrap()
        } else {
            Rod::new(
                self.length,
                section,
                LinearElastic::new(self.youngs, 0.3).unwrap(),
            )
            .unwrap()
        };
        if let Some(d) = self.density {
            rod = rod.with_density(d).unwrap();
        }
        rod = rod.with_base_pose(Pose::new(self.base.0, self.base.1).unwrap());
        let tendons = self
            .tendons
            .iter()
            .map(|(o, e)| Tendon::new(Routing::Constant(*o), Some(*e)).unwrap())
            .collect();
        let chambers = self
            .chambers
            .iter()
            .map(|(a, o)| Chamber::new(ChamberArea::Constant(*a), *o, 0.0, None).unwrap())
            .collect();
        RobotModel::new(rod, tendons, chambers, self.loads.clone()).unwrap()
    }

    fn solve(&self) -> StaticsSolution {
        let act = Actuation::tensions(&self.tensions).with_pressures(&self.pressures);
        let mut o = SolveOptions::default();
        o.newton.tolerance = 1e-14;
        o.newton.max_iterations = 60;
        o.integrator = softrod::Integrator::Rk4 { steps: STEPS };
        solve_statics(&self.model(), &act, &o).unwrap()
    }

    /// The robot with `p` changed by `h` (its unit: N, Pa, m, rad or a relative factor).
    fn perturbed(&self, p: &Parameter, h: f64) -> Build {
        let mut b = self.clone();
        match *p {
            Parameter::Tension(i) => b.tensions[i] += h,
            Parameter::Pressure(j) => b.pressures[j] += h,
            Parameter::TensionScale => b.tensions.iter_mut().for_each(|t| *t *= 1.0 + h),
            Parameter::StiffnessScale => b.youngs *= 1.0 + h,
            Parameter::TendonOffsetScale(i) => {
                let o = &mut b.tendons[i].0;
                o[0] *= 1.0 + h;
                o[1] *= 1.0 + h;
            }
            Parameter::TendonOffsetShift { tendon, direction } => {
                let o = &mut b.tendons[tendon].0;
                o[0] += h * direction[0];
                o[1] += h * direction[1];
            }
            Parameter::ChamberAreaScale(j) => b.chambers[j].0 *= 1.0 + h,
            Parameter::BaseTranslation(k) => b.base.0[k] += h,
            Parameter::BaseRotation(k) => b.base.1 = axis_rotation(k, h) * b.base.1,
            Parameter::Displacement(_) => unreachable!(),
        }
        b
    }
}

/// Pose difference `[p1 - p0; log(R1 R0ᵀ)]` at node `k` (world).
fn pose_diff(a: &StaticsSolution, b: &StaticsSolution, k: usize) -> [f64; 6] {
    let p = |s: &StaticsSolution| Vector3::from(s.position[k]);
    let r = |s: &StaticsSolution| {
        let m = s.rotation[k];
        Matrix3::new(
            m[0][0], m[0][1], m[0][2], m[1][0], m[1][1], m[1][2], m[2][0], m[2][1], m[2][2],
        )
    };
    let dp = p(b) - p(a);
    let dr = r(b) * r(a).transpose();
    let w = softrod::math::so3::log_so3(&dr);
    [dp.x, dp.y, dp.z, w.x, w.y, w.z]
}

/// Checks every parameter's column at the tip and at a middle node (pose, base wrench,
/// tendon lengths) against central differences with relative steps `h`.
fn check(build: &Build, params: &[Parameter], what: &str) {
    let sol = build.solve();
    let n = sol.s.len();
    let nodes = [n / 2, n - 1];
    let sens = sensitivities(&sol, params, &nodes, Linearisation::Actuated).unwrap();
    for (j, p) in params.iter().enumerate() {
        let h = match p {
            Parameter::Tension(_) => 1e-4,
            Parameter::Pressure(_) => 1e-1,
            Parameter::BaseTranslation(_) => 1e-5,
            Parameter::TendonOffsetShift { .. } => 1e-6,
            _ => 1e-5,
        };
        let up = build.perturbed(p, h).solve();
        let down = build.perturbed(p, -h).solve();
        for (o, &k) in sens.nodes.iter().enumerate() {
            let a = pose_diff(&down, &up, k);
            let exact = sens.pose[o].column(j);
            let scale = exact.amax().max(1e-300);
            for r in 0..6 {
                let fd = a[r] / (2.0 * h);
                let err = (fd - exact[r]).abs() / scale;
                assert!(
                    err < 1e-6,
                    "{what}: {p:?} node {k} component {r}: exact {:e} vs fd {fd:e} (rel {err:e})",
                    exact[r]
                );
            }
        }
        let scale = sens.base_wrench.column(j).amax();
        if scale > 0.0 {
            for r in 0..6 {
                let fd = (up.base_wrench[r] - down.base_wrench[r]) / (2.0 * h);
                let err = (fd - sens.base_wrench[(r, j)]).abs() / scale;
                assert!(err < 1e-6, "{what}: {p:?} base wrench {r}: rel {err:e}");
            }
        }
        let nt = build.tendons.len();
        let lscale = sens.tendon_lengths.column(j).amax().max(1e-9);
        for i in 0..nt {
            let fd = (up.tendon_lengths[i] - down.tendon_lengths[i]) / (2.0 * h);
            let err = (fd - sens.tendon_lengths[(i, j)]).abs() / lscale;
            assert!(
                err < 1e-6,
                "{what}: {p:?} length of tendon {i}: rel {err:e}"
            );
        }
        println!("{what}: {p:?} ok");
    }
}

fn niti(tensions: [f64; 6], loads: Loads, density: Option<f64>) -> Build {
    Build {
        length: 0.4,
        radius: 0.7e-3,
        youngs: 54e9,
        hyperelastic: false,
        tendons: (0..6)
            .map(|i| {
                let a = [90.0f64, -30.0, 210.0][i % 3].to_radians();
                (
                    [0.01 * a.cos(), 0.01 * a.sin()],
                    if i < 3 { 0.2 } else { 0.4 },
                )
            })
            .collect(),
        tensions: tensions.to_vec(),
        chambers: Vec::new(),
        pressures: Vec::new(),
        loads,
        density,
        base: (Vector3::zeros(), Matrix3::identity()),
    }
}

fn tendon_parameters() -> Vec<Parameter> {
    let mut p: Vec<Parameter> = (0..6).map(Parameter::Tension).collect();
    p.extend([
        Parameter::TensionScale,
        Parameter::StiffnessScale,
        Parameter::TendonOffsetScale(0),
        Parameter::TendonOffsetScale(4),
        Parameter::TendonOffsetShift {
            tendon: 4,
            direction: [0.6, 0.8],
        },
        Parameter::BaseTranslation(1),
        Parameter::BaseRotation(0),
        Parameter::BaseRotation(2),
    ]);
    p
}

#[test]
fn niti_unloaded_sensitivities_match_central_differences() {
    check(
        &niti([4.0, 0.3, 0.5, 0.2, 2.0, 0.1], Loads::default(), None),
        &tendon_parameters(),
        "niti unloaded",
    );
}

#[test]
fn niti_tip_loaded_sensitivities_match_central_differences() {
    check(
        &niti(
            [4.0, 0.3, 0.5, 0.2, 2.0, 0.1],
            Loads::tip_force(Vector3::new(0.3, -0.2, 0.1)),
            None,
        ),
        &tendon_parameters(),
        "niti tip load",
    );
}

#[test]
fn niti_under_gravity_sensitivities_match_central_differences() {
    let loads = Loads {
        gravity: Vector3::new(0.0, -9.81, 0.0),
        ..Default::default()
    };
    check(
        &niti([4.0, 0.3, 0.5, 0.2, 2.0, 0.1], loads, Some(6450.0)),
        &tendon_parameters(),
        "niti gravity",
    );
}

#[test]
fn hyperelastic_tube_with_chambers_matches_central_differences() {
    let b = tube();
    check(
        &b,
        &[
            Parameter::Tension(0),
            Parameter::Pressure(0),
            Parameter::Pressure(1),
            Parameter::ChamberAreaScale(1),
            Parameter::TendonOffsetScale(0),
            Parameter::BaseRotation(1),
        ],
        "hyperelastic tube",
    );
}

#[test]
fn actuation_jacobian_is_the_tension_then_pressure_columns() {
    let b = niti([1.0, 0.0, 0.0, 0.0, 0.5, 0.0], Loads::default(), None);
    let sol = b.solve();
    let j = actuation_jacobian(&sol, None).unwrap();
    let params: Vec<Parameter> = (0..6).map(Parameter::Tension).collect();
    let s = sensitivities(&sol, &params, &[sol.s.len() - 1], Linearisation::Tension).unwrap();
    assert_eq!(j.shape(), (6, 6));
    assert!((&j - &s.pose[0]).amax() <= 1e-15 * j.amax());
}

fn tube() -> Build {
    let ac = PI * 0.0025f64.powi(2);
    Build {
        length: 0.16,
        radius: 0.012,
        youngs: 0.0,
        hyperelastic: true,
        tendons: vec![([0.008, 0.0], 0.12)],
        tensions: vec![1.5],
        chambers: vec![
            (ac, [0.0, 0.0072]),
            (ac, [0.0072 * (-30f64).to_radians().cos(), -0.0036]),
        ],
        pressures: vec![30e3, 10e3],
        loads: Loads {
            tip_force: Vector3::new(0.05, -0.02, 0.1),
            gravity: Vector3::new(0.0, 0.0, -9.81),
            ..Default::default()
        },
        density: Some(1070.0),
        base: (Vector3::zeros(), Matrix3::identity()),
    }
}
