"""Calibration of Cosserat robots: recovery of known parameters of the NiTi tendon robot and of
a hyperelastic pneumatic arm from noise-free shapes and tips, the exact Jacobian (linearised
boundary-value problem) against central differences of full solves, the stiffness-load identity
and identifiability."""

from __future__ import annotations

import math

import numpy as np
import pytest

import softrod
from softrod.analysis import calibration as cal

TENSIONS = [
    [4.0, 0.0, 0.0, 0.0, 2.0, 0.0],
    [0.0, 3.0, 0.0, 0.0, 0.0, 1.0],
    [0.0, 0.0, 3.0, 1.5, 0.0, 0.0],
    [2.0, 2.0, 0.0, 0.0, 1.0, 1.0],
    [1.0, 0.0, 2.0, 2.0, 0.0, 0.5],
]
S = np.linspace(0.0, 0.4, 30)


@pytest.fixture(scope="module")
def niti():
    return softrod.load_robot(softrod.examples.path("niti_two_segment"))


@pytest.fixture(scope="module")
def truth(niti):
    return niti.with_parameters({"rod.material.youngs_modulus": 50e9, "tendons[0].distance": 0.011})


def rel(a, b):
    return abs(a / b - 1.0)


def pneumatic(mu=60e3, area=2.0e-5):
    return softrod.Robot.from_dict(
        {
            "rod": {
                "length": 0.12,
                "section": {"type": "circular", "radius": 0.01},
                "material": {"type": "neo_hookean", "mu": mu},
            },
            "chambers": [
                {"pressure": 0.0, "area": area, "distance": 0.005, "angle_deg": 0.0},
                {"pressure": 0.0, "area": 2.0e-5, "distance": 0.005, "angle_deg": 120.0},
                {"pressure": 0.0, "area": 2.0e-5, "distance": 0.005, "angle_deg": 240.0},
            ],
        }
    )


def test_markers_on_the_niti_robot_recover_e_and_a_tendon_distance(niti, truth):
    data = [(t, truth.solve(t, s_out=S).position, S) for t in TENSIONS]
    names = ["rod.material.youngs_modulus", "tendons[0].distance"]
    c = softrod.calibrate(niti, data, names)
    assert rel(c.values["rod.material.youngs_modulus"], 50e9) < 1e-6
    assert rel(c.values["tendons[0].distance"], 0.011) < 1e-6
    assert c.residuals[0].shape == (30, 3)
    assert isinstance(c.robot, softrod.Robot)
    assert rel(c.robot.parameter("rod.material.youngs_modulus"), 50e9) < 1e-6


def test_backbones_at_equal_arm_index_recover_e(niti):
    truth = niti.with_parameters({"rod.material.youngs_modulus": 50e9})
    data = [(t, truth.solve(t, s_out=S).position) for t in TENSIONS]
    c = softrod.calibrate(niti, data, ["youngs_modulus"])
    # The undeformed arm index differs from the measured (deformed) one by the axial strain
    # of NiTi under the tendons (~5e-5): the floor of this metric on a Cosserat rod.
    assert rel(c.values["rod.material.youngs_modulus"], 50e9) < 1e-4


def test_tip_poses_recover_e_and_a_base_rotation(niti):
    truth = niti.with_parameters({"rod.material.youngs_modulus": 50e9})
    tilt = truth.with_parameters({"rod.base_pose.rotation": cal_rot_x(0.02).tolist()})
    data = []
    for t in TENSIONS:
        sol = tilt.solve(t)
        pose = np.eye(4)
        pose[:3, :3], pose[:3, 3] = sol.tip_rotation, sol.tip_position
        data.append((t, pose))
    c = softrod.calibrate(niti, data, ["rod.material.youngs_modulus", "base_rotation_x"])
    assert rel(c.values["rod.material.youngs_modulus"], 50e9) < 1e-6
    assert abs(c.values["base_rotation_x"] - 0.02) < 1e-8
    assert c.residuals[0].shape == (6,)


