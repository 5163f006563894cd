//! An arm wrapping a cylinder: a tendon-driven rod bent onto a cylinder across its path.
//!
//! Rod L = 0.3 m, circular r = 5 mm, E = 1 MPa, ν = 0.45; one tendon at the constant offset
//! (4 mm, 0) pulled with tension `T`; a cylinder of radius 30 mm with its axis along `y`
//! through x = 30 + 5 + 2 mm, z = 0.14 m (2 mm clear of the straight rod); RK4 with 80
//! steps. For each tension (the arguments, N; by default 1, 2, 3, 3.2, 3.3, 4, 5, 6, 8) it
//! solves from the straight rod and prints the contacts (`[a, b]` for a contact interval
//! on the cylinder, a point `s` otherwise, with its normal force), their total normal
//! force, the tip position, the iterations, the function evaluations and the wall time, or
//! the error.
//!
//! ```text
//! cargo run --release -p softrod --example wrap_cylinder [-- T1 T2 ...]
//! ```
#![allow(clippy::print_stdout)]

use std::time::Instant;

use softrod::{
    solve_constrained, Actuation, Integrator, LinearElastic, Loads, Obstacle, RobotModel, Rod,
    Routing, Section, SolveOptions, Tendon,
};

fn main() -> Result<(), softrod::Error> {
    let mut tensions: Vec<f64> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    if tensions.is_empty() {
        tensions = vec![1.0, 2.0, 3.0, 3.2, 3.3, 4.0, 5.0, 6.0, 8.0];
    }
    let (l, r, e) = (0.3, 0.005, 1e6);
    let rod = Rod::new(l, Section::circular(r)?, LinearElastic::new(e, 0.45)?)?;
    let tendon = Tendon::new(Routing::Constant([0.004, 0.0]), None)?;
    let model = RobotModel::new(rod, vec![tendon], vec![], Loads::default())?;
    let rc = 0.03;
    let xc = rc + r + 0.002;
    let cylinder = [Obstacle::cylinder([xc, -0.1, 0.14], [xc, 0.1, 0.14], rc)?];
    let opts = SolveOptions {
        integrator: Integrator::Rk4 { steps: 80 },
        ..SolveOptions::default()
    };
    println!(
        "{:>5} | {:<44} | {:>8} | {:<26} | {:>5} | {:>9} | {:>7}",
        "T (N)",
        "contacts: [a, b] or s (m), force (N)",
        "sum (N)",
        "tip (m)",
        "iter",
        "evals",
        "time"
    );
    for t in tensions {
        let start = Instant::now();
        let result = solve_constrained(&model, &Actuation::tensions(&[t]), &opts, None, &cylinder);
        let time = start.elapsed().as_secs_f64();
        match result {
            Ok(s) => {
                let contacts: Vec<String> = s
                    .contacts
                    .iter()
                    .map(|c| {
                        if c.length > 0.0 {
                            format!("[{:.4}, {:.4}] {:.4}", c.s, c.s + c.length, c.normal_force)
                        } else {
                            format!("{:.4} {:.4}", c.s, c.normal_force)
                        }
                    })
                    .collect();
                let total: f64 = s.contacts.iter().map(|c| c.normal_force).sum();
                let tip = s.solution.position.last().copied().unwrap_or([f64::NAN; 3]);
                println!(
                    "{t:>5.2} | {:<44} | {total:>8.4} | ({:>7.4}, {:>7.4}, {:>7.4}) | {:>5} | {:>9} | {time:>6.2}s",
                    contacts.join("; "),
                    tip[0],
                    tip[1],
                    tip[2],
                    s.solution.stats.iterations,
                    s.solution.stats.function_evaluations,
                );
            }
            Err(err) => println!("{t:>5.2} | failed after {time:.2} s: {err}"),
        }
    }
    Ok(())
}
