"""The robot-file schema: located errors, suggestions, all errors at once, strict types, files
that are not UTF-8 TOML, and the JSON Schema published in the docs."""

import json
from pathlib import Path

import pytest

import softrod
from softrod.io import FieldError, robot_file_json_schema, validate_robot_dict
from softrod.robot import load_robot

ROOT = Path(__file__).resolve().parent.parent


def _base(**extra):
    data = {
        "rod": {
            "length": 0.3,
            "section": {"radius": 0.001},
            "material": {"youngs_modulus": 1e9, "poisson_ratio": 0.4},
        }
    }
    data.update(extra)
    return data


def _errors(data):
    with pytest.raises(softrod.ParameterError) as info:
        validate_robot_dict(data)
    errors = info.value.errors
    assert all(isinstance(e, FieldError) for e in errors)
    assert info.value.parameter == errors[0].location
    return errors


def _locations(data):
    return [e.location for e in _errors(data)]


def test_a_valid_description_validates():
    spec = validate_robot_dict(_base(tendons=[{"distance": 0.01, "tension": 1}]))
    assert spec.rod.length == 0.3 and spec.tendons[0].tension == 1.0


@pytest.mark.parametrize(
    ("data", "location", "kind"),
    [
        (
            _base(tendons=[{"distance": 0.01}, {"offset": [0, 0.01]}, {"distance": -0.01}]),
            "tendons[2].distance",
            "range",
        ),
        (_base(solver={"steps": True}), "solver.steps", "type"),
        (_base(solver={"steps": "abc"}), "solver.steps", "type"),
        (_base(solver={"steps": 2.0}), "solver.steps", "type"),
        (_base(solver={"steps": 10**9}), "solver.steps", "range"),
        (
            _base(tendons=[{"distance": 0.01, "angle_deg": float("inf")}]),
            "tendons[0].angle_deg",
            "type",
        ),
        (_base(tendons=[{"distance": float("nan")}]), "tendons[0].distance", "type"),
        (_base(tendons="abc"), "tendons", "type"),
        (_base(tendons=["abc"]), "tendons[0]", "type"),
        (_base(loads="abc"), "loads", "type"),
        (_base(loads={"tip_force": [0, "a", 0]}), "loads.tip_force[1]", "type"),
        (_base(loads={"tip_force": [0, 0]}), "loads.tip_force", "type"),
        (_base(loads={"point_loads": [{"force": [1, 0, 0]}]}), "loads.point_loads[0].s", "missing"),
        (_base(rod="abc"), "rod", "type"),
        (_base(name=3), "name", "type"),
        (
            _base(rod={"length": 0.3, "section": "abc", "material": {"youngs_modulus": 1.0}}),
            "rod.section",
            "type",
        ),
        (
            _base(
                rod={
                    "length": 0.3,
                    "section": {"type": "tapred"},
                    "material": {"youngs_modulus": 1.0},
                }
            ),
            "rod.section.type",
            "choice",
        ),
        (
            _base(
                rod={
                    "length": 0.3,
                    "section": {"radius": 1e-3},
                    "material": {"youngs_modulus": 1.0},
                    "inextensible": 1,
                }
            ),
            "rod.inextensible",
            "type",
        ),
        (_base(tendons=[{"routing": "helical", "radius": 0.01}]), "tendons[0].pitch", "missing"),
        (_base(tendons=[{"distance": 0.01, "end": 0.5}]), "tendons[0].end", "range"),
        (
            _base(chambers=[{"radius": 1e-3, "distance": 0.0, "start": 0.3}]),
            "chambers[0].start",
            "range",
        ),
        (_base(loads={"gravity": [0, 0, -9.81]}), "loads.gravity", "rule"),
        (_base(solver={"integrator": "rk5"}), "solver.integrator", "choice"),
        (_base(colour="red"), "colour", "unknown_key"),
    ],
)
def test_errors_are_located_and_typed(data, location, kind):
    errors = _errors(data)
    assert (errors[0].location, errors[0].kind) == (location, kind)


def test_a_misspelt_key_is_named_with_a_suggestion():
    data = _base()
    data["rod"]["material"] = {"youngs_modulu": 1e9, "poisson_ratio": 0.4}
    (err,) = _errors(data)  # one error, not "unknown key" and "missing key" separately
    assert err.location == "rod.material.youngs_modulu"
    assert err.kind == "unknown_key" and err.suggestion == "youngs_modulus"
    assert "did you mean `youngs_modulus`?" in str(err)  # the message is the contract here


