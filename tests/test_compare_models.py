"""softrod.compare_models and `softrod compare`: the call, the table, exit codes, the plot."""

import numpy as np
import pytest

import softrod
from softrod.cli import main
from softrod.plot import plot_models

ROBOTS = softrod.examples.ROBOTS
NITI = ROBOTS / "niti_two_segment.toml"
TAPERED_ARM = ROBOTS / "tapered_cable_arm.toml"


def _loaded_rod(tip_force):
    return softrod.Robot.from_dict(
        {
            "name": "loaded",
            "rod": {
                "length": 0.3,
                "section": {"radius": 0.001},
                "material": {"youngs_modulus": 50e9, "poisson_ratio": 0.3},
            },
            "tendons": [{"distance": 0.005, "angle_deg": 45, "tension": 2.0}],
            "loads": {"tip_force": tip_force},
        }
    )


def test_niti_robot_pcc_applies_and_is_exact_planar_does_not():
    comp = softrod.compare_models(NITI, repeats=1)
    assert [r.model for r in comp.results] == ["cosserat", "pcc", "planar"]
    ref, p = comp["cosserat"], comp["pcc"]
    assert ref.applies and ref.tip_error == 0.0 and ref.positions.shape[1] == 3
    assert p.applies and "2 segment" in p.note
    # Unloaded tendon-driven PCC is the Cosserat solution: only the RK4 error is left.
    assert p.tip_error < 1e-8 and p.angle_error < 1e-8 and p.backbone_max < 1e-8
    assert p.positions.shape == (len(np.unique(ref.solution.s)), 3)
    assert p.solve_time > 0 and ref.solve_time > 0
    assert not comp["planar"].applies and "6 tendons" in comp["planar"].note
    with pytest.raises(KeyError):
        comp["nope"]


def test_tapered_cable_arm_planar_applies_pcc_does_not():
    comp = softrod.compare_models(softrod.load_robot(TAPERED_ARM), repeats=2)
    pl = comp["planar"]
    assert pl.applies and pl.tip_rotation is None and "anchor=0.27)" in pl.note
    assert 0 < pl.tip_error < 0.05 and 0 < pl.angle_error < 0.5
    assert pl.backbone_max >= pl.backbone_mean > 0
    assert not comp["pcc"].applies and "tapered" in comp["pcc"].note


def test_tip_load_keeps_pcc_rules_out_planar_and_tensions_override():
    comp = softrod.compare_models(_loaded_rod([0.2, 0.0, 0.0]), repeats=1)
    assert comp["pcc"].applies and comp["pcc"].tip_error > 1e-5  # the ansatz is not exact
    assert not comp["planar"].applies and "external loads" in comp["planar"].note
    zero = softrod.compare_models(_loaded_rod([0.0, 0.0, 0.0]), tensions=[0.0], repeats=1)
    assert np.allclose(zero["cosserat"].tip_position, [0, 0, 0.3])
    assert "not at a constant offset" not in zero["pcc"].note


def test_a_robot_that_cannot_be_described_is_compared_with_cosserat_only():
    # A section given by a Python function has no description to map onto PCC or planar.
    section = softrod.FunctionSection(lambda s: (3.1e-6, 7.8e-13, 7.8e-13, 1.6e-12))
    rod = softrod.Rod(0.3, section, softrod.LinearElastic(50e9, 0.3))
    robot = softrod.Robot(rod, tendons=[softrod.Tendon((0.005, 0.0), 1.0)])
    comp = softrod.compare_models(robot, repeats=1)
    assert comp["cosserat"].applies
    assert not comp["pcc"].applies and "cannot" in comp["pcc"].note
    assert not comp["planar"].applies


def test_bad_arguments_raise_parameter_error():
    with pytest.raises(softrod.ParameterError):
        softrod.compare_models(NITI, repeats=0)
    with pytest.raises(softrod.ParameterError):
        softrod.compare_models(NITI, tensions=[1.0])


