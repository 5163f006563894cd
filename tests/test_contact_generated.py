"""Generated soft arms bent by a tendon onto a cylinder or a sphere across their path.

Each case draws a soft rod (L 0.2-0.4 m, radius 3-8 mm, E 0.3-5 MPa, nu 0.45), a tendon at
a constant offset of 0.4-0.9 radii, and an obstacle (cylinder across the bending plane or
sphere, radius 10-50 mm) 0.5-10 mm clear of the straight rod, at 30-70 % of the length. The
tension is set by the ratio of the tendon's free curvature ``T d / EI`` to the curvature of a
rod lying on the obstacle, ``1 / (R_obstacle + r)``.

Oracles on every converged solution: no node inside the obstacle by more than 1e-9 m, every
normal force pushing, the base wrench equal to the contact forces' resultant and moment (the
tendon's loads are internal to the arm) to 1e-10 of the tension, finite shapes. Leaning arms
(ratio up to 0.85) must converge; arms that would wrap (ratio up to 1.3) converge or raise a
named ``ConvergenceError`` (docs/contact.md, "Lying on the cylinder: belts").
"""

import time
import warnings

import numpy as np
import pytest

import softrod as sr


def _case(rng, ratio):
    length = rng.uniform(0.2, 0.4)
    r = rng.uniform(0.003, 0.008)
    young = 10 ** rng.uniform(5.5, 6.7)
    offset = rng.uniform(0.4, 0.9) * r
    ei = young * np.pi * r**4 / 4
    rc = rng.uniform(0.01, 0.05)
    zc = rng.uniform(0.3, 0.7) * length
    xc = rc + r + rng.uniform(0.0005, 0.01)
    center = np.array([xc, 0.0, zc])
    if rng.uniform() < 0.5:
        obstacle = sr.Cylinder((xc, -0.2, zc), (xc, 0.2, zc), rc)

        def gap(p):
            rel = p - center
            return np.hypot(rel[:, 0], rel[:, 2]) - rc - r
    else:
        obstacle = sr.Sphere(tuple(center), rc)

        def gap(p):
            return np.linalg.norm(p - center, axis=1) - rc - r

    tension = ratio * ei / (rc + r) / offset
    rod = sr.Rod(length, sr.CircularSection(r), sr.LinearElastic(young, 0.45))
    return rod, sr.Tendon((offset, 0.0), tension), obstacle, gap, tension, length


def _check(sol, gap, tension, length):
    """The contact laws and the global balance of a converged solution."""
    assert sol.converged
    pos = sol.position
    assert np.isfinite(pos).all()
    assert gap(pos).min() >= -1e-9
    assert all(c["normal_force"] >= 0.0 for c in sol.contacts)
    force = sol.contact_force.sum(axis=0)
    moment = np.cross(pos, sol.contact_force).sum(axis=0)
    assert np.abs(sol.base_wrench[:3] - force).max() <= 1e-10 * tension
    assert np.abs(sol.base_wrench[3:] - moment).max() <= 1e-10 * tension * length


def _solve(rod, tendon, obstacle):
    with warnings.catch_warnings():
        # (Stability is not what these tests check: a rod pressed on a convex obstacle may be
        # unstable with the contact held.)
        warnings.simplefilter("ignore", sr.StabilityWarning)
        return sr.solve_statics(rod, [tendon], obstacles=[obstacle], steps=60)


def test_leaning_arms_converge_and_keep_the_contact_laws():
    rng = np.random.default_rng(20261206)
    touched = 0
    for _ in range(12):
        rod, tendon, obstacle, gap, tension, length = _case(rng, rng.uniform(0.3, 0.85))
        sol = _solve(rod, tendon, obstacle)
        _check(sol, gap, tension, length)
        touched += bool(sol.contacts)
    assert touched >= 10


@pytest.mark.slow
def test_arms_that_may_wrap_converge_or_raise_by_name():
    rng = np.random.default_rng(1)
    converged, raised = 0, 0
    for k in range(40):
        rod, tendon, obstacle, gap, tension, length = _case(rng, rng.uniform(0.3, 1.3))
        t0 = time.perf_counter()
        try:
            sol = _solve(rod, tendon, obstacle)
        except sr.ConvergenceError as err:
            raised += 1
            assert 0.0 <= err.load_factor <= 1.0 and err.iterations > 0
            print(f"{k}: {type(err).__name__} after {time.perf_counter() - t0:.1f} s")
            continue
        _check(sol, gap, tension, length)
        converged += 1
    print(f"converged {converged}, raised {raised}")
    assert converged >= 20
