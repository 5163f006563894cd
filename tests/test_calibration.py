"""Calibration of the planar cable arm: recovery of known parameters from noise-free and noisy
shapes and from rendered photos, exact Jacobians against central differences, identifiability
and the coverage of the confidence intervals."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import softrod
from softrod.analysis import calibration as cal

TRUTH = softrod.PlanarCableArm(0.27, 0.015, 0.0074, 0.3, 140e3)
START = softrod.PlanarCableArm.published_arm()  # E 110 kPa, a 1/3
TENSIONS = (0.5, 1.0, 2.0)


def shapes(arm, tensions=TENSIONS, n=100, angle=0.0):
    """Backbones of ``arm`` from the planar solver (independent of the sensitivity march)."""
    c, s = np.cos(angle), np.sin(angle)
    out = []
    for t in tensions:
        sol = arm.solve(t, n)
        p = np.column_stack([sol.x, sol.y]) @ np.array([[c, s], [-s, c]])
        out.append((t, p))
    return out


def rel(a, b):
    return abs(a - b) / abs(b)


@pytest.mark.parametrize("metric", ["arm-index", "nearest"])
def test_noise_free_shapes_recover_e_and_a(metric):
    c = softrod.calibrate(START, shapes(TRUTH), ["youngs_modulus", "offset_ratio"], metric=metric)
    assert rel(c.values["youngs_modulus"], 140e3) < 1e-6
    assert rel(c.values["offset_ratio"], 0.3) < 1e-6
    assert c.rms < 1e-9
    assert c.identifiable and c.success
    assert isinstance(c.robot, softrod.PlanarCableArm)
    assert rel(c.robot.youngs_modulus, 140e3) < 1e-6
    assert [r.shape for r in c.residuals] == (
        [(100, 2)] * 3 if metric == "arm-index" else [(100,)] * 3
    )


def test_noise_free_recovery_of_four_parameters_with_aliases():
    truth = softrod.PlanarCableArm(0.27, 0.016, 0.0074, 0.3, 140e3)
    data = shapes(truth, tensions=(0.5, 1.0, 2.0, 3.0), angle=0.02)
    c = softrod.calibrate(START, data, ["E", "a", "base_radius", "base_angle"])
    want = {"youngs_modulus": 140e3, "offset_ratio": 0.3, "base_radius": 0.016}
    for k, v in want.items():
        assert rel(c.values[k], v) < 1e-6, (k, c.values[k])
    assert abs(c.values["base_angle"] - 0.02) < 1e-8


def test_tip_poses_recover_e_and_a():
    data = []
    for t in (0.5, 1.0, 2.0):
        sol = TRUTH.solve(t, 2)
        data.append((t, [sol.tip[0], sol.tip[1], sol.tip_angle]))
    c = softrod.calibrate(START, data, ["E", "a"])
    assert rel(c.values["youngs_modulus"], 140e3) < 1e-6
    assert rel(c.values["offset_ratio"], 0.3) < 1e-6
    assert c.residuals[0].shape == (3,)


@pytest.mark.parametrize("metric", ["arm-index", "nearest"])
def test_jacobian_matches_central_differences(metric):
    rng = np.random.default_rng(3)
    data = [(t, p + rng.normal(0, 1e-3, p.shape)) for t, p in shapes(TRUTH, n=40)]
    data.append((1.5, [0.2, 0.1, 0.8]))
    names = ["youngs_modulus", "offset_ratio", "tension_scale", "pretension", "tip_radius"]
    names += ["base_angle"]
    model = cal._model_for(START)
    meas = cal._measurements(data, None, 2)
    values = {
        "youngs_modulus": 120e3,
        "offset_ratio": 0.31,
        "tension_scale": 1.05,
        "pretension": 0.02,
        "tip_radius": 0.0072,
        "base_angle": 0.01,
    }
    _, jac, _ = cal._stack(model, values, names, meas, metric)
    for j, n in enumerate(names):
        h = 1e-5 * max(abs(values[n]), 0.01)
        plus, minus = dict(values), dict(values)
        plus[n] += h
        minus[n] -= h
        rp, _, _ = cal._stack(model, plus, names, meas, metric)
        rm, _, _ = cal._stack(model, minus, names, meas, metric)
        fd = (rp - rm) / (2 * h)
        err = np.max(np.abs(jac[:, j] - fd)) / np.max(np.abs(fd))
        assert err < 1e-6, (n, err)


def test_modulus_with_tension_scale_is_not_identifiable():
    with pytest.warns(softrod.IdentifiabilityWarning, match="youngs_modulus and tension_scale"):
        c = softrod.calibrate(START, shapes(TRUTH), ["youngs_modulus", "tension_scale"])
    assert not c.identifiable
    assert c.condition > 1e12
    assert np.isinf(c.standard_errors["youngs_modulus"])
    assert np.isinf(c.standard_errors["tension_scale"])


def test_e_and_a_are_identifiable_without_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error", softrod.IdentifiabilityWarning)
        c = softrod.calibrate(START, shapes(TRUTH), ["E", "a"])
    assert c.condition < 1e4


def _noisy_fit(rng, sigma, n=30):
    data = [(t, p + rng.normal(0.0, sigma, p.shape)) for t, p in shapes(TRUTH, n=n)]
    return softrod.calibrate(START, data, ["E", "a"])


def _coverage(reps, seed):
    rng = np.random.default_rng(seed)
    hits = {"youngs_modulus": 0, "offset_ratio": 0}
    truth = {"youngs_modulus": 140e3, "offset_ratio": 0.3}
    for _ in range(reps):
        c = _noisy_fit(rng, 2e-4)
        for k, (lo, hi) in c.interval(0.95).items():
            hits[k] += lo <= truth[k] <= hi
    return {k: v / reps for k, v in hits.items()}


def test_interval_coverage_bounded():
    # 40 repetitions: a true 95 % coverage gives <= 33 hits with probability 1.4 %.
    cov = _coverage(40, seed=11)
    assert all(v >= 34 / 40 for v in cov.values()), cov


@pytest.mark.slow
def test_interval_coverage_200_repetitions():
    cov = _coverage(200, seed=12)
    assert all(0.90 <= v <= 0.99 for v in cov.values()), cov


def test_standard_errors_match_the_scatter_of_noisy_fits():
    # Oracle: the spread of the estimates over repetitions (the covariance formula predicts
    # it to first order in the noise).
    rng = np.random.default_rng(5)
    fits = [_noisy_fit(rng, 2e-4) for _ in range(60)]
    e = np.array([c.values["youngs_modulus"] for c in fits])
    se = np.median([c.standard_errors["youngs_modulus"] for c in fits])
    assert 0.7 < np.std(e, ddof=1) / se < 1.4


def test_three_rendered_photos_give_e_within_1_percent_and_a_within_2_percent():
    from arm_photos import render_published_arm

    data = []
    for i, t in enumerate((1.0, 2.0, 3.0)):
        photo = render_published_arm(t, seed=100 + i)
        bb = softrod.extract_backbone(
            photo.image, scale=photo.scale, base=photo.base, direction=photo.direction
        )
        data.append((t, bb))
    start = softrod.PlanarCableArm(0.27, 0.015, 0.0074, 0.25, 70e3)
    for metric in ("arm-index", "nearest"):
        c = softrod.calibrate(start, data, ["youngs_modulus", "offset_ratio"], metric=metric)
        assert rel(c.values["youngs_modulus"], 110e3) < 0.01, c
        assert rel(c.values["offset_ratio"], 1 / 3) < 0.02, c
    before = softrod.backbone_distance(start.solve(3.0, 400), data[2][1]).max
    after = softrod.backbone_distance(c.robot.solve(3.0, 400), data[2][1]).max
    assert after < 0.05 * before


def test_observations_with_separate_actuations_and_backbones_in_pixels():
    data = shapes(TRUTH)
    start = softrod.PlanarCableArm(0.27, 0.015, 0.0074, 0.3, 110e3)
    points, tensions = [p for _, p in data], [t for t, _ in data]
    c = softrod.calibrate(start, points, ["E"], actuations=tensions, bounds={"E": (1e4, 1e6)})
    assert rel(c.values["youngs_modulus"], 140e3) < 1e-6
    from arm_photos import render_published_arm

    photo = render_published_arm(1.0)
    bb = softrod.extract_backbone(photo.image)
    with pytest.raises(softrod.ParameterError, match="pixels"):
        softrod.calibrate(START, [(1.0, bb)], ["E"])


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"parameters": ["stiffness"]}, "stiffness"),
        ({"parameters": []}, "parameters"),
        ({"parameters": ["E", "youngs_modulus"]}, "repeated"),
        ({"metric": "closest"}, "metric"),
        ({"bounds": {"E": (2e5, 1e5)}}, "bounds"),
        ({"bounds": {"a": (0.0, 0.5)}}, "bounds"),
        ({"initial": {"E": 1e9}, "bounds": {"E": (1e4, 1e6)}}, "initial"),
        ({"measurements": [(1.0, np.ones((5, 2)))]}, "zero length"),
        ({"measurements": []}, "measurements"),
        ({"measurements": [(1.0, np.zeros((5, 3)))]}, "measurements\\[0\\]"),
        ({"measurements": [(1.0, [[0, 0], [np.nan, 1]])]}, "measurements\\[0\\]"),
        ({"measurements": [("x", np.eye(2))]}, "measurements\\[0\\]\\[0\\]"),
        ({"max_evaluations": 0}, "max_evaluations"),
    ],
)
def test_bad_input_is_a_named_error(kwargs, match):
    args = {"measurements": shapes(TRUTH, n=10), "parameters": ["E"]}
    args.update(kwargs)
    with pytest.raises(softrod.ParameterError, match=match):
        softrod.calibrate(START, args.pop("measurements"), args.pop("parameters"), **args)


def _partial_backbone():
    """The first 10 of 50 points of the published arm at 2 N (a fuzz run's input): fitting E
    to it makes the optimiser try moduli at which 2 N would compress the arm to zero length."""
    arm = softrod.PlanarCableArm(0.27, 0.015, 0.0074, 0.25, 70e3)
    sol = START.solve(2.0, 50)
    return arm, [(2.0, np.column_stack([sol.x, sol.y])[:10])]


def test_a_trial_modulus_that_cannot_carry_the_tension_is_rejected_not_blamed_on_it():
    arm, data = _partial_backbone()
    assert 2.0 < arm.max_tension  # the user's tension is valid at the robot's modulus
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", cal.IdentifiabilityWarning)
        fit = softrod.calibrate(arm, data, ["E"])
    # The fit ends at a modulus where the measured tension is valid, and says trials were
    # rejected there.
    assert fit.robot.max_tension > 2.0 and np.isfinite(fit.rms)
    assert "rejected" in fit.message and "youngs_modulus" in fit.message
    assert np.all(np.isfinite(fit.residuals[0]))
    # The residual at the result is the model's at that modulus.
    again = softrod.calibrate(fit.robot, data, ["E"], max_evaluations=1)
    np.testing.assert_allclose(again.residuals[0], fit.residuals[0], rtol=1e-9, atol=1e-15)


def test_starting_values_at_which_the_tension_is_invalid_are_named():
    arm, data = _partial_backbone()
    with pytest.raises(softrod.ParameterError) as info:
        softrod.calibrate(arm, data, ["E"], initial={"E": 1e3})
    text = str(info.value)
    assert info.value.parameter == "initial"
    assert "youngs_modulus = 1000" in text and "starting value" in text
    assert "`tension` = 2" in text  # the model's refusal, at that modulus


def test_a_fit_whose_every_trial_is_rejected_names_the_trial_value(monkeypatch):
    # A model that can be evaluated at the start and nowhere else: the fit cannot proceed,
    # and the error says the fitted parameter's trial value makes the tension invalid.
    arm, data = _partial_backbone()
    evaluate = cal._PlanarModel.evaluate

    def only_at_the_start(self, values, names, m, metric):
        if values["youngs_modulus"] != 70e3:
            raise softrod.ParameterError("invalid parameter `tension` = 2: must be < 1 N")
        return evaluate(self, values, names, m, metric)

    monkeypatch.setattr(cal._PlanarModel, "evaluate", only_at_the_start)
    with pytest.raises(softrod.ConvergenceError) as info:
        softrod.calibrate(arm, data, ["E"])
    text = str(info.value)
    assert "starting values (youngs_modulus = 70000)" in text
    assert "every trial value" in text and "trial value youngs_modulus = " in text
    assert "`tension` = 2" in text
    # As every ConvergenceError: the evaluations made, the residual reached, the load factor.
    assert info.value.iterations >= 2 and np.isfinite(info.value.residual)
    assert info.value.load_factor == 1.0
