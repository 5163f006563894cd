"""The command line on bad input: one line, exit 2 (bad input) or 3 (no result), inputs never
overwritten, outputs checked before any work; and the options every command shares."""

import json
import shutil
import subprocess
import sys

import numpy as np
import pytest

import softrod
from softrod.cli import build_parser, main

NITI = softrod.examples.path("niti_two_segment")
TENSILE = softrod.examples.DATA / "silicone-tensile" / "Dragon Skin 10 MEDIUM.csv"


@pytest.fixture
def robot_copy(tmp_path):
    path = tmp_path / "R.toml"
    shutil.copy(NITI, path)
    return path


def _run(argv, capsys):
    status = main([str(a) for a in argv])
    cap = capsys.readouterr()
    return status, cap.out, cap.err.strip().splitlines()


def _one_error_line(err):
    lines = [ln for ln in err if not ln.startswith("wrote ")]
    assert len(lines) == 1 and lines[0].startswith("softrod: error: "), err
    return lines[0]


def test_version(capsys):
    status, out, _ = _run(["--version"], capsys)
    assert status == 0 and out.strip() == f"softrod {softrod.__version__}"


@pytest.mark.parametrize(
    "argv",
    [
        [],
        ["nope"],
        ["solve"],
        ["planar", "--bogus"],
        ["planar", "-t", "abc"],
        ["planar", "-n", "1.5"],
        ["workspace", "niti_two_segment"],
        ["solve", "niti_two_segment", "--tensions", "nan", "0", "0", "0", "0", "0"],
        ["fit", str(TENSILE), "--terms", "x"],
    ],
)
def test_usage_errors_are_one_line_exit_2(argv, capsys):
    status, _, err = _run(argv, capsys)
    assert status == 2
    _one_error_line(err)


def test_output_equal_to_the_input_is_refused(robot_copy, capsys):
    before = robot_copy.read_bytes()
    for option in ("--csv", "--json", "--plot"):
        value = robot_copy if option != "--plot" else robot_copy.with_suffix(".png")
        if option == "--plot":
            continue
        status, _, err = _run(["solve", robot_copy, option, value], capsys)
        assert status == 2 and option in _one_error_line(err)
    # The same file through another spelling of its path.
    alias = robot_copy.parent / "." / robot_copy.name
    status, _, err = _run(["compliance", robot_copy, "--json", alias], capsys)
    assert status == 2
    assert robot_copy.read_bytes() == before


def test_the_input_of_fit_is_never_overwritten(tmp_path, capsys):
    data = tmp_path / "curve.csv"
    shutil.copy(TENSILE, data)
    before = data.read_bytes()
    for option in ("--csv", "--json"):
        status, _, err = _run(["fit", data, option, data], capsys)
        assert status == 2 and "FILE" in _one_error_line(err)
    assert data.read_bytes() == before


def test_two_outputs_on_one_file_are_refused(tmp_path, capsys):
    x = tmp_path / "x"
    status, _, err = _run(["solve", "niti_two_segment", "--csv", x, "--json", x], capsys)
    assert status == 2 and "--json" in _one_error_line(err) and not x.exists()
    png = tmp_path / "a.png"
    argv = ["compliance", "niti_two_segment", "--plot", png, "--gamma-plot", png]
    status, _, err = _run(argv, capsys)
    assert status == 2 and "--gamma-plot" in _one_error_line(err)


def test_bad_figure_extension_is_named_before_any_work(tmp_path, capsys):
    status, out, err = _run(["solve", "niti_two_segment", "--plot", tmp_path / "x.badext"], capsys)
    line = _one_error_line(err)
    assert status == 2 and "--plot" in line and "png" in line and out == ""
    status, _, err = _run(
        ["solve", "niti_two_segment", "--csv", tmp_path / "no/such/x.csv"], capsys
    )
    assert status == 2 and "--csv" in _one_error_line(err)


def test_examples_by_name_and_unknown_names(capsys):
    status, out, _ = _run(["solve", "niti_two_segment"], capsys)
    assert status == 0 and "niti-two-segment" in out
    status, _, err = _run(["solve", "niti_two_segmnt"], capsys)
    assert status == 2 and "niti_two_segment" in _one_error_line(err)
    status, _, err = _run(["solve", "missing/robot.toml"], capsys)
    assert status == 1
    _one_error_line(err)


