"""Contact and end constraints from Python: the tip-contact oracle, clamped and pinned tips,
obstacles in a Robot and in robot files, pickling."""

import pickle
import warnings

import numpy as np
import pytest

import softrod as sr

E, NU, R, L = 2e9, 0.3, 1e-3, 1.0
EI = E * np.pi * R**4 / 4


def _rod():
    return sr.Rod(L, sr.CircularSection(R), sr.LinearElastic(E, NU))


DELTA = 1e-3
CLOSING = 3 * EI * DELTA / L**3  # the tip force that closes the gap to the plane
PLANE = sr.Plane((-(R + DELTA), 0.0, 0.0), (1.0, 0.0, 0.0))


def _pressed(factor, **kw):
    """The cantilever pushed toward the plane by `factor` times the closing force."""
    loads = sr.Loads(tip_force=(-factor * CLOSING, 0, 0))
    return sr.solve_statics(_rod(), loads=loads, obstacles=[PLANE], steps=100, **kw)


def test_tip_contact_reaction_is_the_cantilever_closed_form():
    closing, plane = CLOSING, PLANE
    sol = _pressed(2)
    assert len(sol.contacts) == 1
    c = sol.contacts[0]
    assert c["s"] == L and c["normal"] == [1.0, 0.0, 0.0]
    assert abs(c["normal_force"] / closing - 1) < 1e-4
    assert sol.contact_force.shape == (len(sol.s), 3)
    np.testing.assert_allclose(sol.contact_force.sum(axis=0), [c["normal_force"], 0, 0])
    free = sr.solve_statics(
        _rod(), loads=sr.Loads(tip_force=(-0.5 * closing, 0, 0)), obstacles=[plane]
    )
    assert free.contacts == [] and not free.contact_force.any()
    assert free.tip_reaction is None


def test_clamped_clamped_midspan_and_pin():
    p = 1e-8
    loads = sr.Loads(point_loads=[sr.PointLoad(0.5, (p, 0.0, 0.0))])
    pose = np.eye(4)
    pose[2, 3] = L
    sol = sr.solve_statics(_rod(), loads=loads, tip_constraint=sr.Clamp(pose), steps=200)
    mid = sol.position[np.flatnonzero(sol.s == 0.5)[-1]]
    assert abs(mid[0] / (p * L**3 / (192 * EI)) - 1) < 1e-3
    assert sol.tip_reaction.shape == (6,) and sol.stable
    pinned = sr.solve_statics(_rod(), loads=loads, tip_constraint=sr.Pin((0, 0, L)), steps=200)
    mid = pinned.position[np.flatnonzero(pinned.s == 0.5)[-1]]
    assert abs(mid[0] / (7 * p * L**3 / (768 * EI)) - 1) < 1e-3
    # A solution with a constraint pickles (by solving again).
    again = pickle.loads(pickle.dumps(pinned))
    np.testing.assert_array_equal(again.position, pinned.position)


def test_bad_obstacles_and_constraints_are_named():
    with pytest.raises(sr.ParameterError, match="radius"):
        sr.Sphere((0, 0, 0), -1.0)
    with pytest.raises(sr.ParameterError, match="normal"):
        sr.Plane((0, 0, 0), (0, 0, 0))
    with pytest.raises(sr.ParameterError, match="pose"):
        sr.Clamp(np.ones((4, 4)))
    with pytest.raises(sr.ParameterError, match="obstacles"):
        sr.solve_statics(_rod(), obstacles=3.0)
    with pytest.raises((sr.ParameterError, TypeError), match="tip_constraint"):
        sr.solve_statics(_rod(), tip_constraint="clamp")
    with pytest.raises(sr.ParameterError, match="s_out"):
        sr.solve_statics(_rod(), obstacles=[sr.Plane((0, 0, -1), (0, 0, 1))], s_out=[0.5])


def test_robot_and_robot_file_carry_obstacles():
    plane = sr.Plane((-(R + 1e-3), 0.0, 0.0), (1.0, 0.0, 0.0))
    robot = sr.Robot(
        _rod(), loads=sr.Loads(tip_force=(-4 * 3 * EI * 1e-3, 0, 0)), obstacles=[plane]
    )
    sol = robot.solve()
    assert len(sol.contacts) == 1
    text = robot.to_toml()
    assert "[[obstacles]]" in text
    back = sr.Robot.from_toml(text)
    assert back.obstacles == (plane,)
    np.testing.assert_allclose(back.solve().position, sol.position)
    data = {
        "rod": {
            "length": 1.0,
            "section": {"radius": R},
            "material": {"youngs_modulus": E, "poisson_ratio": NU},
        },
        "tip_constraint": {"type": "pin", "point": [0.0, 0.0, 1.0]},
        "obstacles": [{"type": "sphere", "center": [0.0, 0.1, 0.5], "radius": 0.01}],
    }
    r2 = sr.Robot.from_dict(data)
    assert isinstance(r2.tip_constraint, sr.Pin) and isinstance(r2.obstacles[0], sr.Sphere)
    assert r2.solve().tip_reaction is not None


