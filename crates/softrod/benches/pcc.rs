//! PCC solves: actuation → arc parameters → tip pose, for one segment and a two-segment
//! chain (the issue asks for <= 5 µs per configuration), and the closed-form Jacobians.
//!
//! Run: `cargo bench -p softrod --bench pcc`.
#![allow(missing_docs, clippy::unwrap_used)]

use criterion::{criterion_group, criterion_main, Criterion};
use softrod::nalgebra::Vector3;
use softrod::pcc::{
    arc_from_pressures, arc_from_tendon_displacements, arc_from_tendon_tensions, arc_from_tip,
    chain_jacobian, chain_pose, ArcCoordinates, ElasticSegment, JacobianFrame, PccChambers,
    PccSegment, PccTendons,
};
use std::hint::black_box;

fn pcc(c: &mut Criterion) {
    let body = ElasticSegment::solid_circle(0.15, 0.01, 1e6, true).unwrap();
    let tendons = PccTendons::equally_spaced(3, 0.007, 0.0).unwrap();
    let chambers = PccChambers::equally_spaced(3, 5e-5, 0.005, 0.0).unwrap();
    let tensions = [0.8, 0.1, 0.3];
    let mut g = c.benchmark_group("pcc_solve");
    g.bench_function("tensions_to_pose_1_segment", |b| {
        b.iter(|| {
            let s = arc_from_tendon_tensions(black_box(&tensions), &tendons, &body).unwrap();
            s.pose()
        })
    });
    g.bench_function("pressures_to_pose_1_segment", |b| {
        b.iter(|| {
            let s = arc_from_pressures(black_box(&[2e4, 0.0, 5e3]), &chambers, &body).unwrap();
            s.pose()
        })
    });
    g.bench_function("displacements_to_pose_1_segment", |b| {
        b.iter(|| {
            let s = arc_from_tendon_displacements(
                black_box(&[-0.004, 0.002, 0.001]),
                &tendons,
                0.15,
                true,
            )
            .unwrap();
            s.pose()
        })
    });
    g.bench_function("tensions_to_pose_2_segment_chain", |b| {
        b.iter(|| {
            let s1 = arc_from_tendon_tensions(black_box(&tensions), &tendons, &body).unwrap();
            let s2 =
                arc_from_tendon_tensions(black_box(&[0.0, 0.6, 0.2]), &tendons, &body).unwrap();
            chain_pose(&[s1, s2])
        })
    });
    g.finish();

    let s = PccSegment::new(12.0, 0.7, 0.15).unwrap();
    let chain = [s, PccSegment::new(-4.0, 2.0, 0.1).unwrap()];
    let mut g = c.benchmark_group("pcc_kinematics");
    g.bench_function("arc_pose", |b| b.iter(|| black_box(&s).pose()));
    g.bench_function("arc_jacobian_spatial_arc", |b| {
        b.iter(|| black_box(&s).jacobian(JacobianFrame::Spatial, ArcCoordinates::Arc))
    });
    g.bench_function("chain_jacobian_2_segments_body", |b| {
        b.iter(|| {
            chain_jacobian(
                black_box(&chain),
                JacobianFrame::Body,
                ArcCoordinates::CurvatureVector,
            )
        })
    });
    let tip = s.tip_position();
    g.bench_function("arc_from_tip", |b| {
        b.iter(|| arc_from_tip(black_box(&Vector3::new(tip.x, tip.y, tip.z))).unwrap())
    });
    g.finish();
}

