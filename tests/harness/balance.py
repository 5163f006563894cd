"""Force and moment balance of a solved rod, integrated here from its returned shape.

Cutting the rod together with its tendons and chambers at ``s`` leaves only the external loads
on the distal part. The wrench carried across the cut is the rod's own (``solution.force`` and
``moment``, world frame, moment about ``p(s)``) plus each tendon's pull ``tau t_i`` at
``p + R r_i`` (``t_i`` the unit tangent of the tendon path, computed here from the returned
strains and the routing) minus each chamber's fluid thrust ``P A d3`` at its centroid (the
fluid pushes normal to the cut, ``d3`` the section normal). It must
equal the tip wrench, the point wrenches beyond ``s`` and the integral of the distributed loads
and gravity over ``[s, L]``, with moment arms from the returned backbone. At ``s = 0`` this is
global balance: the base reaction plus the actuators' pull equals minus the sum of all external
loads (tendon terminations and chamber caps being internal to the cut).

Between mesh nodes the backbone is the cubic Hermite interpolant of ``p`` and ``p' = R v``;
integrals use 3-point Gauss-Legendre on each mesh interval (exact for a cubic backbone times a
quadratic load).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

Vec = np.ndarray


@dataclass
class LoadSpec:
    """External loads in plain numbers (world frame unless ``frame == "body"``)."""

    tip_force: Vec = field(default_factory=lambda: np.zeros(3))
    tip_moment: Vec = field(default_factory=lambda: np.zeros(3))
    tip_frame: str = "world"
    #: (s, force, moment, frame)
    point_loads: list[tuple[float, Vec, Vec, str]] = field(default_factory=list)
    distributed_force: Callable[[float], Vec] | None = None
    distributed_moment: Callable[[float], Vec] | None = None
    gravity: Vec = field(default_factory=lambda: np.zeros(3))
    #: rho A(s) (kg/m) when gravity acts.
    mass_per_length: Callable[[float], float] | None = None


@dataclass
class ChamberSpec:
    """A chamber's centroid offset (body frame, m), area (m^2) and pressure (Pa), extent."""

    offset: Vec
    area: Callable[[float], float]
    pressure: float
    start: float
    end: float | None


@dataclass
class TendonSpec:
    """A tendon's offset ``r(s)`` and its derivative (body frame, m), tension, end."""

    offset: Callable[[float], Vec]
    derivative: Callable[[float], Vec]
    tension: float
    end: float | None


def _hermite(s, p, dp):
    """Evaluator of the cubic Hermite backbone on interval k at local x in [0, 1]."""

    def at(k, x):
        h = s[k + 1] - s[k]
        h00 = 2 * x**3 - 3 * x**2 + 1
        h10 = x**3 - 2 * x**2 + x
        h01 = -2 * x**3 + 3 * x**2
        h11 = x**3 - x**2
        return h00 * p[k] + h10 * h * dp[k] + h01 * p[k + 1] + h11 * h * dp[k + 1]

    return at


GL_X = np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)])
GL_W = np.array([5.0, 8.0, 5.0]) / 9.0


def external_wrench(sol, loads: LoadSpec) -> tuple[np.ndarray, np.ndarray]:
    """The external wrench on ``[s_k, L]`` about ``p(s_k)`` for every node, shape (N, 3) x 2.

    At a break (a node listed twice) the first copy is before the jump and the second after:
    a point load at ``s_j`` counts for the copies before it.
    """
    s = np.asarray(sol.s, dtype=float)
    p = np.asarray(sol.position, dtype=float)
    rot = np.asarray(sol.rotation, dtype=float)
    dp = np.einsum("nij,nj->ni", rot, np.asarray(sol.v, dtype=float))
    n = len(s)
    at = _hermite(s, p, dp)
    # Distributed contributions per interval: integral of f and of p x f + l.
    f_int = np.zeros((n, 3))
    pf_int = np.zeros((n, 3))
    g = np.asarray(loads.gravity, dtype=float)
    for k in range(n - 1):
        h = s[k + 1] - s[k]
        if h <= 0:
            continue
        for x, w in zip(GL_X, GL_W, strict=True):
            xi = 0.5 * (x + 1.0)
            sig = s[k] + xi * h
            f = np.zeros(3)
            if loads.distributed_force is not None:
                f = f + np.asarray(loads.distributed_force(sig), dtype=float)
            if loads.mass_per_length is not None and np.any(g):
                f = f + loads.mass_per_length(sig) * g
            lm = np.zeros(3)
            if loads.distributed_moment is not None:
                lm = np.asarray(loads.distributed_moment(sig), dtype=float)
            pk = at(k, xi)
            f_int[k] += 0.5 * h * w * f
            pf_int[k] += 0.5 * h * w * (np.cross(pk, f) + lm)
    # Cumulative from the tip: F(s_k) = sum over intervals >= k.
    f_tail = np.cumsum(f_int[::-1], axis=0)[::-1]
    pf_tail = np.cumsum(pf_int[::-1], axis=0)[::-1]
    tip_r = rot[-1]
    ft = np.asarray(loads.tip_force, dtype=float)
    mt = np.asarray(loads.tip_moment, dtype=float)
    if loads.tip_frame == "body":
        ft, mt = tip_r @ ft, tip_r @ mt
    # Point loads: world force and moment at their position.
    points = []
    for sp, fp, mp, frame in loads.point_loads:
        j = _last_before(s, sp)
        r_j = rot[j + 1] if j + 1 < n else rot[j]
        fw = np.asarray(fp, dtype=float)
        mw = np.asarray(mp, dtype=float)
        if frame == "body":
            fw, mw = r_j @ fw, r_j @ mw
        pos = p[j + 1] if j + 1 < n else p[j]
        points.append((j, pos, fw, mw))
    force = np.zeros((n, 3))
    moment = np.zeros((n, 3))
    for k in range(n):
        fk = ft + f_tail[k] if k < n - 1 else ft.copy()
        mk = np.cross(p[-1] - p[k], ft) + mt
        if k < n - 1:
            mk = mk + pf_tail[k] - np.cross(p[k], f_tail[k])
        for j, pos, fw, mw in points:
            if k <= j:
                fk = fk + fw
                mk = mk + np.cross(pos - p[k], fw) + mw
        force[k], moment[k] = fk, mk
    return force, moment


