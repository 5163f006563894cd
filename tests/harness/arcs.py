"""Compliance of stress-free circular arcs up to 2 pi against Castigliano's closed form.

Two ways to make an arc of angle ``theta`` with a rod of length L: a precurved rod
(``rest_curvature = (0, theta / L, 0)``, no load) and a straight rod under a pure world tip
moment ``(0, EI theta / L, 0)``. Both lie in the x-z plane and bend toward +x, the geometry of
:func:`oracles.castigliano_arc`; with a linear material the element compliance is the same
constant in both, so the integrated compliance (``softrod.compliance``) equals Castigliano's.
For the unloaded precurved rod the tangent compliance equals it too (no geometric stiffness).

The error is :func:`oracles.block_relative_error` of the 6x6 tip compliance (world frame).
"""

from __future__ import annotations

import math

import numpy as np

import softrod

from .oracles import block_relative_error, castigliano_arc

LENGTH, RADIUS, MODULUS, POISSON, SHEAR_COEFFICIENT = 0.2, 0.005, 1e6, 0.45, 0.9
ANGLES = (math.pi / 2, math.pi, 1.5 * math.pi, 2 * math.pi)
RTOLS = (1e-6, 1e-7, 1e-8, 1e-9, 1e-10)


def stiffness() -> tuple[float, ...]:
    g = MODULUS / (2 * (1 + POISSON))
    a = math.pi * RADIUS**2
    i = math.pi * RADIUS**4 / 4
    ks = SHEAR_COEFFICIENT * g * a
    return (ks, ks, MODULUS * a, MODULUS * i, MODULUS * i, g * 2 * i)


def _rod(kappa: float) -> softrod.Rod:
    return softrod.Rod(
        LENGTH,
        softrod.CircularSection(RADIUS),
        softrod.LinearElastic(MODULUS, POISSON),
        rest_curvature=(0.0, kappa, 0.0) if kappa else None,
        shear_coefficient=SHEAR_COEFFICIENT,
    )


def solve(case: str, theta: float, **options) -> softrod.StaticsSolution:
    """The arc of angle ``theta``: ``case`` is ``"precurved"`` or ``"moment"``."""
    kappa = theta / LENGTH
    if case == "precurved":
        return softrod.solve_statics(_rod(kappa), [], None, **options)
    ei = stiffness()[3]
    loads = softrod.Loads(tip_moment=(0.0, ei * kappa, 0.0))
    # A dead moment has no potential: beyond an arc between pi/2 and 0.8 pi its second-order
    # work is negative and the solve warns (docs/stability.md); the arcs are compliance oracles.
    options.setdefault("on_unstable", "ignore")
    return softrod.solve_statics(_rod(0.0), [], loads, **options)


def exact(theta: float, s: float = LENGTH) -> np.ndarray:
    return castigliano_arc(theta / LENGTH, s, stiffness())


def adaptive_options(rtol: float) -> dict:
    """The adaptive integrator at ``rtol``, with ``atol`` two decades below it (m, rad, N):
    the relative tolerance is the one in control."""
    return {"integrator": "adaptive", "rtol": rtol, "atol": 1e-2 * rtol}


def errors(case: str, theta: float, kind: str = "integrated", **options) -> float:
    """Block-relative error of the tip compliance (``kind`` integrated or tangent)."""
    sol = solve(case, theta, **options)
    if kind == "integrated":
        got = softrod.compliance(sol).tip_world
    else:
        got = softrod.tangent_compliance(sol, "tension").world
    return block_relative_error(np.asarray(got), exact(theta))