def test_a_bad_robot_file_gives_every_error_on_one_line(tmp_path, capsys):
    f = tmp_path / "bad.toml"
    f.write_text(
        "[rod]\nlength = -1\n[rod.section]\nradius = 0.001\n[rod.material]\n"
        "youngs_modulu = 1e9\n[solver]\nsteps = true\n"
    )
    status, _, err = _run(["solve", f], capsys)
    line = _one_error_line(err)
    assert status == 2
    for field in ("rod.length", "rod.material.youngs_modulu", "solver.steps"):
        assert f"`{field}`" in line
    assert "did you mean `youngs_modulus`?" in line


@pytest.mark.parametrize(
    ("argv", "option"),
    [
        (["workspace", "niti_two_segment", "--sweep", "0:-4"], "--sweep"),
        (["workspace", "niti_two_segment", "--sweep", "1:abc"], "--sweep"),
        (["workspace", "niti_two_segment", "--sweep", "9:4"], "--sweep"),
        (["workspace", "niti_two_segment", "--sweep", "0:4", "--sweep", "0:2"], "--sweep"),
        (
            ["workspace", "niti_two_segment", "--sweep", "0:4", "--sweep", "1:4", "--sweep", "2:4"],
            "--sweep",
        ),
        (["workspace", "niti_two_segment", "--sweep", "0:4", "--n", "0"], "--n"),
        (["study", "--levels", "1"], "--levels"),
    ],
)
def test_sweep_options_are_named(argv, option, capsys):
    status, _, err = _run(argv, capsys)
    line = _one_error_line(err)
    assert status == 2 and f"`{option}`" in line and "tensions[" not in line


def test_compliance_ellipsoid_arc_lengths_are_checked_before_the_solve(tmp_path, capsys):
    plot = tmp_path / "c.png"
    for argv, needle in [
        (["--at", "0.1"], "needs `--plot FILE`"),
        (["--at", "nan", "--plot", plot], "in [0, 0.4] m"),
        (["--at", "0.1", "0.5", "--plot", plot], "in [0, 0.4] m"),
    ]:
        status, out, err = _run(["compliance", "niti_two_segment", *argv], capsys)
        line = _one_error_line(err)
        assert status == 2 and "`--at`" in line and needle in line, line
        assert out == "" and not plot.exists()


def test_pressures_beside_tensions(capsys):
    p = ["--pressures", *["10e3"] * 6]
    status, out, _ = _run(["solve", "pneumatic_arm", *p], capsys)
    expected = softrod.examples.load("pneumatic_arm").solve(pressures=[10e3] * 6)
    assert status == 0 and f"{expected.tip_position[0]: .9f}" in out
    status, _, err = _run(["solve", "pneumatic_arm", "--pressures", "1"], capsys)
    assert status == 2 and "pressures" in _one_error_line(err)
    for command in ("compliance", "compare", "solve"):
        assert "--pressures" in _options(command) and "--tensions" in _options(command)


def _options(command):
    parser = build_parser()
    sub = next(a for a in parser._actions if hasattr(a, "choices") and a.choices)
    return {o for a in sub.choices[command]._actions for o in a.option_strings}


def test_every_option_has_a_help_string():
    parser = build_parser()
    sub = next(a for a in parser._actions if hasattr(a, "choices") and a.choices)
    for name, p in sub.choices.items():
        for action in p._actions:
            assert action.help, f"softrod {name} {action.dest} has no help"


def test_compliance_without_tendons_prints_one_tangent(tmp_path, capsys):
    f = tmp_path / "rod.toml"
    f.write_text(
        "[rod]\nlength = 0.3\n[rod.section]\nradius = 0.001\n[rod.material]\n"
        "youngs_modulus = 1e9\npoisson_ratio = 0.4\n"
    )
    status, out, _ = _run(["compliance", f], capsys)
    assert status == 0 and out.count("exact tangent tip compliance") == 1
    assert "no tendons" in out and "fixed length" not in out


def _ten_tendons(tmp_path, tension):
    rows = "".join(
        f"[[tendons]]\ndistance = 0.0005\nangle_deg = {36 * i}\ntension = {tension}\n"
        for i in range(10)
    )
    f = tmp_path / "ten.toml"
    f.write_text(
        "[rod]\nlength = 0.3\n[rod.section]\nradius = 0.001\n[rod.material]\n"
        "youngs_modulus = 1e9\npoisson_ratio = 0.4\n" + rows
    )
    return f


def test_compliance_computes_everything_before_printing(tmp_path, capsys):
    # Ten tendons: the tangent at fixed length may be refused by the core; then nothing is
    # printed, not half a report.
    f = _ten_tendons(tmp_path, 0.1)
    status, out, err = _run(["compliance", f], capsys)
    if status != 0:
        assert status in (2, 3) and out == ""
        _one_error_line(err)
    else:
        assert out.count("exact tangent tip compliance") == 2


