//! PCC kinematics against independent oracles: closed-form arc poses, the SE(3) matrix
//! exponential of a constant body twist, hand-computed chains, central finite differences,
//! tendon lengths integrated along the backbone, and brute-force closest arcs.
#![allow(clippy::unwrap_used, missing_docs)]

use std::f64::consts::{FRAC_PI_2, PI};

use softrod::nalgebra::{Matrix3, Matrix4, Matrix6x3, Matrix6xX, Vector3};
use softrod::pcc::{
    arc_frames, arc_from_pressures, arc_from_pressures_jacobian, arc_from_tendon_displacements,
    arc_from_tendon_displacements_jacobian, arc_from_tendon_tensions,
    arc_from_tendon_tensions_jacobian, arc_from_tip, arc_from_tip_with_length, arc_jacobian,
    arc_pose, chain_jacobian, chain_pose, tendon_displacement_jacobian, tendon_displacement_misfit,
    tendon_displacements, ArcCoordinates, ElasticSegment, JacobianFrame, PccChain, PccChambers,
    PccSegment, PccTendons,
};
use softrod::Error;

const FRAMES: [JacobianFrame; 3] = [
    JacobianFrame::Spatial,
    JacobianFrame::Body,
    JacobianFrame::Hybrid,
];
const COORDS: [ArcCoordinates; 2] = [ArcCoordinates::Arc, ArcCoordinates::CurvatureVector];

