"""Binding surface of the Cosserat statics engine: names, shapes, conversions, errors.

The physics (arcs, elastica, tendons, invariances) is tested against oracles in Rust
(``crates/softrod/tests/statics*.rs``).
"""

import numpy as np
import pytest

import softrod
from softrod import (
    CircularSection,
    ConvergenceError,
    LinearElastic,
    Loads,
    ParameterError,
    PointLoad,
    Rod,
    Tendon,
    solve_statics,
)

NITI = LinearElastic(54e9, 0.3)


def niti_rod(**kw):
    return Rod(0.4, CircularSection(0.7e-3), NITI, **kw)


def two_segment_tendons(tensions=(4, 0, 0, 0, 2, 0)):
    out = []
    for k, (end, ang) in enumerate(
        [(0.2, 90), (0.2, -30), (0.2, 210), (0.4, 90), (0.4, -30), (0.4, 210)]
    ):
        a = np.radians(ang)
        out.append(Tendon((0.01 * np.cos(a), 0.01 * np.sin(a)), tensions[k], end))
    return out


def test_solution_fields_have_documented_shapes():
    sol = solve_statics(niti_rod(), two_segment_tendons())
    n = len(sol)
    assert sol.s.shape == (n,) and sol.s[0] == 0.0 and sol.s[-1] == pytest.approx(0.4)
    for name in ("position", "force", "moment", "force_body", "moment_body", "v", "u"):
        assert getattr(sol, name).shape == (n, 3), name
    assert sol.rotation.shape == (n, 3, 3) and sol.quaternion.shape == (n, 4)
    assert sol.tendon_lengths.shape == (6,) and sol.base_wrench.shape == (6,)
    np.testing.assert_array_equal(sol.tip_position, sol.position[-1])
    np.testing.assert_array_equal(sol.tip_rotation, sol.rotation[-1])
    assert sol.converged and sol.stats["converged"]
    assert set(sol.stats) == {
        "load_factor",
        "iterations",
        "residual",
        "function_evaluations",
        "load_steps",
        "converged",
    }
    # Arrays are cached: the same object on every access.
    assert sol.position is sol.position
    # Body and world components are related by the rotations.
    np.testing.assert_allclose(
        np.einsum("nij,nj->ni", sol.rotation, sol.force_body), sol.force, atol=1e-12
    )


def test_base_pose_as_matrix_or_pair_and_loads_keywords():
    rot = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    t = np.eye(4)
    t[:3, :3], t[:3, 3] = rot, (0.1, 0.2, 0.3)
    a = niti_rod(base_pose=t)
    b = niti_rod(base_pose=((0.1, 0.2, 0.3), rot))
    np.testing.assert_array_equal(a.base_pose, b.base_pose)
    np.testing.assert_array_equal(a.base_pose, t)
    loads = Loads(tip_force=(0.0, 0.1, 0.0), point_loads=[PointLoad(0.2, force=(0.05, 0, 0))])
    sa = solve_statics(a, (), loads)
    sb = solve_statics(b, [], loads)
    np.testing.assert_array_equal(sa.position, sb.position)
    np.testing.assert_allclose(sa.position[0], (0.1, 0.2, 0.3))


def test_warm_start_from_solution_or_wrench_and_integrators():
    rod = niti_rod()
    loads = Loads(tip_force=(0.2, 0.0, 0.0))
    cold = solve_statics(rod, two_segment_tendons(), loads)
    warm = solve_statics(rod, two_segment_tendons(), loads, warm_start=cold)
    assert warm.stats["iterations"] <= 1
    again = solve_statics(rod, two_segment_tendons(), loads, warm_start=list(cold.base_wrench))
    np.testing.assert_allclose(again.tip_position, cold.tip_position, atol=1e-9)
    ad = solve_statics(rod, two_segment_tendons(), loads, integrator="adaptive", rtol=1e-10)
    np.testing.assert_allclose(ad.tip_position, cold.tip_position, atol=1e-4)


def test_function_offset_and_rest_curvature_callables():
    rod = niti_rod(rest_curvature=lambda s: (0.0, 0.0, 0.0))
    t = Tendon(lambda s: (0.01, 0.0), 1.0, derivative=lambda s: (0.0, 0.0))
    c = Tendon((0.01, 0.0), 1.0)
    np.testing.assert_allclose(
        solve_statics(rod, [t]).position, solve_statics(niti_rod(), [c]).position, atol=1e-14
    )


def test_exception_in_a_callable_is_reraised():
    def broken(s):
        raise KeyError("boom")

    # Raised where the callable is first called: the constructor tries it once at s = 0.
    with pytest.raises(ValueError, match="tendon offset") as err:
        solve_statics(niti_rod(), [Tendon(broken, 1.0, derivative=lambda s: (0.0, 0.0))])
    assert isinstance(err.value.__cause__, KeyError)


@pytest.mark.parametrize(
    ("make", "name"),
    [
        (lambda: CircularSection(0.0), "radius"),
        (lambda: softrod.TaperedCircularSection(0.01, -1.0), "tip_radius"),
        (lambda: softrod.TubeSection(0.01, 0.01), "inner_radius"),
        (lambda: LinearElastic(-1.0, 0.3), "youngs_modulus"),
        (lambda: LinearElastic(1e6, 0.7), "poisson_ratio"),
        (lambda: LinearElastic(1e6), "poisson_ratio"),
        (lambda: Rod(0.0, CircularSection(0.01), NITI), "length"),
        (lambda: Rod(float("nan"), CircularSection(0.01), NITI), "length"),
        (lambda: Tendon((0.01, 0.0), 1.0, end=0.5).with_tension(-1.0), "tension"),
        (lambda: Tendon((0.01, 0.0), 1.0, derivative=lambda s: (0, 0)), "derivative"),
        (lambda: Tendon(lambda s: (0, 0), 1.0), "derivative"),
        (lambda: Loads(tip_frame="tool"), "tip_frame"),
        (lambda: solve_statics(niti_rod(), integrator="euler"), "integrator"),
        (lambda: solve_statics(niti_rod(), steps=0), "steps"),
        (lambda: solve_statics(niti_rod(), max_iterations=0), "max_iterations"),
        (lambda: solve_statics(niti_rod(), [Tendon((0.01, 0), 1.0, end=0.5)]), "end"),
        (lambda: solve_statics(niti_rod(), (), Loads(tip_force=(float("nan"), 0, 0))), "nan"),
    ],
)
def test_bad_input_raises_parameter_error(make, name):
    with pytest.raises(ParameterError) as info:
        make()
    assert name in str(info.value).lower() or name in info.value.parameter


def test_non_convergence_raises_or_is_returned():
    rod = Rod(0.27, CircularSection(0.01), LinearElastic(110e3, 0.5))
    loads = Loads(tip_force=(0.5, 0.0, 0.0))
    with pytest.raises(ConvergenceError) as info:
        solve_statics(rod, (), loads, max_iterations=1, continuation=False)
    assert info.value.iterations >= 1 and info.value.residual > 0
    sol = solve_statics(rod, (), loads, max_iterations=1, continuation=False, throw=False)
    assert not sol.converged and sol.stats["residual"] > 0
