//! The stability verdict against an independent formulation: a clamped column with a dead
//! compressive point load at mid-length and a free tip. Oracle: the number of negative
//! eigenvalues of its second variation `∫ EI w''² - N(s) w'² ds` (`N = P` below the load, 0
//! above) by Hermite-cubic beam elements (200 elements, `w(0) = w'(0) = 0`, free tip), per
//! bending plane. The tip criterion alone misses the instability where the rod with its tip
//! clamped too has a conjugate point and the tip compliance is positive (31-35 and 49-59
//! times the Euler load `π² EI/(4L²)`: reported stable before); the conjugate points counted
//! along the march of the columns catch it.
#![allow(clippy::unwrap_used, missing_docs)]

use std::f64::consts::PI;
use std::sync::Arc;

use softrod::nalgebra::{DMatrix, Vector3};
use softrod::{
    solve_statics, Actuation, Integrator, LinearElastic, Loads, PointLoad, RobotModel, Rod,
    Section, SolveOptions,
};

const E: f64 = 2e9;
const RADIUS: f64 = 1e-3;
const LENGTH: f64 = 1.0;

fn ei() -> f64 {
    E * PI * RADIUS.powi(4) / 4.0
}

/// Negative eigenvalues per bending plane of the column's second variation, compression `p`
/// (N) on `[0, a]`, by `n` Hermite-cubic beam elements.
fn fem_negatives(p: f64, a: f64, n: usize) -> usize {
    let h = LENGTH / n as f64;
    let dof = 2 * n + 2;
    let mut k = DMatrix::<f64>::zeros(dof, dof);
    let c = ei() / h.powi(3);
    let ke = [
        [12.0, 6.0 * h, -12.0, 6.0 * h],
        [6.0 * h, 4.0 * h * h, -6.0 * h, 2.0 * h * h],
        [-12.0, -6.0 * h, 12.0, -6.0 * h],
        [6.0 * h, 2.0 * h * h, -6.0 * h, 4.0 * h * h],
    ];
    let kg = [
        [36.0, 3.0 * h, -36.0, 3.0 * h],
        [3.0 * h, 4.0 * h * h, -3.0 * h, -h * h],
        [-36.0, -3.0 * h, 36.0, -3.0 * h],
        [3.0 * h, -h * h, -3.0 * h, 4.0 * h * h],
    ];
    for e in 0..n {
        let mid = (e as f64 + 0.5) * h;
        let axial = if mid < a { p } else { 0.0 };
        for i in 0..4 {
            for j in 0..4 {
                k[(2 * e + i, 2 * e + j)] += c * ke[i][j] - axial / (30.0 * h) * kg[i][j];
            }
        }
    }
    let clamped = k.view((2, 2), (dof - 2, dof - 2)).into_owned();
    clamped
        .symmetric_eigen()
        .eigenvalues
        .iter()
        .filter(|v| **v < 0.0)
        .count()
}

#[test]
fn a_column_loaded_at_mid_length_is_stable_exactly_where_its_energy_is_convex() {
    let p_cr = PI * PI * ei() / (4.0 * LENGTH * LENGTH);
    let a = 0.5 * LENGTH;
    let rod = Rod::new(
        LENGTH,
        Section::circular(RADIUS).unwrap(),
        LinearElastic::new(E, 0.3).unwrap(),
    )
    .unwrap();
    let opts = SolveOptions {
        integrator: Integrator::Rk4 { steps: 200 },
        seek_stable: false,
        ..SolveOptions::default()
    };
    // Below the first load (4 P_cr: the lower half's own Euler load), between the first two,
    // where the tip criterion missed it (33, 52), and above the second (36 P_cr).
    for f in [3.0, 3.9, 4.1, 20.0, 33.0, 40.0, 52.0] {
        let p = f * p_cr;
        let loads = Loads {
            point_loads: vec![PointLoad::force(a, Vector3::new(0.0, 0.0, -p))],
            ..Loads::default()
        };
        let model = Arc::new(RobotModel::rod_only(rod.clone(), loads).unwrap());
        let sol = solve_statics(&model, &Actuation::default(), &opts).unwrap();
        let negative = fem_negatives(p, a, 200);
        assert_eq!(
            sol.stable,
            negative == 0,
            "{f} P_cr: stable {} (margin {}), {negative} negative modes per plane",
            sol.stable,
            sol.stability_margin()
        );
    }
}