def test_workspace_refuses_an_all_nan_map(tmp_path, capsys):
    f = _ten_tendons(tmp_path, 0.0)
    png = tmp_path / "map.png"
    argv = ["workspace", f, "--sweep", "0:1", "--n", "3", "--tangent", "length", "--plot", png]
    status, out, err = _run(argv, capsys)
    if status == 0:  # the core computes the tangent for ten tendons: a real map
        assert png.stat().st_size > 10_000 and "nan" not in out.lower()
    else:
        assert status in (2, 3) and not png.exists()
        _one_error_line(err)


def test_workspace_of_a_chamber_only_robot_says_it_has_no_tendons(capsys):
    # A tendon-plus-chamber robot is mapped with its chambers (test_trust_defects.py).
    argv = ["workspace", "pneumatic_arm", "--sweep", "0:1"]
    status, _, err = _run(argv, capsys)
    line = _one_error_line(err)
    assert status == 2 and "no tendons" in line and "chambers" in line


def test_data_outputs_of_every_computing_command(tmp_path, capsys):
    runs = {
        "compliance": ["compliance", "niti_two_segment"],
        "workspace": ["workspace", "niti_two_segment", "--sweep", "0:4", "--n", "4"],
        "compare": ["compare", "niti_two_segment", "--repeats", "1"],
        "fit": ["fit", TENSILE, "-m", "yeoh", "ogden", "--stretch-max", "3"],
        "solve": ["solve", "niti_two_segment"],
    }
    for name, argv in runs.items():
        csv, js = tmp_path / f"{name}.csv", tmp_path / f"{name}.json"
        status, _, _ = _run([*argv, "--csv", csv, "--json", js], capsys)
        assert status == 0, name
        assert json.loads(js.read_text())
        assert len(csv.read_text().splitlines()) >= 2
    table = np.genfromtxt(tmp_path / "workspace.csv", delimiter=",", names=True)
    assert len(table) == 4 and np.all(table["converged"] == 1)
    sol = softrod.examples.load("niti_two_segment").with_tensions([4.0, 0, 0, 0, 0, 0]).solve()
    np.testing.assert_allclose(
        [table["x"][-1], table["y"][-1], table["z"][-1]], sol.tip_position, rtol=1e-12
    )


def test_fit_reports_each_model_and_a_plausibility_check(capsys):
    argv = ["fit", TENSILE, "-m", "mooney-rivlin", "yeoh", "nonsense", "--stretch-max", "3"]
    status, out, _ = _run(argv, capsys)
    assert status == 0
    assert "nonsense: fit failed" in out
    blocks = out.split("\n\n")
    mr = next(b for b in blocks if b.startswith("Mooney"))
    yeoh = next(b for b in blocks if b.startswith("Yeoh"))
    assert "NOT plausible" in mr and "NOT plausible" not in yeoh


def test_check_fit_flags_an_implausible_small_strain_modulus():
    from softrod.analysis.materials import PLAUSIBLE_MODULUS_RATIO, check_fit

    curve = softrod.read_tensile_csv(TENSILE)
    mr = check_fit(curve, curve.fit("mooney-rivlin", stretch_range=(1.0, 3.0)))
    assert not mr.modulus_plausible and mr.modulus_ratio < 1 / PLAUSIBLE_MODULUS_RATIO
    yeoh = check_fit(curve, curve.fit("yeoh", stretch_range=(1.0, 3.0)))
    assert yeoh.plausible
    unstable = softrod.Yeoh(20e3, -2e3)
    assert np.any(np.asarray(unstable.nominal_tangent(np.linspace(1, 5, 50))) <= 0)


def test_schema_command_prints_the_json_schema(capsys):
    status, out, _ = _run(["schema"], capsys)
    assert status == 0 and json.loads(out) == softrod.io.robot_file_json_schema()


def test_console_script_has_no_traceback(tmp_path):
    f = tmp_path / "bad.toml"
    f.write_bytes(b"[rod]\nlength = \xff\n")
    for argv in (["solve", str(f)], ["workspace", "niti_two_segment", "--sweep", "0:-4"]):
        r = subprocess.run(
            [sys.executable, "-m", "softrod", *argv], capture_output=True, text=True, check=False
        )
        assert r.returncode == 2 and "Traceback" not in r.stderr
        assert len(r.stderr.strip().splitlines()) == 1


