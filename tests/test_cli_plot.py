"""The ``softrod`` command line and the plots: exit codes, outputs, files."""

import json
import subprocess
import sys

import numpy as np
import pytest

from softrod import PlanarCableArm
from softrod.cli import main
from softrod.plot import plot_planar


def test_planar_prints_a_table(capsys):
    assert main(["planar", "-t", "1", "2"]) == 0
    out = capsys.readouterr().out
    assert "tip x (mm)" in out and "max compr. strain" in out
    rows = [ln for ln in out.splitlines() if ln.strip().startswith(("1 ", "2 "))]
    assert len(rows) == 2


def test_planar_json_matches_the_api(capsys):
    assert main(["planar", "-t", "1.5", "-n", "11", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    sol = PlanarCableArm.published_arm().solve(1.5, 11)
    got = data["solutions"][0]
    assert got["tip"] == pytest.approx(list(sol.tip), abs=0, rel=0)
    assert len(got["x"]) == 11 and data["arm"]["length"] == 0.27


def test_planar_csv_and_plot(tmp_path):
    csv_path, png = tmp_path / "s.csv", tmp_path / "p.png"
    assert (
        main(["planar", "-t", "0.5", "1", "-n", "21", "--csv", str(csv_path), "--plot", str(png)])
        == 0
    )
    rows = np.loadtxt(csv_path, delimiter=",", skiprows=1)
    assert rows.shape == (42, 7)
    assert png.stat().st_size > 10_000 and png.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize(
    ("argv", "name"),
    [
        (["planar", "--length", "-1"], "length"),
        (["planar", "--offset-ratio", "1.5"], "offset_ratio"),
        (["planar", "--anchor", "0.5"], "anchor"),
        (["planar", "-t", "-1"], "tension"),
        (["planar", "-n", "1"], "n_points"),
        (["planar", "--youngs-modulus", "0"], "youngs_modulus"),
    ],
)
def test_bad_input_exits_2_with_one_line(argv, name, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("softrod: error:") and f"`{name}`" in err[0]


def test_console_script_bad_input_has_no_traceback():
    r = subprocess.run(
        [sys.executable, "-m", "softrod", "planar", "--tip-radius", "0"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert r.returncode == 2
    assert "Traceback" not in r.stderr and "tip_radius" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


def test_demo_prints_table_and_writes_png(tmp_path, capsys):
    png = tmp_path / "demo.png"
    assert main(["demo", "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert out.count("\n") >= 8 and "final-value ODE" in out
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_plot_draws_one_backbone_per_solution():
    arm = PlanarCableArm.published_arm()
    sols = [arm.solve(t) for t in (0.5, 1.0, 2.0)]
    fig = plot_planar(arm, sols)
    ax = fig.axes[0]
    labels = [ln.get_label() for ln in ax.get_lines() if ln.get_label().startswith("T =")]
    assert labels == ["T = 0.5 N", "T = 1 N", "T = 2 N"]
    assert len(fig.axes) == 3
    # The drawn backbone is the solution in millimetres.
    line = ax.get_lines()[0]
    np.testing.assert_allclose(line.get_xdata(), sols[0].x * 1e3)
    assert len(plot_planar(arm, sols, profiles=False).axes) == 1


def test_cli_closes_the_figures_it_opens(tmp_path):
    import matplotlib.pyplot as plt

    mine = plt.figure()
    assert main(["planar", "-t", "1", "--plot", str(tmp_path / "p.png")]) == 0
    assert main(["demo", "--plot", str(tmp_path / "d.png")]) == 0
    assert plt.get_fignums() == [mine.number]  # the caller's figure stays open
