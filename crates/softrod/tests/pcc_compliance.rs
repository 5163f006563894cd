//! The integrated compliance along PCC configurations, through the same computation as the
//! Cosserat model: a PCC arc against Castigliano's closed-form arc compliance, and the PCC and
//! Cosserat paths on the same unloaded tendon-driven segment (both exact arcs).
#![allow(clippy::unwrap_used, missing_docs)]

mod common;

use std::f64::consts::PI;

use common::{assert_blocks_close, castigliano_arc};
use softrod::compliance::{compliance, pcc_compliance, PCC_PANEL_ANGLE};
use softrod::math::so3::exp_so3;
use softrod::nalgebra::Vector3;
use softrod::pcc::statics::{solve_pcc_statics, PccLoads, PccRobot, PccSolveOptions, RoutedTendon};
use softrod::pcc::ElasticSegment;
use softrod::{Integrator, LinearElastic, Loads, Pose, Rod, Section, SolveOptions};

const E: f64 = 2.0e9;
const NU: f64 = 0.3;
const RADIUS: f64 = 0.01;
const LENGTH: f64 = 0.5;
const OFFSET: f64 = 0.008;

fn rod() -> Rod {
    Rod::new(
        LENGTH,
        Section::circular(RADIUS).unwrap(),
        LinearElastic::new(E, NU).unwrap(),
    )
    .unwrap()
}

fn tendon_robot(extensible: bool, angle: f64) -> PccRobot {
    PccRobot::new(vec![ElasticSegment::solid_circle(
        LENGTH, RADIUS, E, extensible,
    )
    .unwrap()])
    .unwrap()
    .with_tendon(RoutedTendon::new(OFFSET, angle, 0).unwrap())
    .unwrap()
}

fn solve(robot: &PccRobot, tension: f64) -> softrod::pcc::statics::PccStaticsSolution {
    let loads = PccLoads {
        tensions: vec![tension],
        ..Default::default()
    };
    solve_pcc_statics(robot, &loads, &PccSolveOptions::default()).unwrap()
}

/// Tension bending the inextensible segment by `angle` (rad): `θ = τ d ℓ0 / (E I)`.
fn tension_for(angle: f64) -> f64 {
    let ei = E * PI * RADIUS.powi(4) / 4.0;
    angle * ei / (OFFSET * LENGTH)
}

#[test]
fn pcc_arc_matches_castigliano() {
    let rod = rod();
    let (ei, gj) = (
        E * PI * RADIUS.powi(4) / 4.0,
        E / (2.0 * (1.0 + NU)) * PI * RADIUS.powi(4) / 2.0,
    );
    let (ea, gas) = (
        E * PI * RADIUS * RADIUS,
        rod.shear_coefficient() * E / (2.0 * (1.0 + NU)) * PI * RADIUS * RADIUS,
    );
    // Tendon at angle 0 bends toward +x (curvature about body y), the oracle's plane.
    let robot = tendon_robot(false, 0.0);
    for angle in [PI / 2.0, PI, 1.5 * PI] {
        let sol = solve(&robot, tension_for(angle));
        let seg = &sol.segments[0];
        assert!((seg.bending_angle() - angle).abs() < 1e-10 && seg.plane_angle().abs() < 1e-12);
        let c = pcc_compliance(&rod, &robot, &sol, None).unwrap();
        let exact = castigliano_arc(seg.curvature(), LENGTH, [gas, gas, ea, ei, ei, gj]);
        assert_blocks_close(&c.tip_world(), &exact, 1e-8, &format!("PCC arc {angle}"));
        assert_eq!(c.s.len(), (angle / PCC_PANEL_ANGLE).ceil() as usize + 1);
    }
}

/// Unloaded tendon-driven segment: the PCC solution is the Cosserat solution exactly (both
/// arcs, extensible or not), the element compliance is the same linear one, so the two
/// integrated compliances differ only by the quadrature on the two meshes (fourth order: PCC
/// panels of 0.005 rad, about 4e-11 of each block's scale; 800 RK4 steps over 1.2π, 3e-11) and
/// the RK4 error of the Cosserat arc (below 1e-12 m at the tip). The entries are compared relative
/// to themselves (small off-diagonal ones amplify the error about 15x): 1e-8 is the margin.
#[test]
fn pcc_and_cosserat_compliance_agree_on_an_unloaded_tendon_segment() {
    let base = Pose::new(
        Vector3::new(0.1, -0.2, 0.3),
        exp_so3(&Vector3::new(0.3, -0.5, 0.2)),
    )
    .unwrap();
    for extensible in [false, true] {
        let rod = rod().with_inextensible(false).with_base_pose(base);
        for (angle, beta) in [(PI / 3.0, 0.7), (1.2 * PI, -2.0)] {
            let robot = tendon_robot(extensible, beta);
            let tension = tension_for(angle);
            let pcc = solve(&robot, tension);
            let cos_rod = rod.clone().with_inextensible(!extensible);
            let tendon =
                common::tendon([OFFSET * beta.cos(), OFFSET * beta.sin()], tension, None).unwrap();
            let options = SolveOptions {
                integrator: Integrator::Rk4 { steps: 800 },
                newton: softrod::NewtonOptions {
                    tolerance: 1e-13,
                    ..SolveOptions::default().newton
                },
                ..Default::default()
            };
            let sol = common::solve(&cos_rod, &[tendon], &Loads::default(), &options).unwrap();
            let c_cos = compliance(&sol).unwrap().tip_world();
            let c_pcc = pcc_compliance(&cos_rod, &robot, &pcc, None)
                .unwrap()
                .tip_world();
            assert_blocks_close(
                &c_pcc,
                &c_cos,
                1e-8,
                &format!("extensible {extensible}, angle {angle}, beta {beta}"),
            );
        }
    }
}

#[test]
fn pcc_compliance_rejects_a_rod_of_another_length() {
    let robot = tendon_robot(false, 0.0);
    let sol = solve(&robot, 1.0);
    let short = Rod::new(
        0.4,
        Section::circular(RADIUS).unwrap(),
        LinearElastic::new(E, NU).unwrap(),
    )
    .unwrap();
    assert!(matches!(
        pcc_compliance(&short, &robot, &sol, None),
        Err(softrod::Error::InvalidParameter { .. })
    ));
    assert!(matches!(
        pcc_compliance(&rod(), &robot, &sol, Some(0)),
        Err(softrod::Error::InvalidParameter { .. })
    ));
}
