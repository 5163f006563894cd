"""Random loaded two-segment NiTi configurations: stability of the returned equilibria.

The robot is ``examples/robots/niti_two_segment.toml`` (RK4, ``steps = 50``). Each
configuration draws the six tensions from U[0, 4] N and a world tip force of magnitude
U[0, 0.3] N along a direction uniform on the sphere, and is solved cold with the defaults.

Two stability oracles, neither using a stability flag of the solver:

1. the smallest eigenvalue of the symmetric part of the tip tangent stiffness
   ``inv(tangent_compliance(sol, "tension").world)`` (tendons at fixed tension, dead loads),
   made dimensionless as ``D K D / (EI / L)`` with ``D = diag(L, L, L, 1, 1, 1)``;
2. perturbation re-solves: the tip wrench is perturbed by ``+-h`` along each of the six axes
   and re-solved warm-started from the answer; the central-difference compliance gives the same
   eigenvalue without the tangent code. Negative: some small tip force moves the tip against
   itself, an equilibrium that does not return.

An equilibrium is unstable when oracle 1 is below ``-MARGIN_TOL``. It is *reported as stable*
when the solver returned it converged without a ``stable`` attribute, with ``stable`` True, and
without a warning.
"""

from __future__ import annotations

import math
import warnings
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

import softrod

from .oracles import rotation_vector

#: Dimensionless stiffness eigenvalue below which an equilibrium counts as unstable.
MARGIN_TOL = 1e-8
ISSUE_TENSIONS = (0.8178, 1.1292, 3.5497, 1.0505, 3.783, 3.0457)
ISSUE_FORCE = (0.0109, 0.249, -0.153)


def robot() -> softrod.Robot:
    return softrod.load_robot(softrod.examples.path("niti_two_segment"))


def scales(r: softrod.Robot) -> tuple[float, float]:
    """(L, EI) of the robot's rod, from its description."""
    spec = r.spec.rod
    radius = spec.section.radius
    return r.rod.length, spec.material.youngs_modulus * math.pi * radius**4 / 4


def configurations(n: int, seed: int = 2024) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    tensions = rng.uniform(0.0, 4.0, size=(n, 6))
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    forces = d * rng.uniform(0.0, 0.3, size=(n, 1))
    return tensions, forces


def margin(compliance: np.ndarray, length: float, ei: float) -> float:
    """Smallest eigenvalue of sym(D K D) / (EI / L), K the inverse of a 6x6 compliance."""
    k = np.linalg.inv(compliance)
    d = np.diag([length] * 3 + [1.0] * 3)
    kd = d @ k @ d / (ei / length)
    return float(np.linalg.eigvalsh(0.5 * (kd + kd.T))[0])


def fd_compliance(r: softrod.Robot, tendons, force, sol, length: float, ei: float) -> np.ndarray:
    """Central-difference tip compliance (world) from warm-started re-solves."""
    h_f, h_m = 1e-4 * ei / length**2, 1e-4 * ei / length
    opts = {"steps": r.solver.get("steps", 40), "tolerance": 1e-13, "warm_start": sol}
    cols = []
    for k in range(6):
        tw = []
        for sgn in (1.0, -1.0):
            f = np.array(force, dtype=float)
            m = np.zeros(3)
            if k < 3:
                f[k] += sgn * h_f
            else:
                m[k - 3] += sgn * h_m
            s = softrod.solve_statics(
                r.rod, tendons, softrod.Loads(tip_force=tuple(f), tip_moment=tuple(m)), **opts
            )
            tw.append((np.asarray(s.tip_position), np.asarray(s.tip_rotation)))
        (p1, r1), (p2, r2) = tw
        h = h_f if k < 3 else h_m
        dtheta = rotation_vector(r1 @ r2.T)
        cols.append(np.concatenate([(p1 - p2) / (2 * h), dtheta / (2 * h)]))
    return np.array(cols).T


@dataclass
class Record:
    index: int
    outcome: str
    margin: float = math.nan
    margin_fd: float = math.nan
    stable: bool | None = None
    warned: bool = False
    fields: bool = True
    error: str = ""
    tip_y: float = math.nan


@dataclass
class Run:
    records: list[Record] = field(default_factory=list)

    @property
    def counts(self) -> Counter:
        return Counter(r.outcome for r in self.records)

    def unstable(self) -> list[Record]:
        return [r for r in self.records if r.outcome == "converged" and r.margin < -MARGIN_TOL]

    def unstable_reported_stable(self) -> list[Record]:
        return [r for r in self.unstable() if r.stable is not False and not r.warned]

    def stable_reported_unstable(self) -> list[Record]:
        return [
            r
            for r in self.records
            if r.outcome == "converged" and r.margin > MARGIN_TOL and r.stable is False
        ]

    def oracle_disagreements(self) -> list[Record]:
        return [
            r
            for r in self.records
            if r.outcome == "converged"
            and abs(r.margin) > 1e-6
            and np.sign(r.margin) != np.sign(r.margin_fd)
        ]


def solve_one(r, tensions, force, index: int = 0, fd: bool = True) -> Record:
    length, ei = scales(r)
    tendons = [t.with_tension(float(x)) for t, x in zip(r.tendons, tensions, strict=True)]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            sol = softrod.solve_statics(
                r.rod, tendons, softrod.Loads(tip_force=tuple(force)), **r.solver
            )
        except softrod.ConvergenceError as exc:
            fields = all(hasattr(exc, f) for f in ("iterations", "residual", "load_factor"))
            return Record(index, "convergence-error", fields=fields, error=str(exc))
        except Exception as exc:
            return Record(index, "other-error", error=f"{type(exc).__name__}: {exc}")
    warned = any("stab" in str(w.message).lower() for w in caught)
    if not sol.converged:
        return Record(index, "not-converged-returned")
    c = softrod.tangent_compliance(sol, "tension").world
    rec = Record(
        index,
        "converged",
        margin=margin(c, length, ei),
        stable=getattr(sol, "stable", None),
        warned=warned,
        tip_y=float(sol.tip_position[1]),
    )
    if fd:
        rec.margin_fd = margin(fd_compliance(r, tendons, force, sol, length, ei), length, ei)
    return rec


def run(n: int = 10_000, seed: int = 2024, fd: bool = True) -> Run:
    r = robot()
    tensions, forces = configurations(n, seed)
    out = Run()
    for i in range(n):
        out.records.append(solve_one(r, tensions[i], forces[i], i, fd))
    return out
