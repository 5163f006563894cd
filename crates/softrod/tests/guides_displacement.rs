//! Displacement control of disk-guided tendons: the path is the polyline of chords through the
//! guides, its shortening from the zero-actuation shape the displacement. Oracles: the round
//! trip through the tension-controlled solve (loading and an unloading step of the same
//! history, frictionless and with guide friction, mixed with channel tendons), the polyline
//! length recomputed here from the returned shape, slack tendons against the robot without
//! them, and the complementarity with a finite tendon stiffness.
#![allow(clippy::unwrap_used, missing_docs)]

use std::sync::Arc;

use softrod::nalgebra::{Matrix3, Vector3};
use softrod::{
    reference_lengths, solve_frictional, solve_statics, Actuation, Error, FrictionOptions,
    FrictionalSolution, Loads, RobotModel, StaticsSolution, TendonInput,
};

#[path = "common/robot.rs"]
mod robot;

/// A tip force that bends the rod at zero actuation (chords then differ from arcs).
fn tip() -> Vector3<f64> {
    Vector3::new(0.03, -0.02, 0.0)
}

/// The NiTi robot with its tendons through 8 disks per segment (coefficient `mu` at every
/// guide) under `loads`; with `channel`, the second segment's tendons in continuous
/// channels of friction `mu` instead.
fn guided(mu: f64, loads: Loads, channel: bool) -> Arc<RobotModel> {
    let tendons = robot::niti_tendons(&[0.0; 6])
        .into_iter()
        .enumerate()
        .map(|(i, t)| {
            let end = if i < 3 { 0.2 } else { 0.4 };
            if channel && i >= 3 {
                return if mu > 0.0 {
                    t.tendon.with_friction(mu).unwrap()
                } else {
                    t.tendon
                };
            }
            let n = (8.0 * end / 0.2_f64).round() as usize;
            let guides = (1..n).map(|g| end * g as f64 / n as f64).collect();
            t.tendon.with_guides(guides, &[mu]).unwrap()
        })
        .collect();
    RobotModel::new(robot::niti_rod(), tendons, Vec::new(), loads).unwrap()
}

/// The polyline length of guided tendon `i` through its anchors (base hole, guides,
/// termination) on the shape `st`: the offset points `p + R r` at the anchors' nodes.
fn polyline(model: &RobotModel, st: &StaticsSolution, i: usize) -> f64 {
    let t = &model.tendons()[i];
    let mut anchors = vec![0.0];
    anchors.extend_from_slice(t.guides());
    anchors.push(model.tendon_ends()[i]);
    let x = |s: f64| {
        let j = st.s.iter().position(|&m| m == s).unwrap();
        let r = Matrix3::from_fn(|p, q| st.rotation[j][p][q]);
        let (o, _) = t.routing().offset(s, &model.rod().section_at(s));
        Vector3::from(st.position[j]) + r * Vector3::new(o[0], o[1], 0.0)
    };
    anchors.windows(2).map(|w| (x(w[1]) - x(w[0])).norm()).sum()
}

/// Largest distance between the nodes of two shapes on the same mesh (m).
fn shape_distance(a: &StaticsSolution, b: &StaticsSolution) -> f64 {
    assert_eq!(a.s, b.s);
    let mut d: f64 = 0.0;
    for (p, q) in a.position.iter().zip(&b.position) {
        for k in 0..3 {
            d = d.max((p[k] - q[k]).abs());
        }
    }
    d
}

/// Largest relative difference of the guide tensions (every anchor) and of the node tensions
/// of two solutions, relative to the largest tension of `b`; and whether their slip states
/// (per guide and per node) agree.
fn tension_distance(a: &FrictionalSolution, b: &FrictionalSolution) -> (f64, bool) {
    let scale = b.tension.iter().flatten().fold(0.0, |m: f64, t| m.max(*t));
    let mut d: f64 = 0.0;
    let mut same = a.slip == b.slip;
    for (ga, gb) in a.guides.iter().zip(&b.guides) {
        assert_eq!(ga.len(), gb.len());
        for (x, y) in ga.iter().zip(gb) {
            d = d.max((x.tension_in - y.tension_in).abs() / scale);
            d = d.max((x.tension_out - y.tension_out).abs() / scale);
            same &= x.slip == y.slip;
        }
    }
    for (x, y) in a.tension.iter().flatten().zip(b.tension.iter().flatten()) {
        d = d.max((x - y).abs() / scale);
    }
    (d, same)
}

