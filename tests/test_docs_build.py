"""The documentation builds: the gallery regenerates, the CLI page equals the parser's help,
``mkdocs build --strict`` passes with the API reference, and public names carry docstrings
with units."""

import importlib.util
import inspect
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import softrod

ROOT = Path(__file__).resolve().parent.parent


def _load(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "docs" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_gallery_regenerates_every_figure(tmp_path):
    written = _load("gallery").main(tmp_path)
    page = (ROOT / "docs" / "gallery.md").read_text(encoding="utf-8")
    for path in written:
        assert path.stat().st_size > 5_000
        assert f"figures/gallery/{path.name}" in page  # every figure is on the page
    assert len(written) >= 11


def test_cli_page_is_generated_from_the_parser():
    gen = _load("gen_cli")
    committed = gen.PAGE.read_text(encoding="utf-8")
    assert committed == gen.page(committed), "docs/cli.md is stale: run python docs/gen_cli.py"
    from softrod.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    for name in sub.choices:
        assert f"### `softrod {name}`" in committed


@pytest.mark.skipif(shutil.which("mkdocs") is None, reason="mkdocs not installed (docs extra)")
def test_mkdocs_build_strict(tmp_path):
    r = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-d", str(tmp_path / "site")],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
    )
    assert r.returncode == 0, r.stderr[-3000:]
    api = (tmp_path / "site" / "api" / "index.html").read_text(encoding="utf-8")
    for name in (
        "softrod.solve_statics",
        "softrod.Robot",
        "softrod.plot.plot_rod",
        "softrod.vision.extract.extract_backbone",
        "softrod.vision.backbone.Backbone",
    ):
        assert f'id="{name}"' in api


UNITS = (
    "(m",
    " m)",
    " m,",
    "(N",
    " N)",
    "Pa",
    "rad",
    "m/N",
    "SI",
    "dimensionless",
    "inches",
    "(s)",
    "mm",
    "m^",
    "N m",
    "units",
)


def _python_defined(obj) -> bool:
    mod = getattr(obj, "__module__", "") or ""
    return mod.startswith("softrod") and not mod.startswith("softrod._core")


def _public():
    for name in softrod.__all__:
        obj = getattr(softrod, name)
        if inspect.ismodule(obj) or not (inspect.isclass(obj) or callable(obj)):
            continue
        yield name, obj


def test_python_public_names_have_docstrings_with_units():
    missing = []
    for name, obj in _public():
        if not _python_defined(obj):
            continue
        doc = inspect.getdoc(obj) or ""
        if not doc or not any(u in doc for u in UNITS):
            missing.append(name)
    assert not missing, f"no docstring with units: {missing}"
    from softrod import plot

    for name in plot.__all__:
        obj = getattr(plot, name)
        if callable(obj):
            doc = inspect.getdoc(obj) or ""
            assert doc and any(u in doc for u in UNITS), name


def test_compiled_public_names_have_docstrings_with_units():
    gaps = []
    for name, obj in _public():
        if _python_defined(obj):
            continue
        doc = inspect.getdoc(obj) or ""
        if len(doc.strip().splitlines()) < 2 or not any(u in doc for u in UNITS):
            gaps.append(name)
    assert not gaps, f"compiled docstrings of one line or without units: {', '.join(gaps)}"
