"""Design summaries of a sweep and the Pareto front, against geometry and brute force."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import xarray as xr

import softrod
from softrod.analysis.design import workspace_measures


def test_hull_and_voxel_measures_of_known_sets():
    rng = np.random.default_rng(3)
    # The corners of a 0.1 x 0.2 x 0.3 box and points inside: hull volume 0.006 m^3.
    corners = np.array(list(itertools.product([0, 0.1], [0, 0.2], [0, 0.3])))
    inside = rng.uniform([0, 0, 0], [0.1, 0.2, 0.3], (200, 3))
    m = workspace_measures(np.vstack([corners, inside]), voxel=0.05)
    assert m["dimension"] == 3
    assert m["hull_volume"] == pytest.approx(0.006, rel=1e-12)
    assert np.isnan(m["hull_area"])
    # A planar unit disc of radius 0.1 tilted in space: hull area -> pi r^2, voxel area
    # counts the squares of a dense grid of it.
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    rot = np.array([[1, 0, 0], [0, np.cos(0.7), -np.sin(0.7)], [0, np.sin(0.7), np.cos(0.7)]])
    ring = np.column_stack([0.1 * np.cos(t), 0.1 * np.sin(t), np.zeros_like(t)]) @ rot.T
    m = workspace_measures(ring + np.array([0.3, -0.2, 0.5]), voxel=0.01)
    assert m["dimension"] == 2 and m["hull_volume"] == 0.0
    assert m["hull_area"] == pytest.approx(np.pi * 0.01, rel=2e-4)
    assert np.isnan(m["voxel_volume"])
    # Pixels of a filled square grid of spacing h with edge h: one per point.
    centres = np.arange(10) * 0.01 + 0.005
    g = np.array([[x, y, 0.0] for x in centres for y in centres[:5]])
    m = workspace_measures(g, voxel=0.01)
    assert m["voxel_area"] == pytest.approx(50 * 1e-4)
    # Points on a line span one dimension: no area.
    m = workspace_measures(np.outer(np.linspace(0, 1, 5), [1, 2, 3]), voxel=0.1)
    assert m["dimension"] == 1 and m["hull_area"] == 0.0


def test_design_summary_over_a_synthetic_sweep():
    # Two design points; tips on a square (design 0) or a larger square (design 1) around
    # the z axis; compliance grows with the distance from the axis.
    u = np.linspace(-1, 1, 5)
    x, y = np.meshgrid(u, u, indexing="ij")
    tips = np.zeros((2, 5, 5, 3))
    for d, scale in enumerate([0.01, 0.02]):
        tips[d, ..., 0], tips[d, ..., 1], tips[d, ..., 2] = scale * x, scale * y, 0.3
    r = np.hypot(tips[..., 0], tips[..., 1])
    c = 1.0 + 100 * r  # m/N
    comp = np.stack([c, 0.5 * c, 0.1 * c], axis=-1)[..., None, :]
    status = np.zeros((2, 5, 5), dtype=np.int8)
    status[0, 0, 0] = 1  # a failed sample does not count
    ds = xr.Dataset(
        {
            "tip_position": (("E", "t0", "t1", "xyz"), tips),
            "translational_compliance": (("E", "t0", "t1", "arm_index", "principal"), comp),
            "status": (("E", "t0", "t1"), status),
        },
        coords={"E": [1.0, 2.0], "arm_index": [1.0]},
        attrs={"actuation_dims": "t0 t1"},
    )
    s = softrod.design_summary(ds, voxel=0.001)
    assert s["reachable"].values.tolist() == [24, 25]
    assert s["workspace_dimension"].values.tolist() == [2, 2]
    # Design 0 lost one corner: the hull is the square minus a triangle.
    assert s["hull_area"].values[0] == pytest.approx(0.02**2 - 0.5 * 0.005**2)
    assert s["hull_area"].values[1] == pytest.approx(0.04**2)
    k = 1.0 / c[1].ravel()
    assert s["stiffness_min"].values[1] == pytest.approx(k.min())
    assert s["stiffness_median"].values[1] == pytest.approx(np.median(k))
    corner = 1.0 + 100 * 0.02 * np.sqrt(2)
    assert s["centre_periphery_ratio"].values[1] == pytest.approx(corner / 1.0)
    assert s["stiffness_min"].attrs["units"] == "N/m"


def test_design_summary_of_a_real_sweep():
    arm = softrod.examples.load("tapered_cable_arm").with_parameters(
        {"solver": {"integrator": "rk4", "steps": 30}}
    )
    ds = softrod.sweep(
        arm,
        actuation={"tendons[0].tension": np.linspace(0, 1.5, 16)},
        design={"tendons[0].ratio": [0.2, 0.5]},
        outputs=("tip_pose", "translational_compliance"),
        progress=False,
    )
    s = softrod.design_summary(ds)
    assert s["hull_area"].dims == ("tendons[0].ratio",)
    # A planar arm: its tips stay in the x-z plane; a larger offset curls the arm further.
    assert (s["workspace_dimension"] == 2).all()
    assert s["hull_area"].values[1] > s["hull_area"].values[0] > 0
    # At zero tension both designs are the same straight rod: the same softest stiffness.
    k0 = 1.0 / ds["translational_compliance"].isel({"tendons[0].tension": 0}).values[:, 0, 0]
    assert k0[0] == k0[1]


def _dominated_brute_force(a, b):
    n = len(a)
    return np.array(
        [
            any((a[j] <= a[i] and b[j] <= b[i]) and (a[j] < a[i] or b[j] < b[i]) for j in range(n))
            for i in range(n)
        ]
    )


def test_pareto_front_against_brute_force():
    rng = np.random.default_rng(7)
    a = rng.integers(0, 12, 300).astype(float)  # ties on purpose
    b = rng.integers(0, 12, 300).astype(float)
    a[5] = np.nan
    for better in [("min", "min"), ("max", "min"), ("max", "max")]:
        p = softrod.Pareto(a, b, better=better)
        sa = a if better[0] == "min" else -a
        sb = b if better[1] == "min" else -b
        ok = np.isfinite(sa)
        expect = np.zeros(len(a), bool)
        expect[ok] = ~_dominated_brute_force(sa[ok], sb[ok])
        assert np.array_equal(p.mask, expect), better
        # Ordered by the first objective, best first.
        first = p.values[:, 0] if better[0] == "min" else -p.values[:, 0]
        assert np.all(np.diff(first) >= 0)


def test_pareto_of_dataarrays_keeps_coordinates():
    da = xr.DataArray(
        [[1.0, 2.0], [3.0, 0.5]], dims=("x", "y"), coords={"x": [10, 20], "y": [1, 2]}, name="area"
    )
    db = xr.DataArray([[4.0, 1.0], [2.0, 5.0]], dims=("x", "y"), name="stiffness")
    p = softrod.Pareto(da, db, better=("max", "max"))
    assert p.names == ("area", "stiffness")
    assert p.mask.dims == ("x", "y")
    t = p.table()
    assert list(t.columns) == ["x", "y", "area", "stiffness"]
    assert t.iloc[0]["area"] == 3.0 and t.iloc[0]["x"] == 20
    with pytest.raises(softrod.ParameterError, match="better"):
        softrod.Pareto(da, db, better=("up", "max"))
    with pytest.raises(softrod.ParameterError, match="same shape"):
        softrod.Pareto([1.0, 2.0], [1.0])


@pytest.mark.filterwarnings("ignore::softrod.StabilityWarning")
def test_a_robot_with_obstacles_or_a_tip_constraint_solves_its_contacts():
    # (Sweeps solved the free rod: their samples went into obstacles, reported converged and
    # stable; then robots with obstacles were refused.) Each sample is now the
    # contact solve of its actuation: robot.solve's, bit for bit; out of the sphere; and the
    # base carries the contacts' force, the only external load (N(0) = the contacts' sum).
    niti = softrod.load_robot(softrod.examples.path("niti_two_segment")).with_tensions([0] * 6)
    kw = {"rod": niti.rod, "tendons": niti.tendons, "solver": niti.solver}
    centre, radius, rod_radius = np.array([0.0, 0.13, 0.3]), 0.04, 0.7e-3
    sphere = softrod.Robot(**kw, obstacles=[softrod.Sphere(tuple(centre), radius)])
    tensions = [0.0, 1.0, 2.0, 3.0, 4.0]
    axis = {"tendons[0].tension": tensions}
    outs = ("tip_pose", "contacts", "backbone", "stability")
    ds = softrod.sweep(
        sphere, actuation=axis, outputs=outs, arm_index=np.linspace(0, 1, 41), progress=False
    )
    assert (ds["status"].values == 0).all()
    assert "every sample starts cold" in ds.attrs["warm_start_rule"]
    touching = 0
    for k, t in enumerate(tensions):
        sol = sphere.with_tensions([t, 0, 0, 0, 0, 0]).solve()
        np.testing.assert_array_equal(ds["tip_position"].values[k], sol.tip_position)
        assert ds["contact_count"].values[k] == len(sol.contacts)
        assert ds["stable"].values[k] == int(sol.stable)
        gap = np.linalg.norm(ds["backbone_position"].values[k] - centre, axis=1)
        assert gap.min() >= radius + rod_radius - 1e-9
        f = ds["contact_force"].values[k]
        np.testing.assert_allclose(sol.base_wrench[:3], f, atol=1e-9 * max(1e-3, abs(f).max()))
        assert np.isnan(ds["tip_reaction"].values[k]).all()
        touching += int(ds["contact_count"].values[k] > 0)
    assert touching >= 2
    # A pinned tip: the tip stays on the pin; the reaction is the solve's.
    point = (0.0, 0.05, 0.39)
    pin = softrod.Robot(**kw, tip_constraint=softrod.Pin(point))
    tensions = [0.5, 1.0, 1.5]
    axis = {"tendons[0].tension": tensions}
    ds = softrod.sweep(pin, actuation=axis, outputs=("tip_pose", "contacts"), progress=False)
    assert (ds["status"].values == 0).all()
    for k, t in enumerate(tensions):
        sol = pin.with_tensions([t, 0, 0, 0, 0, 0]).solve()
        np.testing.assert_allclose(ds["tip_position"].values[k], point, atol=1e-9)
        np.testing.assert_array_equal(ds["tip_reaction"].values[k], sol.tip_reaction)
    with pytest.raises(TypeError, match="`robot`"):
        softrod.sweep(None)  # (a ParameterTypeError: a TypeError naming `robot`)


def test_an_integer_parameter_is_a_design_axis():
    # (Grid values are floats: solver.steps = 40.0 was refused as "must be an integer".)
    niti = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    ds = softrod.sweep(niti, design={"solver.steps": [40, 80, 10**9]}, progress=False)
    assert list(ds["design_error"].values[:2]) == ["", ""]
    assert "must be <= " in ds["design_error"].values[2]
    for k, steps in enumerate((40, 80)):
        want = niti.with_parameters({"solver.steps": steps}).solve().tip_position
        np.testing.assert_array_equal(ds["tip_position"].values[k], want)