/// The actuation of `target` with the tendons `held` displacement-controlled at the
/// shortenings `reference − tendon_lengths` of `target`.
fn held_actuation(
    target: &FrictionalSolution,
    tensions: &[f64],
    held: &[usize],
    reference: &[f64],
) -> Actuation {
    let mut act = Actuation::tensions(tensions);
    for &i in held {
        act.tendons[i] = TendonInput::displacement(reference[i] - target.statics.tendon_lengths[i]);
    }
    act
}

/// The zero of the displacements of a guided tendon is its polyline at zero actuation: what
/// the guided solve reports as `tendon_lengths` there, and the length recomputed from the
/// shape; not the length of the continuous channel on that shape.
#[test]
fn guided_reference_is_the_polyline_at_zero_actuation() {
    let opts = FrictionOptions::default();
    let model = guided(0.2, Loads::tip_force(tip()), false);
    let reference = reference_lengths(&model, &opts.statics).unwrap();
    let zero = solve_frictional(&model, &Actuation::tensions(&[0.0; 6]), &opts, None).unwrap();
    let mut worst: f64 = 0.0;
    let mut chord_vs_arc: f64 = f64::INFINITY;
    let channel = solve_statics(
        &guided(0.0, Loads::tip_force(tip()), true),
        &Actuation::tensions(&[0.0; 6]),
        &opts.statics,
    )
    .unwrap();
    for i in 0..6 {
        let line = polyline(&model, &zero.statics, i);
        worst = worst
            .max((reference[i] - line).abs())
            .max((zero.statics.tendon_lengths[i] - line).abs());
        if i < 3 {
            // The first segment's tendons: the arc of the channel model is longer or shorter
            // than the chords by the sagitta terms.
            chord_vs_arc = chord_vs_arc.min((channel.tendon_lengths[i] - line).abs());
        }
    }
    eprintln!(
        "guided reference: polyline recomputed from the shape {worst:e} m; the channel's arc \
         differs from the chords by at least {chord_vs_arc:e} m"
    );
    assert!(worst < 1e-14, "{worst:e} m");
    assert!(
        chord_vs_arc > 1e-8,
        "{chord_vs_arc:e} m: the check does not tell them apart"
    );
}

