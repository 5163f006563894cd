"""Random PCC statics configurations: valid inputs must solve (no spurious errors).

Each configuration draws a robot (1 to 3 segments of 0.1 to 0.25 m, a 0.7 mm NiTi backbone,
extensible or not, three tendons per segment at 10 mm, turned by a random angle) and an
actuation and load (tensions U[0, 4] N, a world tip force of magnitude U[0, 0.3] N in a random
direction, in half of them a tip moment up to 2 mN m), all valid. Outcomes:

- ``ok``: converged, and the reported tip pose equals the chain of the reported arcs computed
  here (``R = Rz(phi) Ry(kappa l) Rz(-phi)``, ``p = ((1 - cos)/kappa cos phi, ..., sin/kappa)``)
  to 1e-12 m;
- ``tip-mismatch``: converged but the tip disagrees with its own arcs;
- ``parameter-error``: a ParameterError on valid input (a spurious error, e.g. an arc length
  outside ``[0, length]`` by round-off);
- ``convergence-error`` / ``other-error``.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

import softrod
from softrod import pcc

RADIUS, MODULUS = 0.7e-3, 54e9


def arc_transform(kappa: float, phi: float, length: float) -> np.ndarray:
    """Webster-Jones arc with the trailing Rz(-phi) (no twist), written out here."""
    a = kappa * length
    c, s = math.cos(phi), math.sin(phi)
    rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    ry = np.array(
        [[math.cos(a), 0.0, math.sin(a)], [0.0, 1.0, 0.0], [-math.sin(a), 0.0, math.cos(a)]]
    )
    if abs(kappa) * length < 1e-12:
        p = np.array([0.0, 0.0, length])
    else:
        r = (1.0 - math.cos(a)) / kappa
        p = np.array([r * c, r * s, math.sin(a) / kappa])
    t = np.eye(4)
    t[:3, :3] = rz @ ry @ rz.T
    t[:3, 3] = p
    return t


def chain_tip(arcs: np.ndarray) -> np.ndarray:
    t = np.eye(4)
    for kappa, phi, length in arcs:
        t = t @ arc_transform(kappa, phi, length)
    return t


@dataclass
class Record:
    index: int
    outcome: str
    detail: str = ""


@dataclass
class Run:
    records: list[Record] = field(default_factory=list)

    @property
    def counts(self) -> Counter:
        return Counter(r.outcome for r in self.records)


def configuration(rng: np.random.Generator):
    n_seg = int(rng.integers(1, 4))
    lengths = rng.uniform(0.1, 0.25, n_seg)
    extensible = bool(rng.integers(0, 2))
    robot = pcc.Robot.solid_circle(lengths, RADIUS, MODULUS, extensible=extensible)
    base = rng.uniform(0, 2 * math.pi)
    angles = [base + k * 2 * math.pi / 3 for k in range(3)]
    for k in range(n_seg):
        robot = robot.with_tendons(k, [0.01] * 3, angles)
    tensions = rng.uniform(0.0, 4.0, 3 * n_seg)
    d = rng.normal(size=3)
    force = d / np.linalg.norm(d) * rng.uniform(0.0, 0.3)
    moment = rng.normal(size=3) * 1e-3 if rng.uniform() < 0.5 else np.zeros(3)
    return robot, tensions, force, moment


def run(n: int = 10_000, seed: int = 77) -> Run:
    rng = np.random.default_rng(seed)
    out = Run()
    for i in range(n):
        robot, tensions, force, moment = configuration(rng)
        try:
            sol = pcc.solve(robot, tensions, tip_force=force, tip_moment=moment)
        except softrod.ParameterError as exc:
            out.records.append(Record(i, "parameter-error", str(exc)))
            continue
        except softrod.ConvergenceError as exc:
            out.records.append(Record(i, "convergence-error", str(exc)))
            continue
        except Exception as exc:
            out.records.append(Record(i, "other-error", f"{type(exc).__name__}: {exc}"))
            continue
        tip = chain_tip(np.asarray(sol.arcs))
        err = float(np.linalg.norm(tip[:3, 3] - np.asarray(sol.tip_position)))
        rerr = float(np.max(np.abs(tip[:3, :3] - np.asarray(sol.tip_pose)[:3, :3])))
        if sol.converged and err < 1e-12 and rerr < 1e-12:
            out.records.append(Record(i, "ok"))
        else:
            out.records.append(Record(i, "tip-mismatch", f"{err:.2e} m, {rerr:.2e}"))
    return out
