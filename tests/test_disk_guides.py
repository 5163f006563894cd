"""``Robot.with_disk_guides``: tendons through spacer disks at a given spacing.

Oracles: the disks are where the spacing puts them (the same floats as an explicit list), and
as the disks get dense the chords converge to the tendon in a continuous channel at second
order in the spacing (frictionless), and to the channel with the same capstan coefficient
(with friction); bad input is named.
"""

from __future__ import annotations

import numpy as np
import pytest

import softrod

TAU = [1.0, 0.0, 0.3, 0.0, 0.5, 0.1]


@pytest.fixture(scope="module")
def niti() -> softrod.Robot:
    return softrod.load_robot(softrod.examples.path("niti_two_segment"))


def test_disks_are_where_the_spacing_puts_them(niti):
    robot = niti.with_disk_guides(0.025, friction=0.3)
    for t in robot.tendons:
        end = t.end if t.end is not None else 0.4
        n = round(end / 0.025)
        assert t.guides == [end * k / n for k in range(1, n)]
        assert t.guide_friction == [0.3] * (n - 1)
    # A spacing that does not divide the span: disks at multiples of it below the end.
    odd = niti.with_disk_guides(0.03, tendons=[0, 3])
    assert odd.tendons[0].guides == [0.03 * k for k in range(1, 7)]  # end 0.2
    assert odd.tendons[3].guides == [0.03 * k for k in range(1, 14)]  # end 0.4
    assert not odd.tendons[1].guides
    # The original is unchanged and the new description round-trips through its file.
    assert not niti.tendons[0].guides
    assert softrod.Robot.from_toml(robot.to_toml()) == robot


def test_dense_disks_converge_to_the_channel_at_second_order(niti):
    channel = niti.solve(TAU).tip_position
    errors = [
        np.linalg.norm(niti.with_disk_guides(h).solve(TAU).tip_position - channel)
        for h in (0.05, 0.025, 0.0125)
    ]
    # Measured: 1.28e-3, 3.08e-4, 7.62e-5 m (ratios 4.15, 4.04).
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 3.6) & (ratios < 4.4)), (errors, ratios)


def test_dense_disks_with_friction_converge_to_the_channel_with_friction(niti):
    mu = 0.2
    channel = niti.with_parameters({f"tendons[{i}].friction": mu for i in range(6)})
    target = channel.solve(TAU).tip_position
    errors = [
        np.linalg.norm(niti.with_disk_guides(h, friction=mu).solve(TAU).tip_position - target)
        for h in (0.05, 0.025, 0.0125)
    ]
    # Measured: 1.32e-3, 3.35e-4, 9.15e-5 m (ratios 3.94, 3.66).
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all(ratios > 3.3), (errors, ratios)
    assert errors[-1] < 1e-4


@pytest.mark.parametrize(
    ("kwargs", "named"),
    [
        ({"spacing": 0.0}, "spacing"),
        ({"spacing": float("nan")}, "spacing"),
        ({"spacing": 0.5}, "spacing"),
        ({"spacing": 1e-308}, "spacing"),
        ({"spacing": 1e-4}, "spacing"),
        ({"spacing": 0.02, "friction": -0.1}, "friction"),
        ({"spacing": 0.02, "tendons": [6]}, "tendons[0]"),
        ({"spacing": 0.02, "tendons": [1, 1]}, "tendons"),
        ({"spacing": 0.02, "tendons": "0"}, "tendons"),
    ],
)
def test_bad_input_is_named(niti, kwargs, named):
    with pytest.raises(softrod.ParameterError) as info:
        niti.with_disk_guides(**kwargs)
    assert info.value.parameter == named
    assert f"`{named}`" in str(info.value)


def test_other_routings_are_refused_by_name():
    spec = softrod.load_robot(softrod.examples.path("niti_two_segment")).spec
    data = spec.model_dump(mode="python", exclude_none=True)
    data["tendons"][0] = {"routing": "helical", "radius": 0.01, "pitch": 0.1, "tension": 0.0}
    robot = softrod.Robot.from_dict(data)
    with pytest.raises(softrod.ParameterError, match="constant") as info:
        robot.with_disk_guides(0.02)
    assert info.value.parameter == "tendons[0].routing"
    robot.with_disk_guides(0.02, tendons=[1, 2])
