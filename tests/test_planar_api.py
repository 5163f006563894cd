"""Binding surface of the planar cable arm: names, shapes, errors. Physics is tested in Rust."""

import numpy as np
import pytest

import softrod
from softrod import ConvergenceError, ParameterError, PlanarCableArm

ARM = dict(
    length=0.27, base_radius=0.015, tip_radius=0.0074, offset_ratio=1 / 3, youngs_modulus=110e3
)


def test_constructor_keywords_and_published_arm_agree():
    a = PlanarCableArm(**ARM)
    b = PlanarCableArm.published_arm()
    assert a.anchor == pytest.approx(a.length)
    for name in ("length", "base_radius", "tip_radius", "offset_ratio", "youngs_modulus"):
        assert getattr(a, name) == pytest.approx(getattr(b, name))
    assert "PlanarCableArm(" in repr(a)


def test_solve_returns_arrays_of_the_requested_length():
    arm = PlanarCableArm(**ARM)
    sol = arm.solve(1.0)
    for name in ("s", "curvature", "strain", "angle", "x", "y"):
        arr = getattr(sol, name)
        assert isinstance(arr, np.ndarray) and arr.shape == (201,) and arr.dtype == np.float64
    assert sol.tip.shape == (2,)
    assert sol.s[0] == 0.0 and sol.s[-1] == pytest.approx(0.27)
    assert sol.tip[0] == sol.x[-1] and sol.tip[1] == sol.y[-1]
    assert sol.max_compressive_strain == pytest.approx(-sol.strain.min())
    assert sol.method == "closed-form" and sol.stats is None
    assert arm.solve(1.0, 11).x.shape == (11,)


def test_ode_method_and_tolerances():
    arm = PlanarCableArm(**ARM)
    cf = arm.solve(2.0)
    ode = arm.solve(2.0, method="ode", rtol=1e-10, atol=1e-12)
    assert ode.method == "ode" and ode.stats["accepted_steps"] > 0
    assert np.max(np.abs(ode.curvature - cf.curvature)) / cf.curvature.max() < 1e-8


def test_strided_arrays_are_accepted():
    arm = PlanarCableArm(**ARM)
    tensions = np.linspace(0.0, 3.0, 12)
    strided = arm.solve_many(tensions[::3], n_points=5)
    np.testing.assert_array_equal(strided.x, arm.solve_many(tensions[::3].copy(), n_points=5).x)
    grid = np.linspace(0.0, 0.27, 10).reshape(5, 2)
    np.testing.assert_array_equal(arm.solve(1.0, s=grid[:, 0]).s, grid[:, 0])


def test_custom_samples():
    arm = PlanarCableArm(**ARM)
    s = np.array([0.0, 0.1, 0.2])
    sol = arm.solve(1.0, s=s)
    np.testing.assert_array_equal(sol.s, s)
    full = arm.solve(1.0)
    assert np.allclose(sol.tip, full.tip, rtol=0, atol=1e-10)  # different panel grids


