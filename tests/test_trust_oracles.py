"""The trust harnesses' oracles, checked against published values and limits.

Nothing here calls softrod: these are the checks that the oracles themselves are right.
"""

import math

import numpy as np
import pytest
from harness import fuzz, oracles, pcc_random
from scipy import special


def test_elliptic_integrals_match_tables():
    # Abramowitz & Stegun, table 17.1: K(m = 1/2), E(m = 1/2).
    assert special.ellipk(0.5) == pytest.approx(1.854074677301372, abs=1e-14)
    assert special.ellipe(0.5) == pytest.approx(1.350643881047675, abs=1e-14)
    # ellipkm1 is K in the complementary parameter, exact where 1 - p rounds to 1.
    assert special.ellipkm1(0.5) == pytest.approx(special.ellipk(0.5), rel=1e-15)
    p = 1e-30
    assert special.ellipkm1(p) == pytest.approx(math.log(4.0 / math.sqrt(p)), rel=1e-12)


def test_bisshopp_drucker_matches_the_published_table_and_limits():
    # Bisshopp & Drucker (1945): PL^2/EI = 1 gives a tip deflection of 0.3017 L.
    delta, x, angle = oracles.bisshopp_drucker(1.0)
    assert delta == pytest.approx(0.3017, abs=1e-4)
    # Small loads: Euler-Bernoulli, deflection alpha / 3 and tip angle alpha / 2.
    delta, x, angle = oracles.bisshopp_drucker(1e-4)
    assert delta == pytest.approx(1e-4 / 3, rel=1e-4) and angle == pytest.approx(5e-5, rel=1e-4)
    # Large loads: the rod aligns with the load, x -> sqrt(2 / alpha), tip angle -> pi/2.
    delta, x, angle = oracles.bisshopp_drucker(1000.0)
    assert x == pytest.approx(math.sqrt(2e-3), rel=1e-12)
    assert angle == pytest.approx(math.pi / 2, abs=1e-6) and 0.95 < delta < 1.0


def test_elastica_shooting_equals_bisshopp_drucker_for_transverse_loads():
    alphas = np.logspace(-2, 3, 6)
    path = oracles.elastica_paths([math.pi / 2], alphas)
    for k, a in enumerate(alphas):
        delta, x, _angle = oracles.bisshopp_drucker(a)
        assert path["x"][0, k] == pytest.approx(delta, abs=1e-10)
        assert path["z"][0, k] == pytest.approx(x, abs=1e-10)


def test_elastica_shooting_limits_and_mirror_symmetry():
    path = oracles.elastica_paths([0.0, 0.4, -0.4, 2.5], [0.5, 20.0])
    # A pure axial pull leaves the inextensible rod straight.
    assert np.allclose(path["x"][0], 0.0, atol=1e-14) and np.allclose(path["z"][0], 1.0)
    # Mirrored load, mirrored shape.
    assert np.allclose(path["x"][1], -path["x"][2], atol=1e-13)
    assert np.allclose(path["z"][1], path["z"][2], atol=1e-13)
    # Inextensible: the tip stays within one length of the base.
    assert np.all(np.hypot(path["x"], path["z"]) <= 1.0 + 1e-12)
    # Small oblique load: linear beam theory, deflection P_perp L^3 / 3EI along x.
    small = oracles.elastica_paths([1.0], [1e-5])
    assert small["x"][0, 0] == pytest.approx(1e-5 * math.sin(1.0) / 3, rel=1e-4)


def test_castigliano_arc_reduces_to_the_straight_cantilever_and_a_quarter_circle():
    stiff = (3.0, 3.0, 10.0, 0.02, 0.03, 0.015)
    assert np.allclose(
        oracles.castigliano_arc(0.0, 0.4, stiff),
        oracles.straight_cantilever(0.4, stiff),
        rtol=1e-13,
        atol=1e-15,
    )
    # Quarter circle of radius R, bending only (curved-beam tables): along the tip tangent
    # (3 pi / 4 - 2) R^3 / EI, along the base tangent (pi / 4) R^3 / EI, and between them
    # the integral of R^3 cos(phi) (1 - sin(phi)) / EI = R^3 / (2 EI).
    radius, ei = 0.1, 0.02
    c = oracles.castigliano_arc(1 / radius, math.pi / 2 * radius, (math.inf,) * 3 + (ei,) * 3)
    assert c[0, 0] == pytest.approx((3 * math.pi / 4 - 2) * radius**3 / ei, rel=1e-13)
    assert c[2, 2] == pytest.approx(math.pi / 4 * radius**3 / ei, rel=1e-13)
    assert abs(c[0, 2]) == pytest.approx(0.5 * radius**3 / ei, rel=1e-13)
    assert np.allclose(c, c.T, atol=1e-15) and np.all(np.linalg.eigvalsh(c)[3:] > 0)


def test_greenhill_constant_from_the_bessel_zero():
    c, j = oracles.greenhill_constant()
    assert j == pytest.approx(1.86635, abs=1e-5)
    assert c == pytest.approx(1.9863, abs=1e-4)
    assert 9 * j**2 / 4 == pytest.approx(7.837, abs=1e-3)  # Timoshenko & Gere: q l^3/EI


def test_rotation_vector_inverts_rodrigues():
    rng = np.random.default_rng(3)
    for _ in range(50):
        w = rng.normal(size=3)
        w *= rng.uniform(0, 3.1) / np.linalg.norm(w)
        assert np.allclose(oracles.rotation_vector(oracles.rotation_from_vector(w)), w)


def test_fibonacci_directions_cover_the_sphere_without_the_axis():
    d = oracles.fibonacci_directions(100)
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0)
    assert np.max(np.abs(d[:, 2])) < 1.0 - 1e-3
    assert np.linalg.norm(d.mean(axis=0)) < 0.02


def test_pcc_arc_written_out_matches_the_quarter_circle():
    t = pcc_random.arc_transform(math.pi / 2 / 0.1, 0.0, 0.1)
    assert np.allclose(t[:3, 3], [0.2 / math.pi, 0.0, 0.2 / math.pi], atol=1e-15)
    assert np.allclose(t[:3, 2], [1.0, 0.0, 0.0], atol=1e-15)


def test_fuzz_error_naming_rules():
    e = ValueError("invalid parameter `tip_force[1]` = NaN")
    assert fuzz.names_parameter(e, "tip_force")
    assert not fuzz.names_parameter(ValueError("expected a sequence of length 3"), "tip_force")
    assert fuzz.names_parameter(TypeError("argument 's': bad"), "s")
    assert not fuzz.names_parameter(TypeError("the robot's section"), "s")
    assert fuzz.names_parameter(ValueError("`tension` = nan"), "tensions")
    err = ValueError("bad")
    err.parameter = "tendons[0].offset"
    assert fuzz.names_parameter(err, "tendons") and not fuzz.names_parameter(err, "offset")
