//! PCC statics vs. the Cosserat engine on the two-segment NiTi robot, as the tip force grows:
//! the table of `docs/pcc.md`.
//!
//! Robot: 2 × 0.2 m NiTi rod (E = 54 GPa, ν = 0.3, radius 0.7 mm), tendons 10 mm from the
//! backbone at 90°, -30°, 210° in each segment, segment-1 tendons ending at 0.2 m, tensions
//! [4, 0, 0, 0, 2, 0] N; a world-frame tip force along -y. Both models extensible; Cosserat by
//! RK4 with 400 steps. Both solvers follow the load path (warm starts).
//!
//! Run: `cargo run --release -p softrod --example pcc_vs_cosserat`.

#[path = "../tests/common/robot.rs"]
mod common;

use softrod::nalgebra::Vector3;
use softrod::pcc::statics::{solve_pcc_statics, PccLoads, PccRobot, PccSolveOptions};
use softrod::pcc::{ElasticSegment, PccTendons};
use softrod::{Integrator, LinearElastic, Loads, Rod, Section, SolveOptions};

fn main() -> softrod::Result<()> {
    let (e, nu, r, seg, d) = (54e9, 0.3, 0.0007, 0.2, 0.01);
    let angles: Vec<f64> = [90.0f64, -30.0, 210.0]
        .iter()
        .map(|a| a.to_radians())
        .collect();
    let tensions = [4.0, 0.0, 0.0, 0.0, 2.0, 0.0];

    let body = ElasticSegment::solid_circle(seg, r, e, true)?;
    let layout = PccTendons::new(&[d; 3], &angles)?;
    let robot = PccRobot::new(vec![body, body])?
        .with_segment_tendons(0, &layout)?
        .with_segment_tendons(1, &layout)?;

    let rod = Rod::new(2.0 * seg, Section::circular(r)?, LinearElastic::new(e, nu)?)?;
    let tendons = (0..6)
        .map(|i| {
            let b: f64 = angles[i % 3];
            let end = (i < 3).then_some(seg);
            common::tendon([d * b.cos(), d * b.sin()], tensions[i], end)
        })
        .collect::<softrod::Result<Vec<_>>>()?;
    let cosserat_options = SolveOptions {
        integrator: Integrator::Rk4 { steps: 400 },
        newton: softrod::NewtonOptions {
            tolerance: 1e-12,
            ..SolveOptions::default().newton
        },
        ..Default::default()
    };

    println!("| tip force F_y (N) | PCC tip (mm) | Cosserat tip (mm) | distance (mm) | distance / tip motion |");
    println!("| ---: | --- | --- | ---: | ---: |");
    let (mut warm_pcc, mut warm_cosserat) = (None, None);
    let mut p0 = Vector3::zeros();
    for f in [0.0, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0] {
        let force = Vector3::new(0.0, -f, 0.0);
        let loads = PccLoads {
            tensions: tensions.to_vec(),
            tip_force: force,
            ..Default::default()
        };
        let pcc = solve_pcc_statics(
            &robot,
            &loads,
            &PccSolveOptions {
                warm_start: warm_pcc.take(),
                ..Default::default()
            },
        )?;
        warm_pcc = Some(pcc.warm_start());
        let cos = common::solve(
            &rod,
            &tendons,
            &Loads::tip_force(force),
            &SolveOptions {
                warm_start: warm_cosserat,
                ..cosserat_options
            },
        )?;
        warm_cosserat = Some(cos.warm_start());
        let t = pcc.tip_pose;
        let p = Vector3::new(t[(0, 3)], t[(1, 3)], t[(2, 3)]);
        let c = Vector3::from(cos.tip_position());
        if f == 0.0 {
            p0 = c;
        }
        let dist = (p - c).norm();
        let motion = (c - p0).norm();
        let ratio = if motion > 0.0 {
            format!("{:.3}", dist / motion)
        } else {
            "—".to_string()
        };
        println!(
            "| {f} | ({:.2}, {:.2}, {:.2}) | ({:.2}, {:.2}, {:.2}) | {:.3} | {ratio} |",
            p.x * 1e3,
            p.y * 1e3,
            p.z * 1e3,
            c.x * 1e3,
            c.y * 1e3,
            c.z * 1e3,
            dist * 1e3,
        );
    }
    Ok(())
}
