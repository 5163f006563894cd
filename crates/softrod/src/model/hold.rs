//! Intervals of the backbone held on a rigid surface: the contact intervals on curved
//! obstacles of the contact solve.
//!
//! On a held interval `[a, b]` the rod's surface lies on a rigid surface: its gap
//! `g(s) = d(p(s)) - R(s)` (`d` the surface's signed distance, `R` the rod's outer radius)
//! stays zero, under a normal pressure `q(s) n(p(s))` (N/m, `n` the outward normal, the
//! gradient of `d`) that the equations compute from the state at every `s` so that
//! `g'' = 0` (see `cosserat/equations/hold.rs`). Only the contact solve builds models with
//! held intervals ([`RobotModel::with_loads_and_holds`](super::RobotModel)).

use std::fmt::Debug;
use std::sync::Arc;

use nalgebra::Vector3;

/// A rigid surface the backbone can be held on, through the signed distance to it.
pub(crate) trait Surface: Debug + Send + Sync {
    /// Signed distance (m; negative inside) of `x` (m, world) to the surface, and the unit
    /// outward normal at the closest point (the gradient of the distance).
    fn distance(&self, x: &Vector3<f64>) -> (f64, Vector3<f64>);
    /// `tᵀ H t` with `H` the Hessian of the signed distance at `x` (1/m times the unit of
    /// `t` squared); `None` where the distance is not twice differentiable (an edge).
    fn curvature(&self, x: &Vector3<f64>, t: &Vector3<f64>) -> Option<f64>;
}

/// The interval `[a, b]` (m) of the backbone held on `surface`.
#[derive(Debug, Clone)]
pub(crate) struct Hold {
    pub surface: Arc<dyn Surface>,
    pub a: f64,
    pub b: f64,
}
