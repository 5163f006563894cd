"""``softrod sweep``: grids on the command line, the NetCDF it writes (equal to the API's
result), files never overwritten without --overwrite, one-line errors."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import softrod
from softrod.cli import main
from softrod.cli.sweep import parse_grid


def _run(argv, capsys):
    status = main([str(a) for a in argv])
    cap = capsys.readouterr()
    return status, cap.out, cap.err.strip().splitlines()


def test_grid_syntax():
    assert parse_grid("--design", "rod.length=0.1:0.3:3") == ("rod.length", [0.1, 0.2, 0.3])
    assert parse_grid("--tensions", "0=1,2.5") == ("0", [1.0, 2.5])
    assert parse_grid("--tensions", "2=4") == ("2", [4.0])
    assert parse_grid("--design", "x=0.5:9:1") == ("x", [0.5])
    for bad in ["rod.length", "=1", "x=a:b:3", "x=0:1:0", "x=0:1", "x=1,nan"]:
        with pytest.raises(softrod.ParameterError, match="--design"):
            parse_grid("--design", bad)


def test_sweep_writes_the_api_result(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    argv = [
        "sweep",
        "niti_two_segment",
        "--design",
        "rod.material.youngs_modulus=50e9:58e9:3",
        "--tensions",
        "0=0:2:5",
        "--actuation",
        "loads.tip_force[1]=0,0.05",
        "--outputs",
        "tip_pose,translational_compliance,convergence",
        "--arm-index",
        "0.5",
        "1",
        "--out",
        "study.nc",
    ]
    status, out, err = _run(argv, capsys)
    assert status == 0, err
    assert "30 samples" in out and "30 converged" in out
    assert err[-1] == "wrote study.nc"
    with xr.open_dataset(tmp_path / "study.nc") as ds:
        ds = ds.load()
    api = softrod.sweep(
        softrod.examples.load("niti_two_segment"),
        design={"rod.material.youngs_modulus": np.linspace(50e9, 58e9, 3)},
        actuation={"tendons[0].tension": np.linspace(0, 2, 5), "loads.tip_force[1]": [0, 0.05]},
        outputs=("tip_pose", "translational_compliance", "convergence"),
        arm_index=[0.5, 1.0],
        progress=False,
    )
    xr.testing.assert_identical(ds, api)
    # An existing output is refused without --overwrite, and left as it was.
    before = (tmp_path / "study.nc").read_bytes()
    status, _, err = _run(argv, capsys)
    assert status == 2 and "exists (pass --overwrite" in err[-1]
    assert (tmp_path / "study.nc").read_bytes() == before
    status, _, err = _run([*argv, "--overwrite"], capsys)
    assert status == 0, err


def test_sweep_on_a_local_cluster_equals_in_process(tmp_path, capsys):
    argv = ["sweep", "pneumatic_arm", "--pressures", "0=0:3e4:3", "--pressures", "2=0,1e4"]
    assert _run([*argv, "--out", tmp_path / "a.nc"], capsys)[0] == 0
    status, _, err = _run([*argv, "--scheduler", "local:2", "--out", tmp_path / "b.nc"], capsys)
    assert status == 0, err
    assert any("dashboard" in line for line in err)
    with xr.open_dataset(tmp_path / "a.nc") as a, xr.open_dataset(tmp_path / "b.nc") as b:
        xr.testing.assert_identical(a.load(), b.load())


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (["--tensions", "x=0:1:2"], "tendon index"),
        (["--tensions", "9=0:1:2"], "tendon index in [0, 6)"),
        (["--tensions", "0=0:1:2", "--actuation", "tendons[0].tension=1"], "given once"),
        (["--design", "rod.sectoin.radius=1e-3"], "did you mean `section`"),
        (["--outputs", "tip_pos"], "did you mean 'tip_pose'"),
        (["--scheduler", "nowhere"], "--scheduler"),
        (["--scheduler", "local:0"], "local:N"),
        (["--block", "0"], "block"),
        (["--tensions", "0=-1"], "tensions >= 0"),
        (["--design", "rod.length=0.3:0.4:2", "--arc-lengths", "0.35"], "`arc_lengths`"),
    ],
)
def test_bad_input_is_one_line(extra, needle, tmp_path, capsys):
    status, _, err = _run(["sweep", "niti_two_segment", *extra, "--out", tmp_path / "s.nc"], capsys)
    errors = [ln for ln in err if ln.startswith("softrod: error:")]
    assert status == 2 and len(errors) == 1 and needle in errors[0], err
    assert not (tmp_path / "s.nc").exists()


def test_output_names(tmp_path, capsys):
    robot = softrod.examples.path("niti_two_segment")
    status, _, err = _run(["sweep", robot, "--out", robot], capsys)
    assert status == 2 and "is the input ROBOT" in err[-1]
    status, _, err = _run(["sweep", robot, "--out", tmp_path / "s.csv"], capsys)
    assert status == 2 and "ending in .nc" in err[-1]
    status, _, err = _run(["sweep", robot, "--out", tmp_path / "no" / "s.nc"], capsys)
    assert status == 2 and "does not exist" in err[-1]