fn rz(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

fn ry(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

fn homogeneous(r: Matrix3<f64>, p: Vector3<f64>) -> Matrix4<f64> {
    let mut t = Matrix4::identity();
    t.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
    t.fixed_view_mut::<3, 1>(0, 3).copy_from(&p);
    t
}

/// Webster & Jones' closed form, twist removed: `Rz(φ) Ry(κℓ) Rz(-φ)` and the textbook
/// position, evaluated naively (only where `κ` is not small).
fn closed_form(k: f64, phi: f64, l: f64) -> Matrix4<f64> {
    let th = k * l;
    let rho = (1.0 - th.cos()) / k;
    let p = Vector3::new(phi.cos() * rho, phi.sin() * rho, th.sin() / k);
    homogeneous(rz(phi) * ry(th) * rz(-phi), p)
}

/// `exp(ℓ [u^, v; 0, 0])` with `v = z`, `u = κ (-sin φ, cos φ, 0)`, by nalgebra's Padé
/// matrix exponential: an oracle independent of the arc formulas.
fn twist_exponential(k: f64, phi: f64, l: f64) -> Matrix4<f64> {
    let (ux, uy) = (-k * phi.sin(), k * phi.cos());
    let xi = Matrix4::new(
        0.0, 0.0, uy, 0.0, //
        0.0, 0.0, -ux, 0.0, //
        -uy, ux, 0.0, 1.0, //
        0.0, 0.0, 0.0, 0.0,
    ) * l;
    xi.exp()
}

fn max_abs(m: &Matrix4<f64>) -> f64 {
    m.amax()
}

fn inverse(t: &Matrix4<f64>) -> Matrix4<f64> {
    let r = t.fixed_view::<3, 3>(0, 0).into_owned();
    let p = t.fixed_view::<3, 1>(0, 3).into_owned();
    homogeneous(r.transpose(), -(r.transpose() * p))
}

fn seg(k: f64, phi: f64, l: f64) -> PccSegment {
    PccSegment::new(k, phi, l).unwrap()
}

// ------------------------------------------------------------------ forward kinematics ----

#[test]
fn quarter_circle_matches_closed_form() {
    let l = 0.3;
    let k = FRAC_PI_2 / l;
    let rho = 1.0 / k;
    // φ = 0: tip at (ρ, 0, ρ), tangent along +x, frame Ry(π/2).
    let t = arc_pose(k, 0.0, l).unwrap();
    let expected = homogeneous(
        Matrix3::new(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0),
        Vector3::new(rho, 0.0, rho),
    );
    assert!(max_abs(&(t - expected)) < 1e-12, "{t}");
    // φ = π/2: tip at (0, ρ, ρ), tangent along +y, frame = rotation by π/2 about -x.
    let t = arc_pose(k, FRAC_PI_2, l).unwrap();
    let expected = homogeneous(
        Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0),
        Vector3::new(0.0, rho, rho),
    );
    assert!(max_abs(&(t - expected)) < 1e-12, "{t}");
    // General plane angle against the closed form.
    for phi in [-2.5, 0.7, 3.0] {
        let t = arc_pose(k, phi, l).unwrap();
        assert!(max_abs(&(t - closed_form(k, phi, l))) < 1e-12);
    }
}

#[test]
fn full_circle_returns_to_base() {
    for (l, phi) in [(0.5, 0.0), (0.2, 1.3), (2.0, -2.9)] {
        let k = 2.0 * PI / l;
        let t = arc_pose(k, phi, l).unwrap();
        assert!(max_abs(&(t - Matrix4::identity())) < 1e-12, "{t}");
        // Halfway round the tip is at distance 2ρ in the bending plane, pointing back.
        let half = seg(k, phi, l).pose_at(0.5 * l).unwrap();
        let d = 2.0 / k;
        let expected = Vector3::new(d * phi.cos(), d * phi.sin(), 0.0);
        assert!((half.fixed_view::<3, 1>(0, 3) - expected).amax() < 1e-12);
        assert!((half[(2, 2)] + 1.0).abs() < 1e-12);
    }
}

#[test]
fn straight_segment_is_a_translation() {
    for phi in [0.0, 1.0, -2.0] {
        let t = arc_pose(0.0, phi, 0.42).unwrap();
        let expected = homogeneous(Matrix3::identity(), Vector3::new(0.0, 0.0, 0.42));
        assert!(max_abs(&(t - expected)) < 1e-15);
    }
    let t = arc_pose(3.0, 0.5, 0.0).unwrap();
    assert_eq!(t, Matrix4::identity());
}

#[test]
fn pose_matches_twist_exponential() {
    for &(k, phi, l) in &[
        (2.0, 0.3, 0.5),
        (-7.0, 2.0, 0.8),
        (0.01, -1.0, 1.0),
        (30.0, 4.0, 0.2),
        (1e-7, 0.9, 0.7),
    ] {
        let t = arc_pose(k, phi, l).unwrap();
        let e = twist_exponential(k, phi, l);
        assert!(
            max_abs(&(t - e)) < 1e-12,
            "{k} {phi} {l}: {}",
            max_abs(&(t - e))
        );
        let r = t.fixed_view::<3, 3>(0, 0).into_owned();
        assert!((r.transpose() * r - Matrix3::identity()).amax() < 1e-14);
    }
}

#[test]
fn continuous_through_zero_curvature() {
    let (phi, l) = (0.8, 0.6);
    let t0 = arc_pose(0.0, phi, l).unwrap();
    for k in [1e-9, -1e-9, 1e-6, -1e-6] {
        let t = arc_pose(k, phi, l).unwrap();
        assert!(t.iter().all(|v| v.is_finite()));
        // Against κ = 0: the first-order change is κ ℓ² / 2 sideways and κ ℓ in rotation.
        let d = max_abs(&(t - t0));
        assert!(
            d <= 1.0001 * k.abs() * l && d >= 0.4 * k.abs() * l * l,
            "{k}: {d}"
        );
        // Against the Taylor expansion (to θ³, error θ⁵ ℓ): positions and rotation.
        let th = k * l;
        let side = l * (th / 2.0 - th.powi(3) / 24.0);
        let ax = l * (1.0 - th * th / 6.0);
        assert!((t[(0, 3)] - phi.cos() * side).abs() < 1e-15);
        assert!((t[(1, 3)] - phi.sin() * side).abs() < 1e-15);
        assert!((t[(2, 3)] - ax).abs() < 1e-15);
        assert!((t[(0, 2)] - phi.cos() * (th - th.powi(3) / 6.0)).abs() < 1e-15);
    }
    // Where the naive formula is well conditioned it agrees to its own rounding error,
    // about eps / θ² relative on (1 - cos θ)/κ.
    for k in [1e-3, 1e-2, 0.1, 1.0, 5.0] {
        let t = arc_pose(k, phi, l).unwrap();
        let th = k * l;
        let tol = 1e-15 * (1.0 + 1.0 / (th * th)) * l;
        assert!(max_abs(&(t - closed_form(k, phi, l))) < tol, "{k}");
    }
    // Monotone and smooth: equal steps in κ give equal steps in the tip to first order.
    let tips: Vec<f64> = [-2e-6, -1e-6, 0.0, 1e-6, 2e-6]
        .iter()
        .map(|&k| arc_pose(k, phi, l).unwrap()[(0, 3)])
        .collect();
    for w in tips.windows(2) {
        assert!((w[1] - w[0] - phi.cos() * 1e-6 * l * l / 2.0).abs() < 1e-18);
    }
}

#[test]
fn backbone_frames_lie_on_the_arc() {
    let (k, phi, l) = (4.0, -0.6, 0.9);
    let s: Vec<f64> = (0..=20).map(|i| l * i as f64 / 20.0).collect();
    let frames = arc_frames(k, phi, l, &s).unwrap();
    let centre = Vector3::new(phi.cos(), phi.sin(), 0.0) / k;
    for (i, t) in frames.iter().enumerate() {
        // Each frame is the pose of the shorter arc, on the circle, tangent = dp/ds.
        assert!(max_abs(&(t - closed_form(k, phi, s[i]))) < 1e-12);
        let p = t.fixed_view::<3, 1>(0, 3).into_owned();
        assert!(((p - centre).norm() - 1.0 / k).abs() < 1e-12);
        let h = 1e-6;
        let sp = (s[i] + h).min(l);
        let sm = (s[i] - h).max(0.0);
        let dp = (seg(k, phi, l).pose_at(sp).unwrap() - seg(k, phi, l).pose_at(sm).unwrap())
            .fixed_view::<3, 1>(0, 3)
            / (sp - sm);
        // One-sided at the ends: error κ h / 2.
        assert!((dp - t.fixed_view::<3, 1>(0, 2)).amax() < k * h);
    }
    assert_eq!(frames[0], Matrix4::identity());
    assert_eq!(frames[20], arc_pose(k, phi, l).unwrap());
}

#[test]
fn two_quarter_circles_in_different_planes() {
    // Segment 1 bends toward +x, segment 2 toward its own +y (which is world +y): tip at
    // (2ρ, ρ, ρ), tangent +y, frame Ry(π/2) Rx(-π/2) = [[0,-1,0],[0,0,1],[-1,0,0]].
    let l = 0.25;
    let k = FRAC_PI_2 / l;
    let rho = 1.0 / k;
    let chain = PccChain::from_parameters(&[[k, 0.0, l], [k, FRAC_PI_2, l]]).unwrap();
    let expected = homogeneous(
        Matrix3::new(0.0, -1.0, 0.0, 0.0, 0.0, 1.0, -1.0, 0.0, 0.0),
        Vector3::new(2.0 * rho, rho, rho),
    );
    assert!(max_abs(&(chain.tip_pose() - expected)) < 1e-12);
    assert_eq!(chain.len(), 2);
    assert!((chain.length() - 2.0 * l).abs() < 1e-15);
    let poses = chain.segment_poses();
    assert!(max_abs(&(poses[0] - arc_pose(k, 0.0, l).unwrap())) < 1e-15);
    assert!(max_abs(&(poses[1] - expected)) < 1e-12);
    // Frames along the chain: the junction, the midpoint of segment 2, the tip.
    // Midpoint of segment 2 (turned by c = π/4 in its plane): by hand, its local position
    // (0, ρ(1 - cos c), ρ sin c) mapped by segment 1's tip, (ρ + ρ sin c, ρ(1 - cos c), ρ).
    let mid = chain.pose_at(1.5 * l).unwrap();
    let c = FRAC_PI_2 / 2.0;
    let expected_mid = Vector3::new(rho + rho * c.sin(), rho * (1.0 - c.cos()), rho);
    assert!((mid.fixed_view::<3, 1>(0, 3) - expected_mid).amax() < 1e-12);
    assert!(max_abs(&(chain.pose_at(l).unwrap() - poses[0])) < 1e-15);
    assert!(max_abs(&(chain.pose_at(2.0 * l).unwrap() - expected)) < 1e-12);
    // Free function on a slice agrees with the type.
    assert_eq!(chain_pose(chain.segments()), chain.tip_pose());
}

// ---------------------------------------------------------------------------- inverse ----

#[test]
fn extensible_inverse_round_trips() {
    for &(k, phi, l) in &[
        (2.0, 0.3, 0.5),
        (9.0, -2.0, 0.6), // θ = 5.4 rad > π
        (1e-8, 1.2, 0.4),
        (0.5, 3.0, 1.0),
    ] {
        let tip = seg(k, phi, l).tip_position();
        let back = arc_from_tip(&tip).unwrap();
        assert!((back.curvature() - k).abs() < 1e-10 * k.max(1.0), "{k}");
        assert!((back.length() - l).abs() < 1e-12, "{l} {}", back.length());
        assert!(max_abs(&(back.pose() - seg(k, phi, l).pose())) < 1e-11);
    }
    // On the axis: straight.
    let s = arc_from_tip(&Vector3::new(0.0, 0.0, 0.3)).unwrap();
    assert_eq!((s.curvature(), s.length()), (0.0, 0.3));
    assert!(matches!(
        arc_from_tip(&Vector3::new(0.0, 0.0, -0.3)),
        Err(Error::InvalidParameter { name, .. }) if name == "position"
    ));
    assert!(matches!(
        arc_from_tip(&Vector3::new(f64::NAN, 0.0, 0.3)),
        Err(Error::InvalidParameter { name, .. }) if name == "position[0]"
    ));
}

#[test]
fn fixed_length_inverse_is_exact_when_reachable_and_closest_otherwise() {
    for &(k, phi, l) in &[
        (2.0, 0.3, 0.5),
        (9.0, -2.0, 0.6),
        (1e-3, 1.0, 0.4),
        (0.0, 0.0, 1.0),
    ] {
        let tip = seg(k, phi, l).tip_position();
        let fit = arc_from_tip_with_length(&tip, l).unwrap();
        assert!(fit.residual < 1e-12, "{k}: {}", fit.residual);
        assert!(
            (fit.segment.curvature() - k).abs() < 1e-7,
            "{k} {}",
            fit.segment.curvature()
        );
        assert!((fit.segment.tip_position() - tip).norm() < 1e-12);
    }
    // Unreachable targets: compare with a brute-force scan of the bending angle.
    let l = 0.5;
    for target in [
        Vector3::new(0.2, 0.1, 0.1),
        Vector3::new(0.0, 0.0, 0.8),
        Vector3::new(-0.05, 0.02, -0.3),
        Vector3::new(0.3, 0.0, 0.0),
    ] {
        let fit = arc_from_tip_with_length(&target, l).unwrap();
        let phi = target.y.atan2(target.x);
        let brute = (0..=200_000)
            .map(|i| {
                let th = 2.0 * PI * i as f64 / 200_000.0;
                (seg(th / l, phi, l).tip_position() - target).norm()
            })
            .fold(f64::INFINITY, f64::min);
        assert!(
            fit.residual <= brute + 1e-12,
            "{target}: {} {brute}",
            fit.residual
        );
        assert!(fit.residual >= brute - 1e-6);
        assert!(((fit.segment.tip_position() - target).norm() - fit.residual).abs() < 1e-14);
    }
}

// -------------------------------------------------------------------------- Jacobians ----

/// Twist of a finite-difference pose derivative `dT`, in `frame`.
fn twist(t: &Matrix4<f64>, dt: &Matrix4<f64>, frame: JacobianFrame) -> [f64; 6] {
    let m = match frame {
        JacobianFrame::Spatial => dt * inverse(t),
        JacobianFrame::Body => inverse(t) * dt,
        JacobianFrame::Hybrid => dt * inverse(t),
    };
    let w = [
        0.5 * (m[(2, 1)] - m[(1, 2)]),
        0.5 * (m[(0, 2)] - m[(2, 0)]),
        0.5 * (m[(1, 0)] - m[(0, 1)]),
    ];
    let v = if frame == JacobianFrame::Hybrid {
        [dt[(0, 3)], dt[(1, 3)], dt[(2, 3)]]
    } else {
        [m[(0, 3)], m[(1, 3)], m[(2, 3)]]
    };
    [v[0], v[1], v[2], w[0], w[1], w[2]]
}

fn segment_in(coords: ArcCoordinates, q: [f64; 3]) -> PccSegment {
    match coords {
        ArcCoordinates::Arc => seg(q[0], q[1], q[2]),
        ArcCoordinates::CurvatureVector => {
            PccSegment::from_curvature_vector(q[0], q[1], q[2]).unwrap()
        }
    }
}

fn coordinates_of(s: &PccSegment, coords: ArcCoordinates) -> [f64; 3] {
    match coords {
        ArcCoordinates::Arc => [s.curvature(), s.plane_angle(), s.length()],
        ArcCoordinates::CurvatureVector => {
            let u = s.curvature_vector();
            [u.x, u.y, s.length()]
        }
    }
}

/// Central differences of the chain pose with respect to all coordinates.
fn fd_chain(
    segments: &[PccSegment],
    frame: JacobianFrame,
    coords: ArcCoordinates,
) -> Matrix6xX<f64> {
    let n = segments.len();
    let t = chain_pose(segments);
    let mut j = Matrix6xX::zeros(3 * n);
    for i in 0..n {
        let q = coordinates_of(&segments[i], coords);
        for c in 0..3 {
            let h = [1e-5, 1e-5, 1e-6][c];
            let mut plus = segments.to_vec();
            let mut minus = segments.to_vec();
            let (mut qp, mut qm) = (q, q);
            qp[c] += h;
            qm[c] -= h;
            plus[i] = segment_in(coords, qp);
            minus[i] = segment_in(coords, qm);
            let dt = (chain_pose(&plus) - chain_pose(&minus)) / (2.0 * h);
            let tw = twist(&t, &dt, frame);
            for r in 0..6 {
                j[(r, 3 * i + c)] = tw[r];
            }
        }
    }
    j
}

fn assert_close_rel(j: &Matrix6xX<f64>, fd: &Matrix6xX<f64>, what: &str) {
    let scale = j.amax().max(1e-300);
    let err = (j - fd).amax();
    assert!(
        err <= 1e-7 * scale,
        "{what}: err {err:e} scale {scale:e}\n{j}{fd}"
    );
    // Column by column where the column is not negligible.
    for c in 0..j.ncols() {
        let cn = j.column(c).amax();
        if cn > 1e-3 * scale {
            let ce = (j.column(c) - fd.column(c)).amax();
            assert!(ce <= 1e-7 * cn, "{what} column {c}: {ce:e} vs {cn:e}");
        }
    }
}

#[test]
fn segment_jacobians_match_finite_differences() {
    for &(k, phi, l) in &[
        (3.0, 0.4, 0.7),
        (-5.0, 2.2, 0.5),
        (12.0, -1.0, 0.5), // θ = 6 rad
        (0.0, 0.3, 0.6),
        (1e-9, -0.7, 0.6),
        (-1e-6, 1.1, 0.6),
        (0.12, 0.0, 0.9), // θ across the series threshold of the derivative
    ] {
        let s = seg(k, phi, l);
        for frame in FRAMES {
            for coords in COORDS {
                let j: Matrix6x3<f64> = s.jacobian(frame, coords);
                assert!(j.iter().all(|v| v.is_finite()));
                let j = Matrix6xX::from_column_slice(j.as_slice());
                let fd = fd_chain(&[s], frame, coords);
                assert_close_rel(&j, &fd, &format!("{k} {phi} {l} {frame:?} {coords:?}"));
                let free = arc_jacobian(k, phi, l, frame, coords).unwrap();
                assert_eq!(Matrix6xX::from_column_slice(free.as_slice()), j);
            }
        }
    }
}

#[test]
fn jacobian_is_continuous_through_zero_curvature() {
    let (phi, l) = (0.9, 0.5);
    for frame in FRAMES {
        for coords in COORDS {
            let j0 = seg(0.0, phi, l).jacobian(frame, coords);
            for k in [1e-9, -1e-9, 1e-6, -1e-6] {
                let j = seg(k, phi, l).jacobian(frame, coords);
                // Lipschitz in κ with constant of order ℓ² (ℓ³ for the ∂/∂κ column).
                assert!((j - j0).amax() <= 2.0 * k.abs(), "{frame:?} {coords:?} {k}");
            }
        }
    }
}

#[test]
fn chain_jacobian_matches_finite_differences() {
    let segments = [
        seg(4.0, 0.2, 0.3),
        seg(-2.5, 2.0, 0.4),
        seg(1e-8, -1.0, 0.2),
    ];
    let chain = PccChain::new(segments.to_vec()).unwrap();
    for frame in FRAMES {
        for coords in COORDS {
            let j = chain.jacobian(frame, coords);
            assert_eq!(j, chain_jacobian(&segments, frame, coords));
            let fd = fd_chain(&segments, frame, coords);
            assert_close_rel(&j, &fd, &format!("chain {frame:?} {coords:?}"));
        }
    }
}

// --------------------------------------------------------------------- actuation maps ----

#[test]
fn single_tendon_bends_toward_itself() {
    let (l0, r, e) = (0.2, 0.01, 1e6);
    let body = ElasticSegment::solid_circle(l0, r, e, true).unwrap();
    let ei = e * PI * r.powi(4) / 4.0;
    let ea = e * PI * r * r;
    for beta in [0.0, 1.0, -2.5] {
        let tendons = PccTendons::new(&[0.008], &[beta]).unwrap();
        let tau = 0.7;
        let s = arc_from_tendon_tensions(&[tau], &tendons, &body).unwrap();
        assert!((s.curvature() - tau * 0.008 / ei).abs() < 1e-12 * s.curvature());
        let dphi = (s.plane_angle() - beta).rem_euclid(2.0 * PI);
        assert!(dphi.min(2.0 * PI - dphi) < 1e-12);
        assert!((s.length() - l0 * (1.0 - tau / ea)).abs() < 1e-15);
        // The tip moves toward the tendon.
        let tip = s.tip_position();
        assert!((tip.y.atan2(tip.x) - s.plane_angle()).abs() < 1e-12);
        assert!(tip.x * beta.cos() + tip.y * beta.sin() > 0.0);
        // Inextensible: same curvature, rest length.
        let body_i = ElasticSegment::solid_circle(l0, r, e, false).unwrap();
        let si = arc_from_tendon_tensions(&[tau], &tendons, &body_i).unwrap();
        assert_eq!(si.length(), l0);
        assert!((si.curvature() - s.curvature()).abs() < 1e-15);
    }
}

#[test]
fn three_equal_tendons_only_compress() {
    let body = ElasticSegment::new(0.15, 2e-3, Some(50.0)).unwrap();
    let tendons = PccTendons::equally_spaced(3, 0.01, 0.3).unwrap();
    let tau = 2.0;
    let s = arc_from_tendon_tensions(&[tau; 3], &tendons, &body).unwrap();
    assert!(s.curvature().abs() < 1e-14, "{}", s.curvature());
    assert!((s.length() - 0.15 * (1.0 - 3.0 * tau / 50.0)).abs() < 1e-15);
    let tip = s.tip_position();
    assert!(tip.x.abs() < 1e-15 && tip.y.abs() < 1e-15);
    // Three equal chambers: straight and elongated.
    let chambers = PccChambers::equally_spaced(3, 1e-4, 0.012, 0.0).unwrap();
    let p = arc_from_pressures(&[3e4; 3], &chambers, &body).unwrap();
    assert!(p.curvature().abs() < 1e-14);
    assert!((p.length() - 0.15 * (1.0 + 3.0 * 3e4 * 1e-4 / 50.0)).abs() < 1e-15);
}

#[test]
fn single_chamber_bends_away() {
    let body = ElasticSegment::new(0.1, 1e-3, Some(40.0)).unwrap();
    let chambers = PccChambers::new(&[2e-4, 2e-4], &[0.01, 0.01], &[0.5, 0.5 + PI]).unwrap();
    let s = arc_from_pressures(&[1e4, 0.0], &chambers, &body).unwrap();
    // κ = p A r / E I, toward β + π; elongation p A / E A.
    assert!((s.curvature() - 1e4 * 2e-4 * 0.01 / 1e-3).abs() < 1e-12);
    let tip = s.tip_position();
    assert!(tip.x * 0.5f64.cos() + tip.y * 0.5f64.sin() < 0.0);
    assert!((s.length() - 0.1 * (1.0 + 1e4 * 2e-4 / 40.0)).abs() < 1e-15);
}

/// Tendon length by integrating the tendon path `p(s) + R(s) r` with the midpoint rule on
/// the backbone frames (independent of the closed-form displacement).
fn integrated_tendon_length(s: &PccSegment, d: f64, beta: f64) -> f64 {
    let r = Vector3::new(d * beta.cos(), d * beta.sin(), 0.0);
    let n = 20_000;
    let pts: Vec<Vector3<f64>> = (0..=n)
        .map(|i| {
            let t = s.pose_at(s.length() * i as f64 / n as f64).unwrap();
            t.fixed_view::<3, 1>(0, 3) + t.fixed_view::<3, 3>(0, 0) * r
        })
        .collect();
    pts.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

#[test]
fn tendon_displacements_match_path_lengths_and_round_trip() {
    let tendons = PccTendons::new(&[0.01, 0.012, 0.009, 0.011], &[0.1, 1.9, 3.8, 5.0]).unwrap();
    let l0 = 0.25;
    for &(k, phi, l) in &[(6.0, 0.7, 0.27), (3.0, -2.0, 0.25), (0.0, 0.0, 0.23)] {
        let s = seg(k, phi, l);
        let dl = tendon_displacements(&s, &tendons, Some(l0)).unwrap();
        for i in 0..tendons.len() {
            let (d, b) = (tendons.distances()[i], tendons.angles()[i]);
            let len = integrated_tendon_length(&s, d, b);
            assert!(
                (len - l0 - dl[i]).abs() < 1e-9,
                "{i}: {} {}",
                len - l0,
                dl[i]
            );
        }
        // Extensible round trip with four tendons (over-determined, consistent).
        let back = arc_from_tendon_displacements(&dl, &tendons, l0, true).unwrap();
        assert!(max_abs(&(back.pose() - s.pose())) < 1e-13);
        assert!((back.length() - l).abs() < 1e-14);
    }
    // Inextensible round trip with two tendons at 90°.
    let two = PccTendons::new(&[0.01, 0.01], &[0.0, FRAC_PI_2]).unwrap();
    let s = seg(4.0, 2.5, 0.3);
    let dl = tendon_displacements(&s, &two, None).unwrap();
    let back = arc_from_tendon_displacements(&dl, &two, 0.3, false).unwrap();
    assert!((back.curvature() - 4.0).abs() < 1e-12);
    assert!((back.plane_angle() - 2.5).abs() < 1e-12);
    assert_eq!(back.length(), 0.3);
    // Degenerate layouts are rejected.
    let opposite = PccTendons::new(&[0.01, 0.01], &[0.0, PI]).unwrap();
    assert!(matches!(
        tendon_displacement_misfit(&[0.0, 0.0], &opposite, 0.3, false),
        Err(Error::InvalidParameter { name, .. }) if name == "tendons"
    ));
    assert!(matches!(
        arc_from_tendon_displacements(&[0.0, 0.0], &opposite, 0.3, false),
        Err(Error::InvalidParameter { name, .. }) if name == "tendons"
    ));
    assert!(matches!(
        arc_from_tendon_displacements(&dl, &two, 0.3, true),
        Err(Error::InvalidParameter { name, .. }) if name == "tendons"
    ));
}

/// Central differences of a map `R^n -> (segment)` in `coords`.
fn fd_actuation<F: Fn(&[f64]) -> PccSegment>(
    f: F,
    x: &[f64],
    h: f64,
    coords: ArcCoordinates,
) -> Vec<[f64; 3]> {
    (0..x.len())
        .map(|i| {
            let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
            xp[i] += h;
            xm[i] -= h;
            let (qp, qm) = (
                coordinates_of(&f(&xp), coords),
                coordinates_of(&f(&xm), coords),
            );
            let mut d = [0.0; 3];
            for r in 0..3 {
                let mut diff = qp[r] - qm[r];
                if coords == ArcCoordinates::Arc && r == 1 {
                    diff = (diff + PI).rem_euclid(2.0 * PI) - PI;
                }
                d[r] = diff / (2.0 * h);
            }
            d
        })
        .collect()
}

fn assert_jac(j: &softrod::nalgebra::Matrix3xX<f64>, fd: &[[f64; 3]], what: &str) {
    for r in 0..3 {
        let scale = (0..fd.len()).map(|c| j[(r, c)].abs()).fold(0.0, f64::max);
        for c in 0..fd.len() {
            let err = (j[(r, c)] - fd[c][r]).abs();
            assert!(
                err <= 1e-7 * scale.max(1e-300),
                "{what} ({r},{c}): {} vs {}",
                j[(r, c)],
                fd[c][r]
            );
        }
    }
}

#[test]
fn actuation_jacobians_match_finite_differences() {
    let tendons = PccTendons::new(&[0.01, 0.012, 0.009], &[0.2, 2.3, 4.1]).unwrap();
    let body = ElasticSegment::new(0.2, 3e-3, Some(60.0)).unwrap();
    let chambers = PccChambers::new(
        &[1e-4, 1.2e-4, 0.9e-4],
        &[0.01, 0.011, 0.012],
        &[0.0, 2.0, 4.0],
    )
    .unwrap();
    let tensions = [1.5, 0.4, 0.9];
    let pressures = [2e4, 5e3, 1.2e4];
    for coords in COORDS {
        let j = arc_from_tendon_tensions_jacobian(&tensions, &tendons, &body, coords).unwrap();
        let fd = fd_actuation(
            |t| arc_from_tendon_tensions(t, &tendons, &body).unwrap(),
            &tensions,
            1e-4,
            coords,
        );
        assert_jac(&j, &fd, &format!("tensions {coords:?}"));
        let j = arc_from_pressures_jacobian(&pressures, &chambers, &body, coords).unwrap();
        let fd = fd_actuation(
            |p| arc_from_pressures(p, &chambers, &body).unwrap(),
            &pressures,
            1.0,
            coords,
        );
        assert_jac(&j, &fd, &format!("pressures {coords:?}"));
        for extensible in [true, false] {
            let dl = tendon_displacements(
                &seg(5.0, 1.0, if extensible { 0.21 } else { 0.2 }),
                &tendons,
                Some(0.2),
            )
            .unwrap();
            let j = arc_from_tendon_displacements_jacobian(&dl, &tendons, 0.2, extensible, coords)
                .unwrap();
            let fd = fd_actuation(
                |x| arc_from_tendon_displacements(x, &tendons, 0.2, extensible).unwrap(),
                &dl,
                1e-7,
                coords,
            );
            assert_jac(&j, &fd, &format!("displacements {coords:?} {extensible}"));
        }
    }
    // Arc → displacement Jacobian, both coordinates, including a straight segment.
    for &(k, phi, l) in &[(5.0, 1.0, 0.21), (0.0, 0.4, 0.2), (-1e-7, 2.0, 0.2)] {
        for coords in COORDS {
            let s = seg(k, phi, l);
            let j = tendon_displacement_jacobian(&s, &tendons, coords);
            let q = coordinates_of(&s, coords);
            for c in 0..3 {
                let h = 1e-6;
                let (mut qp, mut qm) = (q, q);
                qp[c] += h;
                qm[c] -= h;
                let dp =
                    tendon_displacements(&segment_in(coords, qp), &tendons, Some(0.2)).unwrap();
                let dm =
                    tendon_displacements(&segment_in(coords, qm), &tendons, Some(0.2)).unwrap();
                for i in 0..tendons.len() {
                    let fd = (dp[i] - dm[i]) / (2.0 * h);
                    assert!(
                        (j[(i, c)] - fd).abs() <= 1e-7 * j.amax(),
                        "{k} {coords:?} ({i},{c})"
                    );
                }
            }
        }
    }
}

#[test]
fn straight_actuation_jacobian_in_curvature_coordinates_is_smooth() {
    let tendons = PccTendons::equally_spaced(3, 0.01, 0.0).unwrap();
    let body = ElasticSegment::new(0.2, 3e-3, Some(60.0)).unwrap();
    let j = arc_from_tendon_tensions_jacobian(
        &[1.0; 3],
        &tendons,
        &body,
        ArcCoordinates::CurvatureVector,
    )
    .unwrap();
    assert!(j.iter().all(|v| v.is_finite()));
    // u_y per unit tension of tendon 0 (β = 0) is d / E I.
    assert!((j[(1, 0)] - 0.01 / 3e-3).abs() < 1e-12);
    assert!(matches!(
        arc_from_tendon_tensions_jacobian(&[0.0; 3], &tendons, &body, ArcCoordinates::Arc),
        Err(Error::InvalidParameter { name, .. }) if name == "curvature"
    ));
    // Composed actuation → tip Jacobian through the straight configuration is finite.
    let s = arc_from_tendon_tensions(&[1.0; 3], &tendons, &body).unwrap();
    let jp = s.jacobian(JacobianFrame::Hybrid, ArcCoordinates::CurvatureVector);
    let composed = jp * j;
    assert!(composed.iter().all(|v| v.is_finite()));
}

// ------------------------------------------------------------------------- validation ----

#[test]
fn invalid_parameters_are_named() {
    let name = |r: Result<PccSegment, Error>| match r {
        Err(Error::InvalidParameter { name, .. }) => name,
        other => panic!("{other:?}"),
    };
    assert_eq!(name(PccSegment::new(f64::NAN, 0.0, 1.0)), "curvature");
    assert_eq!(
        name(PccSegment::new(1.0, f64::INFINITY, 1.0)),
        "plane_angle"
    );
    assert_eq!(name(PccSegment::new(1.0, 0.0, -0.1)), "length");
    assert_eq!(name(PccSegment::new(1.0, 0.0, f64::NAN)), "length");
    assert!(matches!(
        PccChain::from_parameters(&[[1.0, 0.0, 1.0], [f64::NAN, 0.0, 1.0]]),
        Err(Error::InvalidParameter { name, .. }) if name == "segments[1].curvature"
    ));
    assert!(PccChain::new(vec![]).is_err());
    assert!(matches!(
        seg(1.0, 0.0, 0.5).pose_at(0.6),
        Err(Error::InvalidParameter { name, .. }) if name == "s"
    ));
    let tendons = PccTendons::equally_spaced(3, 0.01, 0.0).unwrap();
    let body = ElasticSegment::new(0.2, 3e-3, Some(60.0)).unwrap();
    assert!(matches!(
        arc_from_tendon_tensions(&[1.0, -1.0, 0.0], &tendons, &body),
        Err(Error::InvalidParameter { name, .. }) if name == "tensions[1]"
    ));
    assert!(matches!(
        arc_from_tendon_tensions(&[1.0], &tendons, &body),
        Err(Error::InvalidParameter { name, .. }) if name == "tensions.len()"
    ));
    assert!(matches!(
        arc_from_tendon_tensions(&[30.0; 3], &tendons, &body),
        Err(Error::InvalidParameter { name, .. }) if name == "tensions"
    ));
    assert!(matches!(
        PccTendons::new(&[0.01, -0.01], &[0.0, 1.0]),
        Err(Error::InvalidParameter { name, .. }) if name == "distances[1]"
    ));
    assert!(matches!(
        ElasticSegment::new(0.2, 0.0, None),
        Err(Error::InvalidParameter { name, .. }) if name == "bending_stiffness"
    ));
    assert!(matches!(
        arc_from_tip_with_length(&Vector3::new(0.1, 0.0, 0.1), 0.0),
        Err(Error::InvalidParameter { name, .. }) if name == "length"
    ));
}

#[test]
fn the_misfit_is_what_no_arc_explains() {
    // Four tendons 90° apart at one distance: the displacement map's range is spanned by
    // (1, 1, 1, 1) (elongation) and the two bending columns; (1, -1, 1, -1) is orthogonal to
    // it. Three tendons 120° apart, inextensible: a common change (1, 1, 1) is orthogonal to
    // the bending columns. Added to an arc's displacements, such a change is the misfit
    // (negated), and the arc is unchanged.
    let d = 0.01;
    let s = seg(5.0, 0.8, 0.26);
    for (n, extensible, orthogonal) in [
        (4, true, vec![1.0, -1.0, 1.0, -1.0]),
        (3, false, vec![1.0, 1.0, 1.0]),
    ] {
        let tendons = PccTendons::equally_spaced(n, d, 0.0).unwrap();
        let l0 = if extensible { 0.25 } else { 0.26 };
        let dl = tendon_displacements(&s, &tendons, Some(l0)).unwrap();
        let consistent = tendon_displacement_misfit(&dl, &tendons, l0, extensible).unwrap();
        assert!(consistent.iter().all(|m| m.abs() < 1e-16), "{consistent:?}");
        let eps = 2e-4;
        let measured: Vec<f64> = dl
            .iter()
            .zip(&orthogonal)
            .map(|(a, o)| a + eps * o)
            .collect();
        let misfit = tendon_displacement_misfit(&measured, &tendons, l0, extensible).unwrap();
        for (m, o) in misfit.iter().zip(&orthogonal) {
            assert!((m + eps * o).abs() < 1e-16, "{misfit:?}");
        }
        let back = arc_from_tendon_displacements(&measured, &tendons, l0, extensible).unwrap();
        assert!(max_abs(&(back.pose() - s.pose())) < 1e-13);
    }
    // Displacements no arc has are refused as by the arc itself (were NaN misfits).
    let three = PccTendons::equally_spaced(3, 0.01, 0.0).unwrap();
    for (dl, extensible) in [
        ([1e308; 3], true),
        ([1e307, -1e307, 0.0], false),
        ([1e300, 0.0, 0.0], true),
    ] {
        let arc = arc_from_tendon_displacements(&dl, &three, 0.2, extensible).map(|_| ());
        let misfit = tendon_displacement_misfit(&dl, &three, 0.2, extensible).map(|_| ());
        assert!(
            arc.is_err() && misfit == arc,
            "{dl:?}: {misfit:?} vs {arc:?}"
        );
    }
    // As many tendons as unknowns: every set of displacements is one arc's.
    let two = PccTendons::new(&[0.01, 0.012], &[0.0, 2.0]).unwrap();
    let m = tendon_displacement_misfit(&[0.003, -0.001], &two, 0.3, false).unwrap();
    assert!(m.iter().all(|v| v.abs() < 1e-18), "{m:?}");
}