/// PCC statics (issue 6): the two-segment NiTi robot of the docs, by Newton on the
/// equilibrium equations (`softrod::pcc::statics`).
fn pcc_statics(c: &mut Criterion) {
    use softrod::pcc::statics::{solve_pcc_statics, PccLoads, PccRobot, PccSolveOptions};
    let body = ElasticSegment::solid_circle(0.2, 0.0007, 54e9, true).unwrap();
    let angles: Vec<f64> = [90.0f64, -30.0, 210.0]
        .iter()
        .map(|a| a.to_radians())
        .collect();
    let tendons = PccTendons::new(&[0.01; 3], &angles).unwrap();
    let robot = PccRobot::new(vec![body, body])
        .unwrap()
        .with_segment_tendons(0, &tendons)
        .unwrap()
        .with_segment_tendons(1, &tendons)
        .unwrap();
    let tensions = vec![4.0, 0.0, 0.0, 0.0, 2.0, 0.0];
    let opts = PccSolveOptions::default();
    let mut g = c.benchmark_group("pcc_statics");
    for (name, force, moment) in [
        ("niti_2_segment_tendons_only", [0.0; 3], [0.0; 3]),
        (
            "niti_2_segment_tip_force_0.02N",
            [0.0, -0.02, 0.0],
            [0.0; 3],
        ),
        ("niti_2_segment_tip_force_0.1N", [0.0, -0.1, 0.0], [0.0; 3]),
        (
            "niti_2_segment_tip_wrench",
            [0.01, -0.02, 0.005],
            [1e-3, 0.0, -5e-4],
        ),
    ] {
        let loads = PccLoads {
            tensions: tensions.clone(),
            tip_force: Vector3::from(force),
            tip_moment: Vector3::from(moment),
            ..Default::default()
        };
        let sol = solve_pcc_statics(&robot, &loads, &opts).unwrap();
        println!(
            "{name}: {} Newton iterations, {} load steps",
            sol.stats.iterations, sol.stats.load_steps
        );
        g.bench_function(name, |b| {
            b.iter(|| solve_pcc_statics(&robot, black_box(&loads), &opts).unwrap())
        });
    }
    g.finish();
}

/// PCC inverse statics (issue 11) of the same robot: the minimum-norm tensions that put the
/// tip at a target, cold (from zero) and warm (the previous answer, target moved by 1 mm).
fn pcc_inverse(c: &mut Criterion) {
    use softrod::pcc::statics::{solve_pcc_statics, PccLoads, PccRobot, PccSolveOptions};
    use softrod::{pcc_inverse_statics, InverseOptions, InverseWarmStart, Target};
    let body = ElasticSegment::solid_circle(0.2, 0.0007, 54e9, true).unwrap();
    let angles = [90.0f64, -30.0, 210.0].map(f64::to_radians);
    let tendons = PccTendons::new(&[0.01; 3], &angles).unwrap();
    let robot = PccRobot::new(vec![body, body])
        .unwrap()
        .with_segment_tendons(0, &tendons)
        .unwrap()
        .with_segment_tendons(1, &tendons)
        .unwrap();
    let o = PccSolveOptions::default();
    let loads = PccLoads {
        tensions: vec![0.0, 1.7, 0.9, 2.2, 0.0, 0.4],
        ..Default::default()
    };
    let tip = solve_pcc_statics(&robot, &loads, &o).unwrap().tip_pose;
    let p = Vector3::new(tip[(0, 3)], tip[(1, 3)], tip[(2, 3)]);
    let (target, moved) = (
        Target::tip(p),
        Target::tip(p + Vector3::new(1e-3, 0.0, 0.0)),
    );
    let io = InverseOptions::default();
    let none = PccLoads::default();
    let cold = pcc_inverse_statics(&robot, &none, &target, &io, &o, None).unwrap();
    let warm = InverseWarmStart::from(&cold);
    let mut g = c.benchmark_group("pcc_inverse");
    g.bench_function("niti_2_segment_cold", |b| {
        b.iter(|| pcc_inverse_statics(&robot, &none, black_box(&target), &io, &o, None).unwrap())
    });
    g.bench_function("niti_2_segment_warm_1mm", |b| {
        b.iter(|| {
            pcc_inverse_statics(&robot, &none, black_box(&moved), &io, &o, Some(&warm)).unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, pcc, pcc_statics, pcc_inverse);
criterion_main!(benches);