@pytest.mark.parametrize(
    "constraint",
    [
        sr.Pin((0.0, 0.01, 1.0)),
        sr.Slide((0.0, 0.0, 1.0), (0.0, 0.0, 1.0)),
        sr.Clamp(np.array([[1, 0, 0, 0.01], [0, 1, 0, 0], [0, 0, 1, 1.0], [0, 0, 0, 1.0]])),
        sr.Clamp(np.eye(4) + np.diag([0, 0, 0, 0.0]), held=[True, True, True, True, True, False]),
    ],
)
def test_tip_constraint_round_trips_through_a_robot_file(tmp_path, constraint):
    robot = sr.Robot(_rod(), tip_constraint=constraint)
    text = robot.to_toml()
    assert "[tip_constraint]" in text
    back = sr.Robot.from_toml(text)
    assert back.tip_constraint == constraint or np.array_equal(
        back.tip_constraint.pose, constraint.pose
    )
    path = tmp_path / "robot.toml"
    robot.write_toml(path)
    loaded = sr.load_robot(path)
    assert sr.Robot.from_toml(loaded.to_toml()) == loaded
    assert loaded.to_toml() == text


def test_failed_contact_solve_without_throw_returns_the_unconverged_solution():
    loads = sr.Loads(tip_force=(-40 * CLOSING, 0, 0))
    kw = {"obstacles": [PLANE], "max_iterations": 1, "continuation": False}
    with pytest.raises(sr.ConvergenceError, match="contact"):
        sr.solve_statics(_rod(), loads=loads, **kw)
    sol = sr.solve_statics(_rod(), loads=loads, throw=False, **kw)
    assert not sol.converged
    assert sol.stats["load_factor"] < 1 and sol.stats["residual"] > 1e-10
    assert sol.stats["iterations"] == 1
    assert np.isfinite(sol.position).all()


def test_contact_compliance_holds_the_normal_and_slides_along_the_plane():
    free, pressed = _pressed(0.5), _pressed(2)
    c0, c = free.contact_compliance, pressed.contact_compliance
    assert c.shape == (6, 6)
    assert abs(c[0, 0]) <= 1e-9 * c0[0, 0]
    assert c[1, 1] == pytest.approx(L**3 / (3 * EI), rel=1e-3)
    assert sr.solve_statics(_rod()).contact_compliance is None


@pytest.mark.parametrize(("fx", "fy", "state"), [(2.0, 0.5, "stick"), (2.0, -2.0, "slide")])
def test_tip_friction_sticks_and_slides_as_the_cantilever_closed_form(fx, fy, state):
    # Proportional loading: first touch at lambda0 = F_c / Fx, normal reaction Fx - F_c;
    # sticking (|Fy| <= mu Fx) holds the tip at lambda0 Fy L^3 / (3 EI) with the tangential
    # reaction -(1 - lambda0) Fy, sliding puts the reaction on the cone against the slip.
    mu = 0.5
    plane = sr.Plane((-(R + DELTA), 0.0, 0.0), (1.0, 0.0, 0.0), friction=mu)
    force = np.array([-fx * CLOSING, fy * CLOSING, 0.0])
    sol = sr.solve_statics(_rod(), loads=sr.Loads(tip_force=force), obstacles=[plane], steps=100)
    (c,) = sol.contacts
    assert c["state"] == state
    lambda0, normal, comp = 1 / fx, (fx - 1) * CLOSING, L**3 / (3 * EI)
    if state == "stick":
        ft, y = -(1 - lambda0) * force[1], lambda0 * force[1] * comp
    else:
        ft = -np.sign(force[1]) * mu * normal
        y = (force[1] + ft) * comp
    assert abs(c["normal_force"] / normal - 1) < 1e-4
    assert abs(c["tangential_force"][1] / ft - 1) < 1e-4
    assert abs(sol.position[-1, 1] / y - 1) < 1e-4
    assert np.linalg.norm(c["tangential_force"]) <= mu * c["normal_force"] * (1 + 1e-9)
    total = np.asarray(c["normal"]) * c["normal_force"] + np.asarray(c["tangential_force"])
    np.testing.assert_allclose(sol.contact_force.sum(axis=0), total, rtol=0, atol=1e-12 * CLOSING)