/// Round trip on the NiTi robot with disks under a tip force, frictionless and with guide
/// friction: a loading step from rest and an unloading step on the same history under
/// tension control; their shortenings held on the same history give back the tensions (every
/// guide, every node) to 1e-8, the shapes to 1e-10 m and the same slip states; the held
/// tendons' polylines recomputed from the returned shape meet their displacements.
#[test]
fn guided_displacement_round_trip_loading_and_unloading() {
    let opts = FrictionOptions::default();
    let up = [2.0, 0.0, 0.6, 0.0, 1.0, 0.2];
    let down = [1.6, 0.0, 0.48, 0.0, 0.8, 0.16];
    for mu in [0.0, 0.2] {
        let model = guided(mu, Loads::tip_force(tip()), false);
        let reference = reference_lengths(&model, &opts.statics).unwrap();
        let first = solve_frictional(&model, &Actuation::tensions(&up), &opts, None).unwrap();
        let second =
            solve_frictional(&model, &Actuation::tensions(&down), &opts, Some(&first)).unwrap();
        for (name, target, tensions, prev) in [
            ("loading", &first, &up, None),
            ("unloading", &second, &down, Some(&first)),
        ] {
            let held = [0, 4];
            let act = held_actuation(target, tensions, &held, &reference);
            let sol = solve_frictional(&model, &act, &opts, prev).unwrap();
            let (dt, same) = tension_distance(&sol, target);
            let dp = shape_distance(&sol.statics, &target.statics);
            let mut dl: f64 = 0.0;
            for &i in &held {
                let TendonInput::Displacement { displacement, .. } = act.tendons[i] else {
                    unreachable!()
                };
                dl =
                    dl.max((reference[i] - polyline(&model, &sol.statics, i) - displacement).abs());
                assert!(sol.statics.tendon_tensions[i] > 0.0);
            }
            let stuck = sol
                .guides
                .iter()
                .flatten()
                .filter(|g| g.slip == softrod::Slip::Stick)
                .count();
            eprintln!(
                "guided round trip μ = {mu}, {name}: tensions {dt:e} relative, shape {dp:e} m, \
                 held polylines off their displacements by {dl:e} m, slip states equal: \
                 {same} ({stuck} anchors stick), {} marches",
                sol.iterations
            );
            assert!(dt < 1e-8 && dp < 1e-10, "{dt:e}, {dp:e} m");
            assert!(dl < 1e-12, "{dl:e} m");
            assert!(same, "slip states differ");
            if mu > 0.0 && prev.is_some() {
                assert!(stuck > 0, "the unloading step sticks at some guide");
            }
        }
    }
}

/// Guided tendons (first segment, guide friction 0.2) and channel tendons (second segment,
/// channel friction 0.2) on one robot, a guided and a channel tendon displacement-controlled:
/// the round trip of a loading and an unloading step.
#[test]
fn guided_and_channel_tendons_held_together() {
    let opts = FrictionOptions::default();
    let model = guided(0.2, Loads::default(), true);
    let reference = reference_lengths(&model, &opts.statics).unwrap();
    let up = [2.0, 0.0, 0.6, 0.0, 1.0, 0.2];
    let down = [1.8, 0.0, 0.54, 0.0, 0.9, 0.18];
    let first = solve_frictional(&model, &Actuation::tensions(&up), &opts, None).unwrap();
    let second =
        solve_frictional(&model, &Actuation::tensions(&down), &opts, Some(&first)).unwrap();
    for (name, target, tensions, prev) in [
        ("loading", &first, &up, None),
        ("unloading", &second, &down, Some(&first)),
    ] {
        let act = held_actuation(target, tensions, &[0, 4], &reference);
        let sol = solve_frictional(&model, &act, &opts, prev).unwrap();
        let (dt, same) = tension_distance(&sol, target);
        let dp = shape_distance(&sol.statics, &target.statics);
        eprintln!(
            "guided + channel held, {name}: tensions {dt:e} relative, shape {dp:e} m, slip \
             states equal: {same}"
        );
        assert!(dt < 1e-8 && dp < 1e-10, "{dt:e}, {dp:e} m");
        assert!(same, "slip states differ");
    }
}

