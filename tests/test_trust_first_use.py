"""Defects a first-time user met, through the Python API: each a closed form or a named error.

A rod pulled along its axis into a sphere stops on its near side (R = F - E A δ / L); an
obstacle the rod lies in at rest is refused naming ``obstacles[i]``; a rod compressed through
zero length is refused naming ``loads``; a column far past its buckling loads on a mesh too
coarse to follow them is reported unstable, with a warning that says to raise the steps.
"""

import math
import warnings

import numpy as np
import pytest

import softrod as sr

E, RADIUS, LENGTH = 2e9, 1e-3, 1.0
EA = E * math.pi * RADIUS**2
EI = E * math.pi * RADIUS**4 / 4


def _rod():
    return sr.Rod(LENGTH, sr.CircularSection(RADIUS), sr.LinearElastic(E, 0.3))


@pytest.mark.parametrize("force", [30.0, 100.0, 150.0])
def test_a_rod_pulled_into_a_sphere_stops_on_its_near_side(force):
    # The sphere's near surface 2 mm ahead of the tip (1 mm of gap past the rod's radius);
    # from 94 N the contact-free tip lands past the sphere's centre.
    sphere = sr.Sphere((0, 0, LENGTH + 0.012), 0.01)
    sol = sr.solve_statics(_rod(), loads=sr.Loads(tip_force=(0, 0, force)), obstacles=[sphere])
    np.testing.assert_allclose(sol.tip_position, [0, 0, LENGTH + 1e-3], atol=1e-9)
    (contact,) = sol.contacts
    assert contact["normal_force"] == pytest.approx(force - EA * 1e-3 / LENGTH, rel=1e-8)
    assert contact["normal"][2] < -0.999999


@pytest.mark.parametrize(
    ("obstacles", "index"),
    [
        ([sr.Plane((0, 0, 0.5), (0, 0, 1))], 0),
        ([sr.Sphere((0.5, 0.5, 0.5), 0.01), sr.Sphere((0, 0, 0.5125), 1e-3)], 1),
    ],
)
def test_an_obstacle_the_rod_lies_in_at_rest_is_named(obstacles, index):
    with pytest.raises(ValueError, match=rf"obstacles\[{index}\].*clear of the rod at rest"):
        sr.solve_statics(_rod(), loads=sr.Loads(tip_force=(0.005, 0, 0)), obstacles=obstacles)


def test_a_rod_compressed_through_zero_length_is_named():
    with pytest.raises(ValueError, match=r"`loads`.*positive stretch"):
        sr.solve_statics(_rod(), [], sr.Loads(tip_force=(0, 0, -1.5 * EA)))
    # Half of E A: the linear law's closed form v3 = 1 - F/(E A).
    sol = sr.solve_statics(_rod(), [], sr.Loads(tip_force=(0, 0, -0.5 * EA)))
    np.testing.assert_allclose(sol.v[:, 2], 0.5, atol=1e-12)


def test_a_column_too_compressed_for_its_mesh_is_not_stable():
    p_cr = math.pi**2 * EI / (4 * LENGTH**2)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = sr.solve_statics(_rod(), [], sr.Loads(tip_force=(0, 0, -1e4 * p_cr)))
    assert not sol.stable
    messages = [str(w.message) for w in caught if issubclass(w.category, sr.StabilityWarning)]
    assert any("raise the RK4" in m for m in messages), messages