def test_study_runs_outside_the_repository(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    argv = ["study", "--levels", "2", "--max-pressure", "20e3", "--out", "figs", "--json", "s.json"]
    status, out, _ = _run(argv, capsys)
    assert status == 0 and "hyperelastic" in out
    data = json.loads((tmp_path / "s.json").read_text())
    assert set(data) == {"hyperelastic", "linear"}
    assert len(list((tmp_path / "figs").glob("*.png"))) == 4


def test_study_counts_and_records_the_pressure_sets_that_failed(tmp_path, monkeypatch, capsys):
    import csv
    import re

    monkeypatch.chdir(tmp_path)
    argv = ["study", "--levels", "2", "--max-pressure", "1e12", "--out", "figs"]
    status, out, _ = _run([*argv, "--csv", "s.csv", "--json", "s.json"], capsys)
    assert status == 0  # partial failure: reported, not an error (docs/cli.md)
    with open("s.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    data = json.loads((tmp_path / "s.json").read_text())
    printed = dict(re.findall(r"(\w+) \(.*\n.*?(\d+) of 8 pressure sets failed", out))
    for material in ("hyperelastic", "linear"):
        mine = [r for r in rows if r["material"] == material]
        failed = [r for r in mine if r["status"] != "0"]
        assert 0 < len(failed) < 8 and printed[material] == str(len(failed))
        assert all(r["error"] and r["x"] == "nan" for r in failed)
        assert all(r["error"] == "" for r in mine if r["status"] == "0")
        assert data[material]["status"] == [int(r["status"]) for r in mine]
        assert data[material]["error"] == [r["error"] for r in mine]


def _digest(path):
    import hashlib

    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.mark.parametrize(
    "argv, option",
    [
        (["planar", "-t", "1", "--plot", "{f}.png"], "--plot"),
        (["planar", "-t", "1", "--csv", "{f}.csv"], "--csv"),
        (["solve", "niti_two_segment", "--json", "{f}.json"], "--json"),
        (["schema", "-o", "{f}.json"], "--output"),
        (["demo", "--plot", "{f}.png"], "--plot"),
    ],
)
def test_an_existing_file_is_never_overwritten_without_overwrite(argv, option, tmp_path, capsys):
    # A file the user has (here: text under the output name) survives every command that
    # would write there; --overwrite replaces it.
    argv = [a.replace("{f}", str(tmp_path / "mine")) for a in argv]
    target = next(tmp_path / a.rsplit("/", 1)[-1] for a in argv if "mine" in a)
    target.write_text("my data\n")
    before = _digest(target)
    status, _, err = _run(argv, capsys)
    line = _one_error_line(err)
    assert status == 2 and option in line and "exists (pass --overwrite" in line
    assert _digest(target) == before
    status, _, _ = _run([*argv, "--overwrite"], capsys)
    assert status == 0 and _digest(target) != before


def test_demo_replaces_its_own_figure_and_no_other_file(tmp_path, monkeypatch, capsys):
    # The demo run twice in one folder replaces the figure it wrote (marked in the PNG's
    # metadata); a PNG of the same name that the demo did not write is refused.
    from PIL import Image

    from softrod.cli._common import DEMO_MARK

    monkeypatch.chdir(tmp_path)
    png = tmp_path / "softrod-demo.png"
    assert _run(["demo"], capsys)[0] == 0
    with Image.open(png) as im:
        assert im.info.get("Source") == DEMO_MARK
    assert _run(["demo"], capsys)[0] == 0
    Image.new("RGB", (4, 4)).save(png)
    before = _digest(png)
    status, _, err = _run(["demo"], capsys)
    assert status == 2 and "exists (pass --overwrite" in _one_error_line(err)
    assert _digest(png) == before


def test_earlier_names_of_the_examples_and_the_published_arm_keep_working(capsys):
    # The example robots and the planar arm were renamed after the papers; the earlier names
    # give the same objects.
    from softrod.examples import ALIASES

    for old, new in ALIASES.items():
        assert softrod.examples.path(old) == softrod.examples.path(new)
        assert old not in softrod.examples.names() and new in softrod.examples.names()
    assert _run(["solve", "seed000_arm"], capsys)[0] == 0
    a, b = softrod.PlanarCableArm.seed_arm(), softrod.PlanarCableArm.published_arm()
    assert np.array_equal(a.solve(2.0).x, b.solve(2.0).x)
    assert softrod.analysis.seed001_study is softrod.analysis.compliance_study