def cal_rot_x(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def test_hyperelastic_pneumatic_arm_recovers_mu_and_a_chamber_area():
    truth = pneumatic(mu=75e3, area=2.4e-5)
    pressures = [[20e3, 0.0, 0.0], [0.0, 20e3, 5e3], [10e3, 0.0, 20e3], [15e3, 15e3, 0.0]]
    s = np.linspace(0.0, 0.12, 20)
    data = [({"pressures": p}, truth.solve(pressures=p, s_out=s).position, s) for p in pressures]
    c = softrod.calibrate(pneumatic(), data, ["rod.material.mu", "chambers[0].area"])
    assert rel(c.values["rod.material.mu"], 75e3) < 1e-6
    assert rel(c.values["chambers[0].area"], 2.4e-5) < 1e-6


def test_jacobian_matches_central_differences_of_full_solves(niti):
    rng = np.random.default_rng(2)
    s = np.linspace(0.0, 0.4, 12) + 0.004
    s[-1] = 0.4
    data = [
        (t, niti.solve(t, s_out=s).position + rng.normal(0, 1e-3, (12, 3)), s) for t in TENSIONS[:2]
    ]
    data.append((TENSIONS[2], niti.solve(TENSIONS[2], s_out=s).position + 1e-3))
    sol = niti.solve(TENSIONS[3])
    pose = np.eye(4)
    pose[:3, :3] = cal_rot_x(0.05) @ sol.tip_rotation
    pose[:3, 3] = sol.tip_position + 1e-3
    data.append((TENSIONS[3], pose))
    names = [
        "rod.material.youngs_modulus",
        "tendons[0].distance",
        "tension_scale",
        "tendon_offset_scale",
        "base_rotation_y",
    ]
    values = {
        "rod.material.youngs_modulus": 50e9,
        "tendons[0].distance": 0.011,
        "tension_scale": 1.1,
        "tendon_offset_scale": 0.95,
        "base_rotation_y": 0.01,
    }
    model = cal._model_for(niti)
    meas = cal._measurements(data, None, 3, model.check_actuation)
    _, jac, _ = cal._stack(model, values, names, meas, "arm-index")
    for j, n in enumerate(names):
        h = 1e-5 * max(abs(values[n]), 0.1)
        plus, minus = dict(values), dict(values)
        plus[n] += h
        minus[n] -= h
        fd = (
            cal._stack(model, plus, names, meas, "arm-index")[0]
            - cal._stack(model, minus, names, meas, "arm-index")[0]
        ) / (2 * h)
        err = np.max(np.abs(jac[:, j] - fd)) / np.max(np.abs(fd))
        assert err < 1e-6, (n, err)


def test_stiffness_column_is_minus_the_sum_of_the_load_columns(niti):
    # A linear-elastic (or stress-scaled) rod under actuation loads only: scaling every
    # modulus and every load by the same factor leaves the equilibrium unchanged, so
    # E d/dE = -(sum of T_i d/dT_i + sum of p_j d/dp_j) exactly.
    sol = niti.solve(TENSIONS[3])
    d = sol.sensitivities(["stiffness_scale", "tension_scale"])
    pose = d["pose"]
    assert np.max(np.abs(pose[:, :, 0] + pose[:, :, 1])) < 1e-10 * np.max(np.abs(pose))
    p = [20e3, 5e3, 0.0]
    sol = pneumatic().solve(pressures=p)
    d = sol.sensitivities(["stiffness_scale", "pressure[0]", "pressure[1]", "pressure[2]"])
    pose = d["pose"]
    loads = sum(p[j] * pose[:, :, 1 + j] for j in range(3))
    assert np.max(np.abs(pose[:, :, 0] + loads)) < 1e-10 * np.max(np.abs(pose))


def test_modulus_with_tension_scale_is_not_identifiable(niti, truth):
    data = [(t, truth.solve(t, s_out=S).position, S) for t in TENSIONS]
    with pytest.warns(softrod.IdentifiabilityWarning, match="tension_scale"):
        c = softrod.calibrate(niti, data, ["rod.material.youngs_modulus", "tension_scale"])
    assert not c.identifiable


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ({"parameters": ["rod.material.poisson_ratio"]}, "poisson_ratio"),
        ({"parameters": ["tendons[9].distance"]}, "tendons\\[9\\]"),
        ({"parameters": ["rod.length"]}, "rod.length"),
        ({"metric": "nearest"}, "nearest"),
        ({"measurements": [([1.0, 2.0], np.linspace([0, 0, 0], [0, 0, 0.4], 5))]}, "6 tendons"),
        ({"measurements": [(TENSIONS[0], np.zeros((5, 2)))]}, "measurements\\[0\\]"),
        ({"measurements": [(TENSIONS[0], np.ones((3, 3)), [0.1, 0.2])]}, "arc length"),
        # A positive parameter started at or below 0: named as > 0, not as the default
        # bounds a factor of 1000 about it (they were shown as [0.001, 1000] and (0, 0)).
        (
            {"initial": {"youngs_modulus": -1.0}},
            r"initial\['rod.material.youngs_modulus'\]` = -1.0: must be > 0",
        ),
        ({"initial": {"youngs_modulus": 0.0}}, r"= 0.0: must be > 0"),
        (
            {"bounds": {"youngs_modulus": (1e9, 1e9)}},
            r"= \(1000000000.0, 1000000000.0\): must be low",
        ),
    ],
)
def test_bad_input_is_a_named_error(niti, args, match):
    kwargs = {
        "measurements": [(TENSIONS[0], niti.solve(TENSIONS[0], s_out=S).position)],
        "parameters": ["youngs_modulus"],
    }
    kwargs.update(args)
    with pytest.raises(softrod.ParameterError, match=match) as e:
        softrod.calibrate(niti, kwargs.pop("measurements"), kwargs.pop("parameters"), **kwargs)
    # (The name the message gives is the error's `parameter`: it was None for several.)
    assert e.value.parameter and f"`{e.value.parameter}`" in str(e.value)