def test_solve_many_is_vectorised_and_matches_solve():
    arm = PlanarCableArm(**ARM)
    tensions = np.linspace(0, 3, 7)
    batch = arm.solve_many(tensions, n_points=51)
    assert len(batch) == 7
    for name in ("curvature", "strain", "angle", "x", "y"):
        assert getattr(batch, name).shape == (7, 51)
    assert batch.tip.shape == (7, 2) and batch.tip_angle.shape == (7,)
    one = arm.solve(tensions[4], 51)
    np.testing.assert_array_equal(batch.x[4], one.x)
    # Lists and scalars are accepted too.
    assert arm.solve_many([0.5, 1.0]).x.shape == (2, 201)
    assert arm.solve_many(0.5).x.shape == (1, 201)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        (dict(ARM, length=0.0), "length"),
        (dict(ARM, length=float("nan")), "length"),
        (dict(ARM, base_radius=-0.01), "base_radius"),
        (dict(ARM, tip_radius=0.0), "tip_radius"),
        (dict(ARM, offset_ratio=1.0), "offset_ratio"),
        (dict(ARM, offset_ratio=-0.2), "offset_ratio"),
        (dict(ARM, youngs_modulus=0.0), "youngs_modulus"),
        (dict(ARM, anchor=0.0), "anchor"),
        (dict(ARM, anchor=0.5), "anchor"),
    ],
)
def test_bad_parameters_raise_value_error_naming_them(kwargs, name):
    with pytest.raises(ValueError) as info:
        PlanarCableArm(**kwargs)
    assert isinstance(info.value, ParameterError)
    assert info.value.parameter == name
    assert name in str(info.value)


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda arm: arm.solve(-1.0), "tension"),
        (lambda arm: arm.solve(float("nan")), "tension"),
        (lambda arm: arm.solve(float("inf")), "tension"),
        (lambda arm: arm.solve(1.0, 1), "n_points"),
        (lambda arm: arm.solve(1.0, -3), "n_points"),
        (lambda arm: arm.solve(1.0, method="rk45"), "method"),
        (lambda arm: arm.solve(1.0, method="ode", rtol=0.0), "rtol"),
        (lambda arm: arm.solve(1.0, method="ode", atol=-1.0), "atol"),
        (lambda arm: arm.solve(1.0, s=[0.0, 1.0]), "s[1]"),
        (lambda arm: arm.solve_many([1.0, -1.0]), "tensions[1]"),
    ],
)
def test_bad_solve_arguments_raise_value_error_naming_them(call, name):
    with pytest.raises(ParameterError) as info:
        call(PlanarCableArm(**ARM))
    assert info.value.parameter == name


def test_non_convergence_raises_with_iterations_and_residual():
    arm = PlanarCableArm(**ARM)
    with pytest.raises(ConvergenceError) as info:
        arm.solve(1.0, method="ode", rtol=1e-10, atol=1e-12, max_steps=5)
    assert info.value.iterations == 5
    assert np.isfinite(info.value.residual)
    assert isinstance(info.value, RuntimeError)


def test_exceptions_are_exported():
    assert issubclass(softrod.ParameterError, ValueError)
    assert issubclass(softrod.ConvergenceError, RuntimeError)


@pytest.mark.parametrize("ratio", [0.5, 0.6])
def test_the_ode_method_refuses_tensions_whose_strain_it_cannot_resolve(ratio):
    # From a = 1/2 the strain stays above -1 at every tension (it tends to -1/(4 a^2)), so no
    # tension is refused by the model; but q = T (a R k - 1)/(E pi R^2) cancels, and the ODE's
    # strain at 1e12 N was -153 (closed form: -0.69) with its tip 4.3 cm away.
    arm = PlanarCableArm(0.27, 0.015, 0.0074, ratio, 110e3)
    assert arm.max_tension == float("inf")
    exact = arm.solve(1e12)
    assert exact.strain.min() > -1.0
    assert exact.strain.min() == pytest.approx(-1.0 / (4 * ratio**2), rel=1e-6)
    with pytest.raises(ParameterError, match="tension") as e:
        arm.solve(1e12, method="ode")
    assert e.value.parameter == "tension"
    assert "closed form" in str(e.value)
    # Below the bound the ODE's strain is the closed form's to its tolerance.
    ode, closed = arm.solve(1e3, method="ode"), arm.solve(1e3)
    np.testing.assert_allclose(ode.strain, closed.strain, rtol=1e-4)


def test_an_ode_absolute_tolerance_that_turns_the_tip_is_refused():
    # (atol = 1 1/m moved the tip 18 mm at 2 N, reported as a solution.)
    arm = softrod.PlanarCableArm.published_arm()
    for atol in (1.0, 1e308):
        with pytest.raises(softrod.ParameterError) as e:
            arm.solve(2.0, method="ode", atol=atol)
        assert e.value.parameter == "atol"
    bound = 1e-3 / arm.length
    ode = arm.solve(2.0, method="ode", atol=bound)
    exact = arm.solve(2.0)
    assert np.linalg.norm(np.subtract(ode.tip, exact.tip)) <= bound * arm.length**2
