"""``softrod backbone``: outputs, exit codes, and files it must not touch."""

import json
import subprocess
import sys

import numpy as np
import pytest
from arm_photos import render_published_arm
from skimage import io

import softrod
from softrod.cli import main


@pytest.fixture(scope="module")
def photo(tmp_path_factory):
    shot = render_published_arm(2.0, "0.3MP", seed=21)
    path = tmp_path_factory.mktemp("photos") / "arm.png"
    io.imsave(path, shot.image, check_contrast=False)
    return shot, path


def _args(shot, path):
    return [
        "backbone",
        str(path),
        "--scale",
        repr(float(shot.scale)),
        "--base",
        *(repr(float(v)) for v in shot.base),
        "--direction",
        *(repr(float(v)) for v in shot.direction),
    ]


def test_backbone_writes_csv_json_and_overlay(photo, tmp_path, capsys):
    shot, path = photo
    before = path.read_bytes()
    csv_path, js, png = tmp_path / "b.csv", tmp_path / "b.json", tmp_path / "b.png"
    argv = [*_args(shot, path), "--csv", str(csv_path), "--json", str(js), "--plot", str(png)]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "base to tip" in out and "warning" not in out
    api = softrod.extract_backbone(
        shot.image, scale=shot.scale, base=shot.base, direction=shot.direction
    )
    back = softrod.Backbone.read_csv(csv_path)
    np.testing.assert_allclose(back.points, api.points, rtol=1e-8, atol=1e-12)
    data = json.loads(js.read_text())
    assert data["unit"] == "m" and len(data["points"]) == len(api)
    np.testing.assert_allclose(data["points"], api.points, rtol=1e-12)
    assert data["quality"]["base_source"] == "given"
    assert png.read_bytes()[:4] == b"\x89PNG" and png.stat().st_size > 20_000
    assert path.read_bytes() == before


def test_backbone_in_pixels_without_scale(photo, capsys):
    _, path = photo
    assert main(["backbone", str(path), "--points", "40"]) == 0
    out = capsys.readouterr().out
    assert "40 points" in out and " px" in out


def test_backbone_refuses_to_overwrite(photo, tmp_path, capsys):
    shot, path = photo
    before = path.read_bytes()
    existing = tmp_path / "old.csv"
    existing.write_text("keep me\n")
    for argv, flag in [
        ([*_args(shot, path), "--csv", str(existing)], "--csv"),
        ([*_args(shot, path), "--plot", str(path)], "--plot"),
        ([*_args(shot, path), "--json", str(path), "--overwrite"], "--json"),
        (
            [*_args(shot, path), "--csv", str(tmp_path / "a"), "--json", str(tmp_path / "a")],
            "--json",
        ),
    ]:
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and f"`{flag}`" in err[0]
    assert existing.read_text() == "keep me\n" and path.read_bytes() == before
    assert main([*_args(shot, path), "--csv", str(existing), "--overwrite"]) == 0
    assert softrod.Backbone.read_csv(existing).unit == "m"


@pytest.mark.parametrize(
    "make, name",
    [
        (lambda d: d / "missing.png", "PHOTO"),
        (lambda d: (d / "text.png").write_text("hello") and d / "text.png", "image"),
        (lambda d: d, "PHOTO"),
    ],
    ids=["missing", "not-an-image", "directory"],
)
def test_bad_photo_exits_2_with_one_line(make, name, tmp_path, capsys):
    assert main(["backbone", str(make(tmp_path))]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("softrod: error:") and f"`{name}`" in err[0]


def test_bad_arguments_exit_2(photo, tmp_path, capsys):
    _, path = photo
    blank = tmp_path / "blank.png"
    io.imsave(blank, np.full((60, 80), 200, np.uint8), check_contrast=False)
    for argv, name in [
        (["backbone", str(path), "--scale", "-2"], "scale"),
        (["backbone", str(path), "--direction", "0", "0"], "direction"),
        (["backbone", str(blank)], "image"),
    ]:
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and f"`{name}`" in err[0]


def test_a_base_far_outside_the_photo_is_refused(tmp_path, capsys):
    img = np.zeros((100, 100), np.uint8)  # diagonal 141.42 px
    img[45:55, 10:90] = 255
    shot = tmp_path / "bar.png"
    io.imsave(shot, img, check_contrast=False)
    out = tmp_path / "b.csv"
    argv = ["backbone", str(shot), "--base", "1e6", "1e6", "--csv", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "`--base` = [1000000.0, 1000000.0]" in err[0]
    assert "col in [-141.4, 240.4]" in err[0] and "row in [-141.4, 240.4]" in err[0]
    assert not out.exists()
    assert main(["backbone", str(shot), "--base", "-141", "49.5", "--csv", str(out)]) == 0
    assert "extrapolated over" in capsys.readouterr().out
    np.testing.assert_allclose(softrod.Backbone.read_csv(out).pixels[0], [-141.0, 49.5])


def test_console_script_from_another_directory(photo, tmp_path):
    shot, path = photo
    r = subprocess.run(
        [sys.executable, "-m", "softrod", *_args(shot, path), "--csv", "rel.csv"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=False,
    )
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "rel.csv").exists()
    r = subprocess.run(
        [sys.executable, "-m", "softrod", "backbone", "nope.png"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=False,
    )
    assert r.returncode == 2 and "Traceback" not in r.stderr
