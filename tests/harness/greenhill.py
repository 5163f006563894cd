"""Self-weight column (Greenhill): an upright uniform rod under its own weight.

A clamped rod standing up along +z under gravity ``(0, 0, -g)`` is straight and stable below
``l_c = C (EI / q)^(1/3)`` (``q = rho A g``; ``C`` from the first zero of ``J_{-1/3}``,
:func:`oracles.greenhill_constant`) and the straight equilibrium is unstable above it. The rod
is Ecoflex-like (E = 100 kPa, rho = 1070 kg/m^3, 120 mm long, inextensible as in Greenhill's
column); its radius sets ``L / l_c``.
"""

from __future__ import annotations

import math

import numpy as np

import softrod

from .oracles import greenhill_constant

LENGTH, MODULUS, DENSITY, GRAVITY = 0.12, 100e3, 1070.0, 9.81


def radius_for(ratio: float) -> float:
    """The radius that makes ``L / l_c = ratio``: ``EI / q = E r^2 / (4 rho g)``."""
    c, _ = greenhill_constant()
    lc = LENGTH / ratio
    return math.sqrt(4 * DENSITY * GRAVITY * (lc / c) ** 3 / MODULUS)


def rod(ratio: float, inextensible: bool = True) -> softrod.Rod:
    return softrod.Rod(
        LENGTH,
        softrod.CircularSection(radius_for(ratio)),
        softrod.LinearElastic(MODULUS, 0.5),
        inextensible=inextensible,
        density=DENSITY,
    )


def loads() -> softrod.Loads:
    return softrod.Loads(gravity=(0.0, 0.0, -GRAVITY))


def measure(ratio: float, inextensible: bool = True, **options) -> dict:
    """Solves the column; reports straightness, the flag and the lateral tip compliance.

    ``lateral`` is the smallest eigenvalue of the lateral force-to-translation block of the
    symmetric tangent tip compliance (m/N): positive for a stable straight column, negative
    past the critical length (the first buckling mode has crossed zero stiffness).
    """
    sol = softrod.solve_statics(rod(ratio, inextensible), [], loads(), **options)
    tip = np.asarray(sol.tip_position)
    c = np.asarray(softrod.tangent_compliance(sol, "tension").world)
    lateral = float(np.linalg.eigvalsh(0.5 * (c[:2, :2] + c[:2, :2].T))[0])
    return {
        "ratio": ratio,
        "converged": sol.converged,
        "straight": bool(np.hypot(tip[0], tip[1]) < 1e-9 * LENGTH),
        "tip_offset": float(np.hypot(tip[0], tip[1])),
        "stable": getattr(sol, "stable", None),
        "margin": getattr(sol, "stability_margin", None),
        "lateral": lateral,
    }
