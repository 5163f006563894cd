"""Property-based fuzz of robot descriptions (hypothesis).

Generated descriptions, valid and broken, either load into a robot that writes itself back to
an equal robot, or raise one ParameterError whose ``errors`` are located FieldErrors; raw
bytes as a file raise a ParameterError too. Never another exception.
"""

import math

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import softrod
from softrod import Robot
from softrod.io import FieldError

FINITE = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False, allow_infinity=False)
POSITIVE = st.floats(min_value=1e-4, max_value=1.0)
# Anything a TOML file can hold where a number is expected.
WILD = st.one_of(
    FINITE,
    st.floats(),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.booleans(),
    st.text(max_size=5),
    st.lists(FINITE, max_size=4),
    st.dictionaries(st.sampled_from(["a", "radius"]), FINITE, max_size=2),
)


def maybe_wild(strategy):
    """Mostly the valid strategy, sometimes anything."""
    return st.one_of(strategy, strategy, strategy, WILD)


def vec(n):
    return st.lists(st.floats(-10, 10), min_size=n, max_size=n)


def descriptions(wild: bool):
    """Robot descriptions; with ``wild``, any field may hold anything and keys may be unknown."""
    w = maybe_wild if wild else (lambda strategy: strategy)
    SECTIONS = st.one_of(
        st.fixed_dictionaries({"radius": w(POSITIVE)}),
        st.fixed_dictionaries(
            {"type": st.just("tapered"), "base_radius": POSITIVE, "tip_radius": w(POSITIVE)}
        ),
        st.fixed_dictionaries(
            {
                "type": st.just("tube"),
                "outer_radius": POSITIVE,
                "inner_radius": st.floats(0, 0.5e-4),
            }
        ),
        st.fixed_dictionaries({"type": st.sampled_from(["table", "hexagon", "circular"])}),
    )
    MATERIALS = st.one_of(
        st.fixed_dictionaries(
            {"youngs_modulus": w(st.floats(1e3, 1e11)), "poisson_ratio": st.floats(0, 0.5)}
        ),
        st.fixed_dictionaries({"type": st.just("neo_hookean"), "mu": w(st.floats(1e3, 1e6))}),
        st.fixed_dictionaries(
            {"type": st.just("yeoh"), "c10": st.floats(1e3, 1e5), "c20": st.floats(-1e3, 1e3)}
        ),
        st.fixed_dictionaries(
            {"type": st.just("mooney_rivlin"), "c10": st.floats(1e3, 1e5), "c01": FINITE}
        ),
        st.fixed_dictionaries(
            {
                "type": st.just("ogden"),
                "mu": st.lists(FINITE, min_size=1, max_size=3),
                "alpha": st.lists(FINITE, min_size=1, max_size=3),
            }
        ),
        st.fixed_dictionaries(
            {
                "silicone": st.sampled_from(
                    [*softrod.SILICONES, "ecoflex 00-30", "Dragon Skin 99"]
                ),
                "type": st.sampled_from(["yeoh", "neo_hookean", "mooney_rivlin", "linear"]),
            }
        ),
    )
    TENDONS = st.one_of(
        st.fixed_dictionaries(
            {
                "distance": w(st.floats(0, 0.01)),
                "angle_deg": w(st.floats(-360, 360)),
                "tension": w(st.floats(0, 5)),
            },
            optional={"end": w(st.floats(0.01, 1.0))},
        ),
        st.fixed_dictionaries({"offset": w(vec(2)), "tension": st.floats(0, 5)}),
        st.fixed_dictionaries(
            {"routing": st.just("radius_proportional"), "ratio": w(st.floats(0, 0.99))}
        ),
        st.fixed_dictionaries(
            {
                "routing": st.sampled_from(["helical", "helix"]),
                "radius": POSITIVE,
                "pitch": w(FINITE),
            }
        ),
    )
    CHAMBERS = st.fixed_dictionaries(
        {
            "pressure": w(FINITE),
            "radius": st.floats(1e-4, 1e-3),
            "distance": st.floats(0, 1e-3),
        },
        optional={"start": st.floats(0, 0.2), "end": st.floats(0.01, 1.0), "area": POSITIVE},
    )
    LOADS = st.fixed_dictionaries(
        {},
        optional={
            "tip_force": w(vec(3)),
            "gravity": w(vec(3)),
            "tip_frame": st.sampled_from(["world", "body", "wrld"]),
            "point_loads": st.lists(
                st.fixed_dictionaries({"s": w(st.floats(0, 1)), "force": vec(3)}),
                max_size=2,
            ),
        },
    )
    SOLVER = st.fixed_dictionaries(
        {},
        optional={
            "integrator": st.sampled_from(["rk4", "adaptive", "euler"]),
            "steps": w(st.integers(1, 200)),
            "rtol": w(st.floats(1e-12, 1e-3)),
            "continuation": w(st.booleans()),
        },
    )
    ROD = st.fixed_dictionaries(
        {
            "length": w(st.floats(0.01, 1.0)),
            "section": w(SECTIONS),
            "material": MATERIALS,
        },
        optional={
            "density": w(st.floats(100, 10000)),
            "inextensible": w(st.booleans()),
            "rest_curvature": w(vec(3)),
            "base_pose": st.fixed_dictionaries({"position": w(vec(3))}),
        },
    )
    DESCRIPTIONS = st.fixed_dictionaries(
        {"rod": w(ROD)},
        optional={
            "name": w(st.text(max_size=10)),
            "tendons": st.lists(w(TENDONS), max_size=4),
            "chambers": st.lists(CHAMBERS, max_size=2),
            "loads": w(LOADS),
            "solver": SOLVER,
            **({"colour": st.just("red")} if wild else {}),
        },
    )
    return DESCRIPTIONS


def _check_error(exc):
    assert isinstance(exc, softrod.ParameterError)
    assert exc.errors and all(isinstance(e, FieldError) for e in exc.errors)
    assert all(isinstance(e.location, str) and e.message for e in exc.errors)
    assert exc.parameter == exc.errors[0].location


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.one_of(descriptions(wild=False), descriptions(wild=True)))
def test_generated_descriptions_load_or_raise_located_errors(data):
    try:
        robot = Robot.from_dict(data)
    except softrod.ParameterError as exc:
        _check_error(exc)
        return
    again = Robot.from_toml(robot.to_toml())
    assert again == robot
    for t in robot.tendons:
        assert math.isfinite(t.tension)
    np.testing.assert_array_equal(np.asarray(again.rod.base_pose), np.asarray(robot.rod.base_pose))


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=200))
def test_arbitrary_bytes_as_a_robot_file(tmp_path_factory, raw):
    path = tmp_path_factory.mktemp("bytes") / "r.toml"
    path.write_bytes(raw)
    try:
        softrod.load_robot(path)
    except softrod.ParameterError as exc:
        _check_error(exc)