/// A guided tendon paid out (negative displacement) goes slack: zero tension everywhere
/// along it, and the shape of the robot without that tendon (1e-10 m), frictionless and with
/// guide friction. The displacement pays out 1 mm more than the path of that tendon needs on
/// the robot without it (its polyline recomputed from that shape), so the slack is 1 mm.
#[test]
fn guided_tendon_paid_out_goes_slack() {
    let opts = FrictionOptions::default();
    for mu in [0.0, 0.2] {
        let model = guided(mu, Loads::tip_force(tip()), false);
        let reference = reference_lengths(&model, &opts.statics).unwrap();
        // The robot without tendon 0 (the other first-segment tendons share its guides, so
        // the mesh carries its anchors).
        let tendons: Vec<_> = model.tendons()[1..].to_vec();
        let without = RobotModel::new(
            model.rod().clone(),
            tendons,
            Vec::new(),
            Loads::tip_force(tip()),
        )
        .unwrap();
        let other = solve_frictional(
            &without,
            &Actuation::tensions(&[0.0, 0.6, 0.0, 1.0, 0.2]),
            &opts,
            None,
        )
        .unwrap();
        let needed = reference[0] - polyline(&model, &other.statics, 0);
        let delta = needed.min(0.0) - 1e-3;
        let mut act = Actuation::tensions(&[0.0, 0.0, 0.6, 0.0, 1.0, 0.2]);
        act.tendons[0] = TendonInput::displacement(delta);
        let sol = solve_frictional(&model, &act, &opts, None).unwrap();
        let dp = shape_distance(&sol.statics, &other.statics);
        let slack = reference[0] - polyline(&model, &sol.statics, 0) - delta;
        let zero = sol.guides[0]
            .iter()
            .all(|g| g.tension_in == 0.0 && g.tension_out == 0.0)
            && sol.tension.iter().all(|row| row[0] == 0.0);
        eprintln!(
            "guided slack μ = {mu}: displacement {delta:e} m (the path without it shortens by \
             {needed:e} m); shape against the robot without it {dp:e} m, slack {slack:e} m, \
             zero tension: {zero}"
        );
        assert!(delta < 0.0);
        assert!(zero && sol.statics.tendon_tensions[0] == 0.0);
        assert!(
            (slack - (needed - delta)).abs() < 1e-10,
            "{slack:e} m against {:e} m",
            needed - delta
        );
        assert!(dp < 1e-10, "{dp:e} m");
    }
}

/// μ = 0: guided displacement control (one tendon inextensible, one with a finite axial
/// stiffness) against the guided tension solve at the returned tensions: the same shape,
/// and the complementarity `ℓ_ref − ℓ − δ + τ/k = 0` with `ℓ` the polyline recomputed here.
#[test]
fn frictionless_guided_displacement_against_the_tension_solve() {
    let opts = FrictionOptions::default();
    let model = guided(0.0, Loads::tip_force(tip()), false);
    let reference = reference_lengths(&model, &opts.statics).unwrap();
    let k = 400.0;
    let mut act = Actuation::tensions(&[0.0, 0.0, 0.5, 0.0, 0.0, 0.3]);
    act.tendons[0] = TendonInput::displacement(4e-3);
    act.tendons[4] = TendonInput::Displacement {
        displacement: 2e-3,
        stiffness: k,
    };
    let sol = solve_frictional(&model, &act, &opts, None).unwrap();
    let tau = sol.statics.tendon_tensions.clone();
    assert!(tau[0] > 0.0 && tau[4] > 0.0, "{tau:?}");
    let plain = solve_frictional(&model, &Actuation::tensions(&tau), &opts, None).unwrap();
    let dp = shape_distance(&sol.statics, &plain.statics);
    let g0 = reference[0] - polyline(&model, &sol.statics, 0) - 4e-3;
    let g4 = reference[4] - polyline(&model, &sol.statics, 4) - 2e-3 + tau[4] / k;
    eprintln!(
        "μ = 0 guided displacement: tensions {:.9} N, {:.9} N; against the tension solve \
         {dp:e} m; complementarity {g0:e} m, {g4:e} m (k = {k} N/m)",
        tau[0], tau[4]
    );
    assert!(dp < 1e-10, "{dp:e} m");
    assert!(g0.abs() < 1e-12 && g4.abs() < 1e-12, "{g0:e}, {g4:e}");
}

/// The statics solve without friction cannot hold a guided tendon (its tension along the
/// continuous channel would be another robot's answer): refused by name.
#[test]
fn statics_solve_refuses_a_held_guided_tendon_by_name() {
    let model = guided(0.0, Loads::default(), false);
    let mut act = Actuation::tensions(&[0.0; 6]);
    act.tendons[1] = TendonInput::displacement(1e-3);
    match solve_statics(&model, &act, &FrictionOptions::default().statics) {
        Err(Error::InvalidParameter { name, .. }) => assert_eq!(name, "tendons[1].guides"),
        other => panic!("expected a named error, got {other:?}"),
    }
}