@pytest.mark.parametrize(
    ("name", "hint"),
    [
        ("rod.material.youngs_modulu", "youngs_modulus"),
        ("rod.materal.youngs_modulus", "material"),
        ("tendons[0].distanc", "distance"),
    ],
)
def test_a_misspelt_parameter_path_is_an_unknown_key_with_a_suggestion(niti, name, hint):
    data = [(TENSIONS[0], niti.solve(TENSIONS[0], s_out=S).position)]
    with pytest.raises(softrod.ParameterError, match=f"did you mean `{hint}`") as info:
        softrod.calibrate(niti, data, [name])
    assert info.value.parameter == "parameters" and name in str(info.value)
    assert "stiffness_scale" not in str(info.value)


@pytest.mark.parametrize(
    "pose",
    [2.0 * np.eye(4), np.diag([1.0, 1.0, -1.0, 1.0]), np.vstack([np.eye(4)[:3], [0, 0, 1, 1]])],
)
def test_a_tip_pose_that_is_not_rigid_is_refused(pose):
    # 2 I was accepted and the fit went on to a modulus of 1.3e13 Pa (an optimiser trial),
    # blamed on `rod.material.youngs_modulus`.
    robot = softrod.examples.load("niti_two_segment")
    with pytest.raises(softrod.ParameterError, match="rigid transform") as e:
        softrod.calibrate(robot, [([1, 0, 0, 0, 0.5, 0], pose)], ["rod.material.youngs_modulus"])
    assert "measurements[0]" in str(e.value)


def test_a_fit_stuck_far_from_its_measurements_is_reported_poor(niti):
    # Measurements the file's own robot makes (E = 54 GPa); from 1 GPa the fit stops at a
    # local minimum near 0.83 GPa whose residuals are about a quarter of the rod's length,
    # with a tight confidence interval: reported by a PoorFitWarning. From the file's value
    # the modulus comes back and nothing is reported.
    t = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    data = [(t, niti.solve(t, s_out=S).position, S)]
    name = "rod.material.youngs_modulus"
    with pytest.warns(softrod.PoorFitWarning) as caught:
        stuck = softrod.calibrate(niti, data, [name], initial={name: 1e9})
    assert stuck.rms > cal.POOR_FIT_FRACTION * 0.4
    assert caught[0].message.rms == pytest.approx(stuck.rms)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", softrod.PoorFitWarning)
        good = softrod.calibrate(niti, data, [name])
    assert rel(good.values[name], 54e9) < 1e-6 and good.rms < 1e-9


def test_more_starts_leave_the_local_minimum_and_every_start_is_reported(niti):
    # The stuck fit above with eight starts (log-uniform in [1e6, 1e12] Pa, the default
    # bounds around 1 GPa): some reach the modulus the measurements were made with.
    import warnings

    t = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    data = [(t, niti.solve(t, s_out=S).position, S)]
    name = "rod.material.youngs_modulus"
    with warnings.catch_warnings():
        warnings.simplefilter("error", softrod.PoorFitWarning)
        fit = softrod.calibrate(niti, data, [name], initial={name: 1e9}, starts=8)
    assert rel(fit.values[name], 54e9) < 1e-6 and fit.rms < 1e-9
    assert len(fit.starts) == 8 and fit.starts[0]["initial"] == {name: 1e9}
    # The first start alone stops at the local minimum; the best start is returned.
    assert fit.starts[0]["rms"] > cal.POOR_FIT_FRACTION * 0.4
    fitted = [st for st in fit.starts if "rms" in st]
    assert min(st["rms"] for st in fitted) == pytest.approx(fit.rms, rel=1e-9)
    assert fit.initial in [st["initial"] for st in fitted]
    for st in fit.starts:  # drawn within the bounds; the others say why they were left
        assert 1e6 <= st["initial"][name] <= 1e12
        assert "error" in st or st["evaluations"] >= 1
    assert fit.evaluations == sum(st.get("evaluations", 0) for st in fit.starts)
    # The same starts every time (seeded).
    again = softrod.calibrate(niti, data, [name], initial={name: 1e9}, starts=8)
    assert [st["initial"] for st in again.starts] == [st["initial"] for st in fit.starts]


def test_starts_are_checked(niti):
    t = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    data = [(t, niti.solve(t, s_out=S).position, S)]
    name = "rod.material.youngs_modulus"
    with pytest.raises(softrod.ParameterError, match="`starts` = 0") as e:
        softrod.calibrate(niti, data, [name], starts=0)
    assert e.value.parameter == "starts"
    with pytest.raises(softrod.ParameterError, match="finite, to draw `starts`") as e:
        softrod.calibrate(niti, data, [name], starts=2, bounds={name: (1e9, math.inf)})
    assert e.value.parameter == f"bounds[{name!r}]"