def test_table_lists_models_and_reasons():
    text = softrod.compare_models(TAPERED_ARM, repeats=1).table()
    lines = text.splitlines()
    assert lines[0].split()[0] == "model" and "time (ms)" in lines[0]
    assert lines[2].startswith("cosserat") and lines[3].startswith("planar")
    assert "pcc: does not apply: a tapered section" in text


def test_cli_prints_table_writes_plot_and_exits(tmp_path, capsys):
    png = tmp_path / "models.png"
    assert main(["compare", str(NITI), "--repeats", "1", "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "niti-two-segment" in out and "\npcc " in out
    assert "planar: does not apply" in out
    assert png.read_bytes()[:4] == b"\x89PNG" and png.stat().st_size > 10_000
    assert main(["compare", str(NITI), "--tensions", "1", "2"]) == 2
    assert main(["compare", str(tmp_path / "missing.toml")]) == 1
    assert main(["compare", str(TAPERED_ARM), "--tensions", "1", "--repeats", "1"]) == 0
    assert "\nplanar " in capsys.readouterr().out


def test_plot_models_draws_every_applicable_model():
    fig = plot_models(softrod.compare_models(TAPERED_ARM, repeats=1))
    ax = fig.axes[0]
    labels = [ln.get_label() for ln in ax.get_lines()]
    assert labels[0] == "cosserat" and labels[1].startswith("planar (tip")
    assert "pcc" in ax.get_legend().get_title().get_text()


def test_mappings_follow_the_base_pose_and_chambers_split_segments():
    c, s = np.cos(0.5), np.sin(0.5)
    base = {"position": [0.1, 0.2, -0.3], "rotation": [[c, -s, 0], [s, c, 0], [0, 0, 1]]}

    def arm(pose, angle):
        rod = {
            "length": 0.27,
            "section": {"type": "tapered", "base_radius": 0.015, "tip_radius": 0.0074},
            "material": {"youngs_modulus": 110e3, "poisson_ratio": 0.5},
        }
        if pose:
            rod["base_pose"] = base
        tendon = {"routing": "radius_proportional", "ratio": 1 / 3, "angle_deg": angle}
        return softrod.Robot.from_dict({"rod": rod, "tendons": [{**tendon, "tension": 2.0}]})

    # Rotating and shifting the base, or turning the tendon, moves both models rigidly.
    ref = softrod.compare_models(arm(False, 0), repeats=1)["planar"]
    for pose, angle in [(True, 0), (True, 60), (False, -120)]:
        got = softrod.compare_models(arm(pose, angle), repeats=1)["planar"]
        assert got.tip_error == pytest.approx(ref.tip_error, rel=1e-6)
        assert got.angle_error == pytest.approx(ref.angle_error, rel=1e-6)
    chambers = softrod.Robot.from_dict(
        {
            "rod": {
                "length": 0.3,
                "base_pose": base,
                "section": {"radius": 0.01},
                "material": {"youngs_modulus": 1e6, "poisson_ratio": 0.45},
            },
            "chambers": [
                {"pressure": 3e3, "radius": 0.003, "distance": 0.005, "angle_deg": 30, "end": 0.15},
                {"pressure": 2e3, "radius": 0.003, "distance": 0.005, "start": 0.15},
            ],
        }
    )
    p = softrod.compare_models(chambers, repeats=1)["pcc"]
    assert p.applies and "2 segment" in p.note and p.tip_error < 1e-9


def test_planar_anchor_is_the_tendon_end():
    robot = softrod.load_robot(TAPERED_ARM)
    data = {**robot.source, "tendons": [{**robot.source["tendons"][0], "end": 0.2}]}
    comp = softrod.compare_models(softrod.Robot.from_dict(data), repeats=1)
    pl = comp["planar"]
    assert pl.applies and "anchor=0.2)" in pl.note
    # Both arms run straight beyond the anchor; they differ by millimetres, as at full length.
    assert (
        0 < pl.tip_error < 0.05
        and pl.tip_error < softrod.compare_models(TAPERED_ARM)["planar"].tip_error
    )
