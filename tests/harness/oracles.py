"""Independent oracles, written from mechanics only (no softrod code).

- :func:`bisshopp_drucker`: the tip of an inextensible cantilever under a transverse dead tip
  load, from the elliptic-integral closed form (Bisshopp & Drucker 1945), parametrised by the
  complementary parameter ``1 - k^2`` so that it stays exact up to ``P L^2 / EI = 1000`` and
  beyond.
- :func:`elastica_paths`: the planar elastica under an oblique dead tip load, by multiple
  shooting with a fine fixed-step RK4 and Newton, continued in load from the unloaded rod (the
  branch connected to it).
- :func:`castigliano_arc`: the 6x6 compliance of a circular arc by Castigliano's theorem,
  integrated with composite Gauss-Legendre quadrature.
- :func:`greenhill_constant`: the self-weight buckling constant from the first zero of the
  Bessel function ``J_{-1/3}``.

Conventions (those of ``docs/compliance.md``): twists ``[translation; rotation]``, wrenches
``[force; moment]``, world components, the wrench applied at the node's position.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import optimize, special

# ----------------------------------------------------------------------------- small helpers


def skew(v: np.ndarray) -> np.ndarray:
    """The cross-product matrix of a 3-vector."""
    x, y, z = v
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def rotation_vector(r: np.ndarray) -> np.ndarray:
    """The rotation vector (axis times angle, rad) of a rotation matrix (log map)."""
    w = 0.5 * np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    s = np.linalg.norm(w)
    c = 0.5 * (np.trace(r) - 1.0)
    angle = math.atan2(s, c)
    if s < 1e-300:
        return np.zeros(3)
    if angle < 1.0:
        return w * (angle / s)
    # Far from the identity: the axis from the symmetric part is better conditioned.
    b = 0.5 * (r + r.T) - c * np.eye(3)
    k = int(np.argmax(np.diag(b)))
    axis = b[:, k] / math.sqrt(max(b[k, k], 1e-300))
    if np.dot(axis, w) < 0:
        axis = -axis
    return axis / np.linalg.norm(axis) * angle


def rotation_from_vector(w: np.ndarray) -> np.ndarray:
    """Rodrigues' formula: the rotation matrix of a rotation vector (rad)."""
    w = np.asarray(w, dtype=float)
    angle = float(np.linalg.norm(w))
    if angle < 1e-300:
        return np.eye(3)
    k = skew(w / angle)
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def block_relative_error(got: np.ndarray, exact: np.ndarray) -> float:
    """Largest entry error of a 6x6 matrix, each 3x3 block relative to the block's largest
    exact entry (blocks whose exact entries are all zero: relative to the whole matrix's)."""
    got, exact = np.asarray(got, float), np.asarray(exact, float)
    whole = np.max(np.abs(exact))
    worst = 0.0
    for i in (0, 3):
        for j in (0, 3):
            e = exact[i : i + 3, j : j + 3]
            scale = np.max(np.abs(e))
            if scale < 1e-12 * whole:
                scale = whole
            worst = max(worst, float(np.max(np.abs(got[i : i + 3, j : j + 3] - e)) / scale))
    return worst


def gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [-1, 1]."""
    return np.polynomial.legendre.leggauss(n)


# ----------------------------------------------------------------------------- elastica


def bisshopp_drucker(alpha: float) -> tuple[float, float, float]:
    """Tip of an inextensible cantilever of length 1 under a transverse dead tip load.

    Bisshopp & Drucker (1945): with ``alpha = P L^2 / EI`` and ``k`` solving
    ``K(k) - F(phi1, k) = sqrt(alpha)``, ``sin(phi1) = 1 / (k sqrt 2)``, the tip deflection is
    ``1 - 2 (E(k) - E(phi1, k)) / sqrt(alpha)`` and its axial projection
    ``sqrt(2 (2 k^2 - 1) / alpha)``. Solved for ``p = 1 - k^2`` on a log scale: at
    ``alpha = 1000``, ``p`` is about 1e-27, below the resolution of ``k`` itself.

    Returns:
        (transverse deflection, axial projection, tip angle in rad), lengths per L.
    """
    root = math.sqrt(alpha)

    def parts(logp: float):
        p = math.exp(logp)
        m = 1.0 - p
        k = math.sqrt(m)
        phi1 = math.asin(min(1.0, 1.0 / (k * math.sqrt(2.0))))
        return p, m, k, phi1

    def g(logp: float) -> float:
        p, m, _, phi1 = parts(logp)
        return special.ellipkm1(p) - special.ellipkinc(phi1, m) - root

    logp = optimize.brentq(g, math.log(1e-300), math.log(0.5 - 1e-15), xtol=1e-15, rtol=1e-15)
    _, m, _, phi1 = parts(logp)
    e_full = special.ellipe(m)
    delta = 1.0 - 2.0 * (e_full - special.ellipeinc(phi1, m)) / root
    x = math.sqrt(2.0 * (2.0 * m - 1.0) / alpha)
    # Tip angle from the first integral theta'^2 = 2 alpha (sin theta_L - sin theta) and the
    # base moment theta'(0) = alpha x: sin(theta_L) = alpha x^2 / 2 = 2 k^2 - 1.
    tip_angle = math.asin(min(1.0, 2.0 * m - 1.0))
    return delta, x, tip_angle


def _elastica_segments(theta0, omega0, alpha, beta, length, steps):
    """RK4 over every shooting segment at once, with the 2x2 sensitivity of (theta, omega).

    Arrays are (n_directions, n_segments); ``beta`` is (n_directions, 1). Returns end
    (theta, omega), increments (dx, dz) and the sensitivity (..., 2, 2).
    """
    h = length / steps
    shape = theta0.shape
    y = np.stack([theta0, omega0, np.zeros(shape), np.zeros(shape)], axis=-1)
    phi = np.zeros((*shape, 2, 2))
    phi[..., 0, 0] = 1.0
    phi[..., 1, 1] = 1.0

    def f(y, phi):
        th, om = y[..., 0], y[..., 1]
        dy = np.stack([om, alpha * np.sin(th - beta), np.sin(th), np.cos(th)], axis=-1)
        a = np.zeros((*shape, 2, 2))
        a[..., 0, 1] = 1.0
        a[..., 1, 0] = alpha * np.cos(th - beta)
        return dy, a @ phi

    for _ in range(steps):
        k1, p1 = f(y, phi)
        k2, p2 = f(y + 0.5 * h * k1, phi + 0.5 * h * p1)
        k3, p3 = f(y + 0.5 * h * k2, phi + 0.5 * h * p2)
        k4, p4 = f(y + h * k3, phi + h * p3)
        y = y + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        phi = phi + h / 6.0 * (p1 + 2 * p2 + 2 * p3 + p4)
    return y[..., 0], y[..., 1], y[..., 2], y[..., 3], phi


def elastica_paths(
    betas,
    alphas,
    *,
    segments: int = 48,
    steps: int = 48,
    max_ratio: float = 1.08,
) -> dict[str, np.ndarray]:
    """Planar inextensible elastica under a dead tip load, continued in load from zero.

    The rod has length 1, is clamped at the origin with its tangent along +z, and the load of
    dimensionless size ``alpha = P L^2 / EI`` points at angle ``beta`` from +z toward +x. With
    ``theta`` the tangent angle (from z toward x), ``theta'' = alpha sin(theta - beta)``,
    ``theta(0) = 0``, ``theta'(1) = 0``, ``x' = sin theta``, ``z' = cos theta``. Multiple
    shooting (``segments`` segments of ``steps`` RK4 steps each, Newton on all unknowns with the
    exact sensitivity) keeps the problem well conditioned at large loads; continuation starts
    from the straight unloaded rod and never multiplies the load by more than ``max_ratio`` per
    step, so it follows the branch connected to the unloaded rod.

    Args:
        betas: Load angles (rad), shape (D,); not exactly pi (the bifurcation).
        alphas: Increasing positive loads at which to report, shape (A,).

    Returns:
        ``x``, ``z``, ``tip_angle`` (each (D, A)) and ``residual`` (largest final residual).
    """
    betas = np.asarray(betas, dtype=float)
    alphas = np.asarray(alphas, dtype=float)
    d, m = len(betas), segments
    n = 2 * m - 1
    beta = betas[:, None]
    length = 1.0 / m
    # Unknowns: omega_0, then (theta_j, omega_j) for j = 1..M-1.
    u = np.zeros((d, n))
    u_prev, a_prev = u.copy(), 0.0
    out = {k: np.zeros((d, len(alphas))) for k in ("x", "z", "tip_angle")}
    worst = 0.0
    a_cur = 0.0

    def unpack(u):
        theta = np.concatenate([np.zeros((d, 1)), u[:, 1::2]], axis=1)
        omega = u[:, 0::2]
        return theta, omega

    def newton(u, alpha):
        for _ in range(30):
            theta, omega = unpack(u)
            th_e, om_e, dx, dz, phi = _elastica_segments(theta, omega, alpha, beta, length, steps)
            r = np.zeros((d, n))
            r[:, 0 : n - 1 : 2] = th_e[:, :-1] - theta[:, 1:]
            r[:, 1 : n - 1 : 2] = om_e[:, :-1] - omega[:, 1:]
            r[:, n - 1] = om_e[:, -1]
            scale = max(1.0, math.sqrt(alpha))
            res = float(np.max(np.abs(r))) / scale
            if res < 1e-13:
                return u, res, (dx, dz, th_e)
            jac = np.zeros((d, n, n))
            for j in range(m):
                rows = [2 * j, 2 * j + 1] if j < m - 1 else [n - 1]
                prow = [0, 1] if j < m - 1 else [1]
                cols = [2 * j - 1, 2 * j] if j > 0 else [0]
                pcol = [0, 1] if j > 0 else [1]
                for ri, pr in zip(rows, prow, strict=True):
                    for ci, pc in zip(cols, pcol, strict=True):
                        jac[:, ri, ci] = phi[:, j, pr, pc]
                    if j < m - 1:
                        jac[:, ri, 2 * j + 1 + (ri - 2 * j)] = -1.0
            u = u - np.linalg.solve(jac, r[..., None])[..., 0]
            if not np.all(np.isfinite(u)):
                break
        return None, math.inf, None

    for k, target in enumerate(alphas):
        while a_cur < target:
            step_to = min(target, max(a_cur * max_ratio, 1e-3) if a_cur > 0 else target)
            while True:
                if a_cur > 0 and a_cur != a_prev:
                    w = (step_to - a_cur) / (a_cur - a_prev)
                    guess = u + w * (u - u_prev)
                else:
                    guess = u
                new, res, ends = newton(guess, step_to)
                if new is not None:
                    break
                step_to = a_cur + 0.5 * (step_to - a_cur)
                if step_to - a_cur < 1e-12 * max(1.0, a_cur):
                    raise RuntimeError(f"elastica continuation stalled at alpha = {a_cur}")
            u_prev, a_prev = u, a_cur
            u, a_cur = new, step_to
        dx, dz, th_e = ends
        out["x"][:, k] = dx.sum(axis=1)
        out["z"][:, k] = dz.sum(axis=1)
        out["tip_angle"][:, k] = th_e[:, -1]
        worst = max(worst, res)
    out["residual"] = np.array(worst)
    return out


def fibonacci_directions(n: int) -> np.ndarray:
    """``n`` unit vectors spread over the sphere (golden-angle spiral); none exactly +-z."""
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    phi = i * math.pi * (3.0 - math.sqrt(5.0))
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


# ----------------------------------------------------------------------------- compliance


def castigliano_arc(kappa: float, s: float, stiffness) -> np.ndarray:
    """Compliance at arc length ``s`` of a stress-free circular arc (world frame at the node).

    The arc starts at the origin with its tangent along +z and bends toward +x (body curvature
    ``kappa`` about body y): ``R(t) = Ry(kappa t)``,
    ``p(t) = ((1 - cos kappa t) / kappa, 0, sin(kappa t) / kappa)``. A wrench ``[F; M]`` at
    ``p(s)`` loads the section at ``t`` with body force ``R^T F`` and body moment
    ``R^T (M + (p(s) - p(t)) x F)``; Castigliano's theorem gives
    ``C = integral_0^s B^T diag(1 / stiffness) B dt`` (32 panels of 24-point Gauss-Legendre).

    Args:
        kappa: Curvature (1/m); 0 is the straight rod.
        s: Arc length of the node (m).
        stiffness: ``(k G A, k G A, E A, E Ix, E Iy, G J)``; ``inf`` for a rigid mode.
    """

    def pos(t):
        if abs(kappa) < 1e-14:
            return np.array([0.0, 0.0, t])
        a = kappa * t
        return np.array([(1.0 - math.cos(a)) / kappa, 0.0, math.sin(a) / kappa])

    def rot(t):
        a = kappa * t
        c, sn = math.cos(a), math.sin(a)
        return np.array([[c, 0.0, sn], [0.0, 1.0, 0.0], [-sn, 0.0, c]])

    cinv = np.diag([0.0 if math.isinf(k) else 1.0 / k for k in stiffness])
    x, w = gauss_legendre(24)
    panels = 32
    ps = pos(s)
    c = np.zeros((6, 6))
    for k in range(panels):
        a, b = s * k / panels, s * (k + 1) / panels
        for xi, wi in zip(x, w, strict=True):
            t = 0.5 * (a + b) + 0.5 * (b - a) * xi
            rt = rot(t).T
            b_map = np.zeros((6, 6))
            b_map[:3, :3] = rt
            b_map[3:, :3] = rt @ skew(ps - pos(t))
            b_map[3:, 3:] = rt
            c += b_map.T @ cinv @ b_map * (0.5 * (b - a) * wi)
    return c


def straight_cantilever(length: float, stiffness) -> np.ndarray:
    """Closed-form Timoshenko tip compliance of a straight cantilever along +z (world frame)."""
    ksx, ksy, ea, eix, eiy, gj = stiffness
    c = np.zeros((6, 6))
    c[0, 0] = length**3 / (3 * eiy) + length / ksx
    c[1, 1] = length**3 / (3 * eix) + length / ksy
    c[2, 2] = length / ea
    c[3, 3] = length / eix
    c[4, 4] = length / eiy
    c[5, 5] = length / gj
    c[0, 4] = c[4, 0] = length**2 / (2 * eiy)
    c[1, 3] = c[3, 1] = -(length**2) / (2 * eix)
    return c


# ----------------------------------------------------------------------------- self-weight


def greenhill_constant() -> tuple[float, float]:
    """Greenhill's self-weight column: ``l_c = C (EI / q)^(1/3)``.

    The buckled shape of an upright clamped column of weight ``q`` per length satisfies
    ``EI theta'' + q (l - s) theta = 0`` (``theta`` the tilt, ``s`` up from the clamp). With
    ``x = l - s`` the solution with no moment at the free top (``d theta / dx = 0`` at
    ``x = 0``) is ``sqrt(x) J_{-1/3}(2/3 sqrt(q/EI) x^{3/2})``; the clamp ``theta = 0`` at
    ``x = l`` gives ``J_{-1/3}(2/3 sqrt(q l^3 / EI)) = 0``, so
    ``l_c = (9 j^2 EI / (4 q))^(1/3)`` with ``j`` the first zero of ``J_{-1/3}``.

    Returns:
        (the constant C, the zero j).
    """
    j = optimize.brentq(lambda x: special.jv(-1.0 / 3.0, x), 1.0, 3.0, xtol=1e-15, rtol=1e-15)
    return (9.0 * j * j / 4.0) ** (1.0 / 3.0), j
