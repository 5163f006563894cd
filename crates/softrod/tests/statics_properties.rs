//! Property tests over pseudo-random rods, tendons and loads: whatever the shape, the total
//! base wrench balances the external loads (global equilibrium, computed from the returned
//! positions), and the rod's base wrench differs from it by exactly the tendons' pull.
#![allow(clippy::unwrap_used, missing_docs, clippy::too_many_lines)]

mod common;

use softrod::nalgebra::Vector3;
use softrod::{LinearElastic, Loads, PointLoad, Rod, Routing, Section, SolveOptions};

/// Small deterministic generator (64-bit LCG), uniform in [0, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
    fn vec(&mut self, scale: f64) -> Vector3<f64> {
        Vector3::new(
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
        ) * scale
    }
}

#[test]
fn random_problems_satisfy_global_equilibrium() {
    let mut g = Lcg(20261122);
    let mut solved = 0;
    for case in 0..40 {
        let l = g.range(0.1, 0.5);
        let r0 = g.range(0.002, 0.01);
        let section = if case % 2 == 0 {
            Section::circular(r0).unwrap()
        } else {
            Section::tapered_circular(r0, r0 * g.range(0.4, 1.0)).unwrap()
        };
        let e = 10f64.powf(g.range(5.0, 9.0));
        let rod = Rod::new(
            l,
            section,
            LinearElastic::new(e, g.range(0.2, 0.5)).unwrap(),
        )
        .unwrap()
        .with_inextensible(case % 5 == 0);
        let ei = e * std::f64::consts::PI * r0.powi(4) / 4.0;
        let f_ref = ei / (l * l);
        let mut tendons = Vec::new();
        for k in 0..(case % 4) {
            let routing = match k % 3 {
                0 => Routing::Constant([g.range(-0.5, 0.5) * r0, g.range(-0.5, 0.5) * r0]),
                1 => Routing::RadiusProportional {
                    ratio: g.range(0.1, 0.6),
                    angle: g.range(0.0, std::f64::consts::TAU),
                },
                _ => Routing::Helical {
                    radius: 0.5 * r0,
                    pitch: g.range(-2.0, 2.0) * l + 0.05,
                    phase: g.range(0.0, std::f64::consts::TAU),
                },
            };
            let end = if g.next() < 0.5 {
                None
            } else {
                Some(g.range(0.2, 1.0) * l)
            };
            tendons.push(
                common::tendon_with(routing, g.range(0.0, 2.0) * ei / (l * r0), end).unwrap(),
            );
        }
        let mut loads = Loads {
            tip_force: g.vec(f_ref),
            tip_moment: g.vec(f_ref * l),
            // Distributed force on every third problem (its moment about the base needs the
            // shape between samples, so the moment balance is checked on the others).
            distributed_force: (case % 3 == 0)
                .then(|| softrod::Profile::Constant(g.vec(f_ref / l))),
            ..Default::default()
        };
        let s_point = g.range(0.2, 0.8) * l;
        loads.point_loads.push(PointLoad {
            s: s_point,
            force: g.vec(f_ref),
            moment: g.vec(f_ref * l),
            frame: softrod::Frame::World,
        });
        let opts = SolveOptions {
            newton: softrod::NewtonOptions {
                throw: false,
                ..SolveOptions::default().newton
            },
            ..Default::default()
        };
        let sol = common::solve(&rod, &tendons, &loads, &opts).unwrap();
        if !sol.stats.converged {
            continue;
        }
        solved += 1;
        let q = loads
            .distributed_force
            .as_ref()
            .map_or(Vector3::zeros(), |f| f.at(0.0));
        let p = |i: usize| Vector3::from(sol.position[i]);
        let n = sol.s.len();
        // Force balance: N(0) = F_tip + F_point + q L.
        let fb = Vector3::new(sol.base_wrench[0], sol.base_wrench[1], sol.base_wrench[2]);
        let f_total = loads.tip_force + loads.point_loads[0].force + q * l;
        assert!(
            (fb - f_total).amax() < 1e-9 * f_ref,
            "case {case}: {fb:?} vs {f_total:?}"
        );
        // Moment balance about the base: M(0) = Σ (x - p0) × F + Σ M.
        if loads.distributed_force.is_none() {
            let mb = Vector3::new(sol.base_wrench[3], sol.base_wrench[4], sol.base_wrench[5]);
            let ip = sol.s.iter().position(|&s| s == s_point).unwrap();
            let m_total = (p(n - 1) - p(0)).cross(&loads.tip_force)
                + loads.tip_moment
                + (p(ip) - p(0)).cross(&loads.point_loads[0].force)
                + loads.point_loads[0].moment;
            assert!(
                (mb - m_total).amax() < 1e-9 * f_ref * l,
                "case {case}: {mb:?} vs {m_total:?}"
            );
        }
        // Rod's own base force = total minus the tendons' pull at s = 0.
        let nb0 = Vector3::from(sol.n_world[0]);
        let pull = fb - nb0;
        let tension: f64 = tendons.iter().map(|t| t.tension()).sum();
        assert!(
            pull.norm() <= tension * (1.0 + 1e-12) + 1e-12,
            "case {case}"
        );
    }
    println!("{solved} of 40 random problems converged");
    assert!(solved >= 30);
}
