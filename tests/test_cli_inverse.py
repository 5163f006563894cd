"""``softrod inverse``: the actuation printed and written reaches the target (checked by an
independent forward solve at the tensions read back from the CSV); bad input is one line with
exit status 2, a target out of reach exit status 3 after every target was reported; inputs are
never overwritten."""

import csv
import json
import shutil

import numpy as np
import pytest

import softrod
from softrod.cli import main

NITI = softrod.examples.path("niti_two_segment")


def _run(argv, capsys):
    status = main([str(a) for a in argv])
    cap = capsys.readouterr()
    return status, cap.out, cap.err.strip().splitlines()


def _one_error_line(err):
    lines = [ln for ln in err if not ln.startswith("wrote ")]
    assert len(lines) == 1 and lines[0].startswith("softrod: error: "), err
    return lines[0]


def _targets():
    robot = softrod.load_robot(NITI)
    first = robot.solve([2.0, 0.0, 0.0, 0.0, 2.0, 0.0]).tip_position
    return robot, first, first + np.array([1e-3, 0.0, 0.0])


def test_a_path_of_two_targets_to_csv_and_json(tmp_path, capsys):
    robot, a, b = _targets()
    out_csv, out_json = tmp_path / "inv.csv", tmp_path / "inv.json"
    argv = ["inverse", "niti_two_segment", "--target", *a, "--target", *b]
    status, out, _ = _run([*argv, "--csv", out_csv, "--json", out_json], capsys)
    assert status == 0 and "target 2 (m)" in out and "converged True" in out
    with open(out_csv, encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 2
    for row, target in zip(rows, (a, b), strict=True):
        tensions = [float(row[f"tension_{i}"]) for i in range(6)]
        assert min(tensions) >= 0.0 and row["converged"] == "True"
        tip = robot.solve(tensions).tip_position  # independent forward solve
        assert np.linalg.norm(tip - target) <= 1e-9
    data = json.loads(out_json.read_text())
    assert np.asarray(data["tensions"]).shape == (2, 6) and data["converged"] == [True, True]


def test_bounds_are_honoured(capsys, tmp_path):
    _, a, _ = _targets()
    out_csv = tmp_path / "inv.csv"
    argv = ["inverse", NITI, "--target", *a, "--tension-bounds", "0", "3", "--csv", out_csv]
    status, _, _ = _run(argv, capsys)
    assert status == 0
    with open(out_csv, encoding="utf-8") as fh:
        row = next(csv.DictReader(fh))
    assert max(float(row[f"tension_{i}"]) for i in range(6)) <= 3.0 + 1e-12


def test_a_target_out_of_reach_exits_3_with_the_distance(capsys):
    status, _, err = _run(["inverse", "niti_two_segment", "--target", 0.3, 0.3, 0.0], capsys)
    assert status == 3 and "out of reach" in _one_error_line(err)


def test_a_path_with_a_target_out_of_reach_reports_every_target(tmp_path, capsys):
    """The target out of reach does not hide the others: both are printed and written (the
    reachable one checked by an independent forward solve), then exit status 3 naming it."""
    robot, a, _ = _targets()
    out_csv = tmp_path / "inv.csv"
    argv = ["inverse", NITI, "--target", 0.3, 0.3, 0.0, "--target", *a, "--csv", out_csv]
    status, out, err = _run(argv, capsys)
    line = _one_error_line(err)
    assert status == 3 and "target 1 is not reached" in line and "1 of 2 targets" in line
    assert "(target not reached)" in out and "converged True" in out
    with open(out_csv, encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["converged"] for r in rows] == ["False", "True"]
    assert [r["reached"] for r in rows] == ["False", "True"]
    assert float(rows[0]["position_error"]) > 0.05  # (0.3, 0.3, 0) m: far outside the workspace
    tensions = [float(rows[1][f"tension_{i}"]) for i in range(6)]
    assert np.linalg.norm(robot.solve(tensions).tip_position - a) <= 1e-9


@pytest.mark.parametrize(
    "extra, name",
    [
        (["--target", "0.1", "0"], "--target"),
        (["--target", "0.1", "0", "nan"], "--target"),
        (["--target", "0.1", "0", "0.3", "--rotation", *"1 0 0 0 1 0 0 0 2".split()], "--rotation"),
        (["--target", "0.1", "0", "0.3", "--tension-bounds", "inf", "3"], "--tension-bounds"),
        (["--target", "0.1", "0", "0.3", "--tension-bounds", "-1", "3"], "tension_bounds"),
        (["--target", "0.1", "0", "0.3", "--tolerance", "-1"], "--tolerance"),
        (["--target", "0.1", "0", "0.3", "--weights", "1", "1"], "weights"),
        ([], "--target"),
    ],
)
def test_bad_input_is_one_line_with_exit_2(extra, name, capsys):
    status, _, err = _run(["inverse", "niti_two_segment", *extra], capsys)
    assert status == 2 and name in _one_error_line(err)


def test_the_robot_file_is_never_overwritten(tmp_path, capsys):
    robot = tmp_path / "R.toml"
    shutil.copy(NITI, robot)
    before = robot.read_bytes()
    status, _, err = _run(["inverse", robot, "--target", 0.1, 0.0, 0.3, "--csv", robot], capsys)
    assert status == 2 and "--csv" in _one_error_line(err) and robot.read_bytes() == before


def test_several_starts_reach_a_target_beyond_a_fold(tmp_path, capsys):
    # A curled soft arm (test_inverse_starts.py): from rest the target is reported out of
    # reach (exit status 3); from 16 starts it is reached with the known tensions.
    from harness.robots import curled

    robot, truth, target = curled("antagonistic")
    path = tmp_path / "curl.toml"
    path.write_text(robot.to_toml(), encoding="utf-8")
    out_csv = tmp_path / "inv.csv"
    status, _, err = _run(["inverse", path, "--target", *target], capsys)
    assert status == 3 and "not reached" in err[-1]
    status, out, _ = _run(
        ["inverse", path, "--target", *target, "--starts", 16, "--csv", out_csv], capsys
    )
    assert status == 0 and "converged True" in out
    with open(out_csv, encoding="utf-8") as fh:
        (row,) = list(csv.DictReader(fh))
    tensions = [float(row[f"tension_{i}"]) for i in range(2)]
    assert np.allclose(tensions, truth, rtol=1e-6, atol=1e-9)
    assert np.linalg.norm(robot.solve(tensions).tip_position - target) <= 1e-9


@pytest.mark.parametrize(
    ("command", "option", "value", "expected"),
    [
        ("inverse", "--starts", 0, "must be in [1, 10000]"),
        ("inverse", "--starts", 10001, "must be in [1, 10000]"),
        ("compare", "--repeats", 0, "must be >= 1"),
    ],
)
def test_a_count_out_of_range_names_its_option(command, option, value, expected, capsys):
    # (It named the core's `starts` or `repeats`, not the option.)
    argv = [command, "niti_two_segment", option, value]
    if command == "inverse":
        argv += ["--target", 0.0, 0.0, 0.3]
    status, _, err = _run(argv, capsys)
    assert status == 2
    assert err == [f"softrod: error: invalid option `{option}` = {value}: {expected}"], err