@pytest.mark.parametrize("bad", [-0.2, float("nan"), float("inf"), 11.0, "rough"])
@pytest.mark.parametrize(
    "make",
    [
        lambda mu: sr.Plane((0, 0, 0), (1, 0, 0), friction=mu),
        lambda mu: sr.Sphere((0, 0, 0), 0.1, friction=mu),
        lambda mu: sr.Capsule((0, 0, 0), (0, 0, 1), 0.1, friction=mu),
        lambda mu: sr.Cylinder((0, 0, 0), (0, 0, 1), 0.1, friction=mu),
        lambda mu: sr.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], friction=mu),
    ],
)
def test_bad_friction_is_a_named_value_error(make, bad):
    with pytest.raises(ValueError, match=r"friction.*in \[0, 10\]") as err:
        make(bad)
    assert err.value.parameter == "friction"
    assert repr(bad) in str(err.value)


# The propped cantilever: a stout rod (R/L = 0.01) over a post (a cylinder across it, axis
# along y) at a = 0.6 L, surface gap 1e-6 L, pressed by the tip force (-Fx, Fy, 0).
R_POST, GAP, A, RC = 1e-2, 1e-6, 0.6, 0.05


def _post(friction):
    x = -(R_POST + GAP + RC)
    return sr.Cylinder((x, -0.2, A), (x, 0.2, A), RC, friction=friction)


@pytest.mark.parametrize(("fy", "state"), [(0.5, "stick"), (-1.5, "slide")])
def test_interior_friction_is_the_propped_cantilever(fy, state):
    # Timoshenko flexibilities (Cowper's shear area, as the rod's section): alpha at a under
    # a unit force at a, beta at a under one at L (and at L under one at a), gamma at L.
    ei = E * np.pi * R_POST**4 / 4
    gas = 6 * (1 + NU) / (7 + 6 * NU) * E / (2 * (1 + NU)) * np.pi * R_POST**2
    alpha = A**3 / (3 * ei) + A / gas
    beta = A**2 * (3 * L - A) / (6 * ei) + A / gas
    gamma = L**3 / (3 * ei) + L / gas
    mu, closing = 0.5, GAP / beta
    fx, fy = 2 * closing, fy * closing
    rod = sr.Rod(L, sr.CircularSection(R_POST), sr.LinearElastic(E, NU))
    loads = sr.Loads(tip_force=(-fx, fy, 0.0))
    sol = sr.solve_statics(rod, loads=loads, obstacles=[_post(mu)], steps=100)
    (c,) = sol.contacts
    assert c["state"] == state
    # Proportional loading: the rod touches the post at lambda0 = gap / (Fx beta); the post
    # then props it at a, sticking (|Fy| <= mu Fx) where it touched, else sliding.
    lambda0 = closing / fx
    normal = (1 - lambda0) * fx * beta / alpha
    ft = -(1 - lambda0) * fy * beta / alpha if state == "stick" else -np.sign(fy) * mu * normal
    tip = (-fx * gamma + normal * beta, fy * gamma + ft * beta)
    assert abs(c["s"] - A) < 1e-4
    assert abs(c["normal_force"] / normal - 1) < 1e-4
    assert abs(c["tangential_force"][1] / ft - 1) < 1e-4
    np.testing.assert_allclose(sol.position[-1, :2], tip, rtol=1e-4)
    total = np.asarray(c["normal"]) * c["normal_force"] + np.asarray(c["tangential_force"])
    np.testing.assert_allclose(sol.contact_force.sum(axis=0), total, rtol=0, atol=1e-12 * fx)


def test_friction_in_robot_files_and_along_an_interval():
    plane = sr.Plane((-(R + DELTA), 0.0, 0.0), (1.0, 0.0, 0.0), friction=0.4)
    robot = sr.Robot(_rod(), loads=sr.Loads(tip_force=(-2 * CLOSING, 0, 0)), obstacles=[plane])
    text = robot.to_toml()
    assert "friction = 0.4" in text
    back = sr.Robot.from_toml(text)
    assert back.obstacles == (plane,)
    assert back.solve().contacts[0]["state"] == "stick"
    # Frictionless obstacles write no friction key (robot files as before).
    assert "friction" not in sr.Robot(_rod(), obstacles=[PLANE]).to_toml()
    data = {
        "rod": {
            "length": 1.0,
            "section": {"radius": R},
            "material": {"youngs_modulus": E, "poisson_ratio": NU},
        },
        "obstacles": [{"type": "plane", "point": [0, 0, 0], "normal": [1, 0, 0], "friction": -1}],
    }
    with pytest.raises(ValueError, match="friction"):
        sr.Robot.from_dict(data)
    # A frictional floor the rod lies along (a uniform load: a contact interval): refused,
    # naming `friction`.
    q = 72 * EI * DELTA / (0.5 * L) ** 4
    loads = sr.Loads(distributed_force=(-q, 0.0, 0.0))
    with pytest.raises(ValueError, match="friction") as err:
        sr.solve_statics(_rod(), loads=loads, obstacles=[plane], steps=100)
    assert err.value.parameter == "friction"


