//! Robustness of loaded solves: random two-segment NiTi configurations (tensions U[0, 4] N,
//! tip force up to 0.3 N in a random direction, RK4 with 50 steps). Prints the converged rate
//! and the number of converged equilibria whose tangent compliance (tendons at fixed tension)
//! is not positive definite, and writes one CSV line per configuration (converged, tip,
//! iterations, load steps, load factor, smallest eigenvalue, inputs) for comparisons.
//!
//! Run: `cargo run --release -p softrod --example robustness_loaded -- 2000 out.csv`.
#![allow(missing_docs, clippy::unwrap_used)]

use std::io::Write;

use softrod::compliance::{tangent_compliance, TendonControl};
use softrod::nalgebra::Vector3;
use softrod::{
    solve_statics, Actuation, Integrator, LinearElastic, Loads, NewtonOptions, RobotModel, Rod,
    Section, SolveOptions, Tendon,
};

/// xorshift64 in [0, 1): the same sequence as the baseline harness.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map(|a| a.parse().unwrap())
        .unwrap_or(2000);
    let out = std::env::args().nth(2).unwrap_or("robustness.csv".into());
    let rod = Rod::new(
        0.4,
        Section::circular(0.7e-3).unwrap(),
        LinearElastic::new(54e9, 0.3).unwrap(),
    )
    .unwrap();
    let tendons: Vec<Tendon> = (0..6)
        .map(|k| {
            let a = [90.0f64, -30.0, 210.0][k % 3].to_radians();
            let end = Some(if k < 3 { 0.2 } else { 0.4 });
            Tendon::constant([0.01 * a.cos(), 0.01 * a.sin()], end).unwrap()
        })
        .collect();
    let d = SolveOptions::default();
    let opts = SolveOptions {
        integrator: Integrator::Rk4 { steps: 50 },
        newton: NewtonOptions {
            throw: false,
            ..d.newton
        },
        ..d
    };
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut f = std::fs::File::create(&out).unwrap();
    let (mut conv, mut unstable) = (0, 0);
    let t0 = std::time::Instant::now();
    for i in 0..n {
        let t: Vec<f64> = (0..6).map(|_| 4.0 * rng.next()).collect();
        let mag = 0.3 * rng.next();
        let z = 2.0 * rng.next() - 1.0;
        let ph = 2.0 * std::f64::consts::PI * rng.next();
        let r = (1.0 - z * z).sqrt();
        let force = Vector3::new(mag * r * ph.cos(), mag * r * ph.sin(), mag * z);
        let model = RobotModel::new(
            rod.clone(),
            tendons.clone(),
            vec![],
            Loads::tip_force(force),
        )
        .unwrap();
        let s = solve_statics(&model, &Actuation::tensions(&t), &opts);
        let (ok, tip, it, ls, lam, eig) = match &s {
            Ok(s) => {
                let eig = if s.stats.converged {
                    tangent_compliance(s, TendonControl::Tension, None)
                        .map(|c| {
                            ((c.world + c.world.transpose()) * 0.5)
                                .symmetric_eigenvalues()
                                .min()
                        })
                        .unwrap_or(f64::NAN)
                } else {
                    f64::NAN
                };
                let st = &s.stats;
                (
                    st.converged,
                    s.tip_position(),
                    st.iterations,
                    st.load_steps,
                    st.load_factor,
                    eig,
                )
            }
            Err(_) => (false, [f64::NAN; 3], 0, 0, 0.0, f64::NAN),
        };
        if ok {
            conv += 1;
            if eig <= 0.0 {
                unstable += 1;
            }
        }
        writeln!(
            f,
            "{i},{},{:.17e},{:.17e},{:.17e},{it},{ls},{lam},{eig:.6e},{},{},{},{},{},{},{:.17e},{:.17e},{:.17e}",
            ok as u8, tip[0], tip[1], tip[2], t[0], t[1], t[2], t[3], t[4], t[5], force.x, force.y,
            force.z
        )
        .unwrap();
    }
    println!(
        "{n} configurations: converged {conv} ({:.2} %), unstable among converged {unstable}, {:.1} s",
        100.0 * conv as f64 / n as f64,
        t0.elapsed().as_secs_f64()
    );
}
