"""``softrod calibrate``: the fit from backbone CSVs, outputs, exit codes, files it must not
touch."""

import json

import numpy as np
import pytest

import softrod
from softrod.cli import main

TRUTH = softrod.PlanarCableArm(0.27, 0.015, 0.0074, 0.3, 140e3)


@pytest.fixture
def csvs(tmp_path):
    paths = []
    for t in (0.5, 1.0, 2.0):
        sol = TRUTH.solve(t, 80)
        p = tmp_path / f"shape-{t}.csv"
        # millimetres, with a header, as a lab's digitised backbone
        np.savetxt(p, np.column_stack([sol.x, sol.y]) * 1e3, delimiter=",", header="x,y")
        paths.append((t, p))
    return paths


def test_planar_fit_from_csvs_prints_and_writes_json(csvs, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "fit.json"
    args = ["calibrate", "planar", "--measurements", *(f"{t}:{p}" for t, p in csvs)]
    args += ["--parameters", "E", "a", "--unit-scale", "1e-3", "--json", str(out)]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "youngs_modulus" in text and "correlation" in text
    fit = json.loads(out.read_text())
    assert abs(fit["values"]["youngs_modulus"] / 140e3 - 1) < 1e-6
    assert abs(fit["values"]["offset_ratio"] / 0.3 - 1) < 1e-6
    before = out.read_text()
    assert main(args) == 2  # refuses to overwrite
    assert out.read_text() == before
    assert main([*args, "--overwrite"]) == 0


def test_bad_input_exits_2_with_the_option(csvs, capsys):
    t, p = csvs[0]
    assert main(["calibrate", "planar", "--measurements", f"{t}:{p}", "--parameters", "Q"]) == 2
    assert "parameters" in capsys.readouterr().err
    assert main(["calibrate", "planar", "--measurements", f"x:{p}", "--parameters", "E"]) == 2
    assert "--measurements" in capsys.readouterr().err
    assert main(["calibrate", "planar", "--measurements", "1:none.csv", "--parameters", "E"]) == 2
    args = ["calibrate", "planar", "--measurements", f"{t}:{p}", "--parameters", "E"]
    assert main([*args, "--bounds", "E=1"]) == 2
    assert "--bounds" in capsys.readouterr().err


def test_not_identifiable_is_a_warning_line(csvs, capsys):
    args = ["calibrate", "planar", "--measurements", *(f"{t}:{p}" for t, p in csvs)]
    args += ["--parameters", "E", "tension_scale", "--unit-scale", "1e-3"]
    assert main(args) == 0
    err = capsys.readouterr().err
    assert "softrod: warning: the measurements cannot determine" in err


def test_an_output_on_a_measurements_csv_is_refused_even_with_overwrite(
    csvs, tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(tmp_path)
    niti = softrod.examples.load("niti_two_segment")
    meas = tmp_path / "meas.csv"
    np.savetxt(meas, niti.solve(tensions=[1, 0, 0, 0, 0.5, 0]).position, delimiter=",")
    before = meas.read_bytes()
    base = ["calibrate", "niti_two_segment", "--measurements", f"1,0,0,0,0.5,0:{meas}"]
    base += ["--parameters", "rod.material.youngs_modulus", "--overwrite"]
    for option in ("--json", "--write-robot"):
        # the second spelling reaches the same file through another path
        for value in (str(meas), f"{tmp_path}/./meas.csv"):
            assert main([*base, option, value]) == 2
            out, err = capsys.readouterr()
            assert option in err and "--measurements" in err and out == ""
            assert meas.read_bytes() == before
    # any one of several measurements, and the planar arm's CSVs too
    p = csvs[1][1]
    args = ["calibrate", "planar", "--measurements", *(f"{t}:{p}" for t, p in csvs)]
    args += ["--parameters", "E", "--unit-scale", "1e-3", "--json", str(p), "--overwrite"]
    kept = p.read_bytes()
    assert main(args) == 2
    assert "--measurements" in capsys.readouterr().err and p.read_bytes() == kept


@pytest.mark.parametrize("text", ["x,y,z\n", "keep\n"])
def test_a_measurements_csv_without_data_rows_is_bad_input(tmp_path, capsys, text):
    meas = tmp_path / "hdr.csv"
    meas.write_text(text)
    argv = ["calibrate", "niti_two_segment", "--measurements", f"1,0,0,0,0.5,0:{meas}"]
    assert main([*argv, "--parameters", "rod.material.youngs_modulus"]) == 2
    err = capsys.readouterr().err
    assert "`path`" in err and "no data rows" in err and "internal error" not in err


@pytest.mark.parametrize(("text", "width"), [("x,y\n0,0\n0.1,0\n0.2,0.01\n", 2), ("0\n1\n", 1)])
def test_a_measurements_csv_with_too_few_columns_names_the_file(tmp_path, capsys, text, width):
    meas = tmp_path / "okc.csv"
    meas.write_text(text)
    item = f"1,0,0,0,0.5,0:{meas}"
    argv = ["calibrate", "niti_two_segment", "--measurements", item]
    assert main([*argv, "--parameters", "rod.material.youngs_modulus"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "`columns`" not in err[0] and "internal error" not in err[0]
    assert str(meas) in err[0] and f"{width} column" in err[0]
    assert "3 (x, y, z)" in err[0] or "2 or 3" in err[0]


def test_a_planar_measurements_csv_with_three_columns_reads_the_first_two(csvs, tmp_path, capsys):
    # x, y and a third column (e.g. half-widths): the planar arm's fit reads x and y, as before.
    wide = []
    for t, p in csvs:
        xy = np.loadtxt(p, delimiter=",")
        q = tmp_path / f"wide-{t}.csv"
        np.savetxt(q, np.column_stack([xy, np.full(len(xy), 7.0)]), delimiter=",")
        wide.append((t, q))
    runs = []
    for paths in (csvs, wide):
        args = ["calibrate", "planar", "--measurements", *(f"{t}:{p}" for t, p in paths)]
        assert main([*args, "--parameters", "E", "--unit-scale", "1e-3"]) == 0
        runs.append(capsys.readouterr().out)
    assert runs[0] == runs[1]


def test_a_misspelt_parameter_suggests_the_key(tmp_path, capsys):
    niti = softrod.examples.load("niti_two_segment")
    meas = tmp_path / "meas.csv"
    np.savetxt(meas, niti.solve(tensions=[1, 0, 0, 0, 0.5, 0]).position, delimiter=",")
    argv = ["calibrate", "niti_two_segment", "--measurements", f"1,0,0,0,0.5,0:{meas}"]
    assert main([*argv, "--parameters", "rod.material.youngs_modulu"]) == 2
    err = capsys.readouterr().err
    assert "did you mean `youngs_modulus`?" in err and "stiffness_scale" not in err


def test_starts_are_reported_and_the_best_is_kept(csvs, tmp_path, capsys):
    out = tmp_path / "fit.json"
    args = ["calibrate", "planar", "--measurements", *(f"{t}:{p}" for t, p in csvs)]
    args += ["--parameters", "E", "a", "--unit-scale", "1e-3", "--json", str(out)]
    assert main([*args, "--starts", "4"]) == 0
    text = capsys.readouterr().out
    assert "of 4 fitted" in text
    fit = json.loads(out.read_text())
    assert len(fit["starts"]) == 4 and abs(fit["values"]["youngs_modulus"] / 140e3 - 1) < 1e-6
    fitted = [st for st in fit["starts"] if "rms" in st]
    assert fit["rms"] == min(st["rms"] for st in fitted)
    assert main([*args, "--starts", "0", "--overwrite"]) == 2
    assert "--starts" in capsys.readouterr().err