def test_a_belt_is_reported_and_its_linearisations_refused_by_name():
    """A tendon-bent soft rod lying on a cylinder (3.3 N: a belt of about 8 mm): the contact
    has a length, its lumped pressure balances the base wrench (the tendon's loads are
    internal), and the tangent compliance and the actuation Jacobian, which are not
    linearised about a belt, raise a ParameterError naming ``solution``."""
    length, radius = 0.3, 0.005
    rod = sr.Rod(length, sr.CircularSection(radius), sr.LinearElastic(1e6, 0.45))
    xc = 0.03 + radius + 0.002
    cylinder = sr.Cylinder((xc, -0.1, 0.14), (xc, 0.1, 0.14), 0.03)
    with pytest.warns(sr.StabilityWarning):
        sol = sr.solve_statics(rod, [sr.Tendon((0.004, 0.0), 3.3)], obstacles=[cylinder], steps=80)
    (belt,) = sol.contacts
    assert 0.005 < belt["length"] < 0.012
    # The base wrench is the contact forces' resultant and moment about the origin (to
    # 1e-10 of the tension, and of the tension times the length).
    force = sol.contact_force.sum(axis=0)
    moment = np.cross(sol.position, sol.contact_force).sum(axis=0)
    assert np.abs(sol.base_wrench[:3] - force).max() <= 1e-10 * 3.3
    assert np.abs(sol.base_wrench[3:] - moment).max() <= 1e-10 * 3.3 * length
    assert sol.contact_compliance is None
    for call in (lambda: sr.tangent_compliance(sol), lambda: sr.actuation_jacobian(sol)):
        with pytest.raises(sr.ParameterError, match="solution"):
            call()


@pytest.mark.parametrize("ratio, stable", [(0.95, True), (1.05, False)])
def test_a_push_on_top_of_a_sphere_slides_off_past_the_tip_stiffness(ratio, stable):
    """Stability holds the contact: a straight rod pushing its tip on top of a sphere is stable
    while the push P is below k rho (k its lateral tip stiffness, rho the distance of the
    centreline's tip from the centre); past it the tip slides off (a warning says so)."""
    radius = 0.05
    k = 3 * EI / L**3  # (shear adds 9e-6 relative at L/r = 1000)
    push = ratio * k * (radius + R)
    sphere = sr.Sphere((0.0, 0.0, L + R + radius), radius)
    loads = sr.Loads(tip_force=(0, 0, push))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = sr.solve_statics(_rod(), loads=loads, obstacles=[sphere], steps=40)
    assert len(sol.contacts) == 1 and sol.contacts[0]["s"] == L
    assert sol.stable is stable and (sol.stability_margin > 0) is stable
    warned = [w for w in caught if issubclass(w.category, sr.StabilityWarning)]
    assert bool(warned) is not stable
    assert all("contacts held" in str(w.message) for w in warned)


def test_a_copied_obstacle_and_too_many_obstacles_are_refused():
    # (Two copies of one plane gave another, unstable equilibrium reported converged; 2,000
    # copies of a sphere ran for minutes and gigabytes.)
    rod = sr.Rod(1.0, sr.CircularSection(1e-3), sr.LinearElastic(2e9, 0.3))
    loads = sr.Loads(tip_force=(0.05, 0, 0))
    plane = sr.Plane((0.02, 0, 0), (-1, 0, 0))
    one = sr.solve_statics(rod, loads=loads, obstacles=[plane])
    assert one.stable and one.tip_position[0] <= 0.02 + 1e-9
    with pytest.raises(sr.ParameterError) as e:
        sr.solve_statics(rod, loads=loads, obstacles=[plane, plane])
    assert e.value.parameter == "obstacles[1]" and "obstacles[0] again" in str(e.value)
    sphere = sr.Sphere((0.05, 0, 0.7), 0.04)
    with pytest.raises(sr.ParameterError) as e:
        sr.solve_statics(rod, loads=loads, obstacles=[sphere] * 2000)
    assert e.value.parameter == "obstacles.len()" and "[0, 256]" in str(e.value)