@pytest.mark.parametrize(
    ("data", "location", "suggestion"),
    [
        (_base(tendon=[]), "tendon", "tendons"),
        (_base(solver={"stpes": 3}), "solver.stpes", "steps"),
        (_base(tendons=[{"routing": "helicl"}]), "tendons[0].routing", "helical"),
        (_base(solver={"integrator": "adaptve"}), "solver.integrator", "adaptive"),
        (_base(loads={"tip_frame": "bdy"}), "loads.tip_frame", "body"),
    ],
)
def test_suggestions_for_keys_and_choices(data, location, suggestion):
    err = next(e for e in _errors(data) if e.location == location)
    assert err.suggestion == suggestion


def test_silicone_names_are_checked_with_a_suggestion():
    data = _base()
    data["rod"]["material"] = {"silicone": "dragon skin 11"}
    (err,) = _errors(data)
    assert err.location == "rod.material.silicone" and err.suggestion == "Dragon Skin 10"


def test_every_error_is_reported_at_once():
    data = {
        "rod": {"length": -1, "section": {"radius": 0}, "material": {"youngs_modulu": 1}},
        "tendons": [{"distance": 0.01, "tension": True}, {"offset": [1]}],
        "solver": {"steps": "abc", "stepz": 3},
    }
    locations = set(_locations(data))
    assert locations >= {
        "rod.length",
        "rod.section.radius",
        "rod.material.youngs_modulu",
        "tendons[0].tension",
        "tendons[1].offset",
        "solver.steps",
        "solver.stepz",
    }


def test_rules_between_keys_of_one_table():
    assert _locations(_base(tendons=[{"distance": 0.01, "offset": [0.01, 0]}])) == [
        "tendons[0].distance"
    ]
    assert _locations(_base(tendons=[{"offset": [0.01, 0], "angle_deg": 3}])) == [
        "tendons[0].angle_deg"
    ]
    assert _locations(_base(chambers=[{"distance": 0.001}])) == ["chambers[0].area"]
    table = {"type": "table", "s": [0, 0.3], "area": [1, 1], "ix": [1], "iy": [1, 1], "j": [1, 1]}
    data = _base()
    data["rod"]["section"] = table
    assert _locations(data) == ["rod.section.ix"]


def test_constructor_errors_are_located_in_the_file():
    data = _base()
    data["rod"]["section"] = {"type": "tube", "outer_radius": 0.001, "inner_radius": 0.002}
    with pytest.raises(softrod.ParameterError) as info:
        softrod.Robot.from_dict(data)
    assert info.value.errors[0].location.startswith("rod.section")
    assert info.value.errors[0].kind == "model"


def test_tables_as_strings_and_the_file_as_a_string_are_rejected():
    assert _locations("abc") == [""]
    assert _locations(_base(chambers="x")) == ["chambers"]


def test_non_utf8_and_invalid_toml_files(tmp_path):
    f = tmp_path / "latin1.toml"
    f.write_bytes('name = "bras à câble"\n'.encode("latin-1"))
    with pytest.raises(softrod.ParameterError) as info:
        load_robot(f)
    assert info.value.errors[0].location == "" and info.value.source == str(f)
    g = tmp_path / "bad.toml"
    g.write_text("[rod\nlength = 1")
    with pytest.raises(softrod.ParameterError) as info:
        load_robot(g)
    assert info.value.errors[0].kind == "type"


def test_the_published_json_schema_is_the_generated_one():
    committed = json.loads((ROOT / "docs" / "robot-file.schema.json").read_text())
    assert committed == robot_file_json_schema(), (
        "regenerate: softrod schema -o docs/robot-file.schema.json"
    )


def test_the_json_schema_names_every_table_and_law():
    schema = robot_file_json_schema()
    assert set(schema["properties"]) == {
        "name",
        "description",
        "rod",
        "tendons",
        "chambers",
        "loads",
        "solver",
        "obstacles",
        "tip_constraint",
    }
    assert {
        "CircularSectionSpec",
        "TaperedSectionSpec",
        "TubeSectionSpec",
        "TableSectionSpec",
        "LinearMaterialSpec",
        "NeoHookeanSpec",
        "MooneyRivlinSpec",
        "YeohSpec",
        "OgdenSpec",
        "SiliconeSpec",
        "ConstantTendonSpec",
        "RadiusProportionalTendonSpec",
        "HelicalTendonSpec",
        "ChamberSpec",
        "LoadsSpec",
        "SolverSpec",
    } <= set(schema["$defs"])
    assert schema["$defs"]["RodSpec"]["additionalProperties"] is False