def _last_before(s: np.ndarray, sp: float) -> int:
    """Index of the last node copy at or before the point load's jump (its 'before' copy)."""
    idx = np.nonzero(np.isclose(s, sp, rtol=0, atol=1e-12 * max(1.0, s[-1])))[0]
    if len(idx):
        return int(idx[0])
    return int(np.searchsorted(s, sp) - 1)


def actuator_wrench(sol, tendons: Sequence[TendonSpec], chambers: Sequence[ChamberSpec] = ()):
    """The tendons' pull minus the chambers' thrust across every section, world, about p(s)."""
    s = np.asarray(sol.s, dtype=float)
    rot = np.asarray(sol.rotation, dtype=float)
    v = np.asarray(sol.v, dtype=float)
    u = np.asarray(sol.u, dtype=float)
    n = len(s)
    force, moment = np.zeros((n, 3)), np.zeros((n, 3))
    length = s[-1]
    # Node k carries actuator j if it lies inside its span; at the end the proximal copy does.
    first_copy = np.ones(n, dtype=bool)
    first_copy[1:] = s[1:] != s[:-1]

    def inside(k, start, end):
        end = length if end is None else end
        if s[k] < start or s[k] > end:
            return False
        if s[k] == end and end < length:
            return first_copy[k]
        if s[k] == start and start > 0:
            return not first_copy[k] or (k + 1 < n and s[k + 1] != s[k])
        return True

    def pull(k, r, dr, size, normal=False):
        r3, dr3 = np.array([r[0], r[1], 0.0]), np.array([dr[0], dr[1], 0.0])
        tangent = rot[k][:, 2] if normal else rot[k] @ (v[k] + np.cross(u[k], r3) + dr3)
        tangent = tangent / np.linalg.norm(tangent)
        return size * tangent, np.cross(rot[k] @ r3, size * tangent)

    for k in range(n):
        for t in tendons:
            if t.tension and inside(k, 0.0, t.end):
                f, m = pull(k, t.offset(s[k]), t.derivative(s[k]), t.tension)
                force[k] += f
                moment[k] += m
        for c in chambers:
            if c.pressure and inside(k, c.start, c.end):
                f, m = pull(k, c.offset, np.zeros(2), c.pressure * c.area(s[k]), normal=True)
                force[k] -= f
                moment[k] -= m
    return force, moment


def balance_error(
    sol,
    loads: LoadSpec,
    scale_force: float,
    length: float,
    tendons: Sequence[TendonSpec] = (),
    chambers: Sequence[ChamberSpec] = (),
) -> tuple[float, float]:
    """Largest mismatch between the wrench carried across the sections (rod plus actuators) and
    the external loads beyond them, relative to ``scale_force`` (N) and ``scale_force *
    length`` (N m): (at the base, anywhere along the rod)."""
    ext_f, ext_m = external_wrench(sol, loads)
    act_f, act_m = actuator_wrench(sol, tendons, chambers)
    nf = np.asarray(sol.force, dtype=float) + act_f
    nm = np.asarray(sol.moment, dtype=float) + act_m
    err = np.maximum(
        np.max(np.abs(nf - ext_f), axis=1) / scale_force,
        np.max(np.abs(nm - ext_m), axis=1) / (scale_force * length),
    )
    return float(err[0]), float(np.max(err))
