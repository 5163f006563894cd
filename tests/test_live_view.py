"""The live view: API (re-solve, exports round-trip, status), and the page in a real headless
browser (Debian's chromium with selenium): a slider moved through the DOM re-renders the shape.
"""

import os
import shutil
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import softrod

pytest.importorskip("viser")
from softrod.plot.live import serve

NITI = Path(__file__).resolve().parent.parent / "examples" / "robots" / "niti_two_segment.toml"


@pytest.fixture
def view():
    v = serve(NITI, port=0, open_browser=False)
    yield v
    v.stop()


def test_set_actuation_resolves_and_redraws(view):
    n0, v0 = view.renders, view.last_vertices.copy()
    sol = view.set_actuation(tensions=[1, 0, 0, 0, 3, 0])
    assert sol.converged and view.renders == n0 + 1
    assert np.abs(view.last_vertices - v0).max() > 1e-3
    ref = softrod.load_robot(NITI).with_tensions([1, 0, 0, 0, 3, 0]).solve()
    np.testing.assert_allclose(sol.tip_position, ref.tip_position, atol=1e-12)
    # A tip force does positive work on the tip displacement it causes.
    before = view.solution.tip_position.copy()
    f = np.array([0.0, 0.0, -0.02])
    view.set_actuation(tip_force=f)
    assert np.dot(view.solution.tip_position - before, f) > 0


def test_exports_round_trip(view, tmp_path):
    view.set_actuation(tensions=[2, 0, 0, 0, 1, 0], tip_force=[0.01, 0, 0])
    name, toml = view.export("toml")
    path = tmp_path / name
    path.write_bytes(toml)
    again = softrod.load_robot(path).solve()  # the exported file reproduces the shape
    np.testing.assert_allclose(again.position, view.solution.position, atol=1e-12)
    _, csv = view.export("csv")
    rows = np.loadtxt(csv.decode().splitlines(), delimiter=",", skiprows=1)
    np.testing.assert_allclose(rows[:, 1:4], view.solution.position)
    import json

    data = json.loads(view.export("json")[1])
    assert data["tensions"] == [2, 0, 0, 0, 1, 0] and data["tip_force"] == [0.01, 0, 0]
    with pytest.raises(softrod.ParameterError, match="kind"):
        view.export("xlsx")


def test_status_reports_stability_when_the_solver_does(view):
    sol = SimpleNamespace(converged=True, stats={"iterations": 3, "residual": 1e-12}, stable=False)
    assert "UNSTABLE" in view._status_text(sol, 1e-3)
    del sol.stable
    assert "not reported" in view._status_text(sol, 1e-3)


def test_bad_port_is_named():
    with pytest.raises(softrod.ParameterError, match="port"):
        serve(NITI, port=70000, open_browser=False)


def _browser():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


@pytest.mark.skipif(
    _browser() is None or shutil.which("chromedriver") is None,
    reason="no chromium/chromedriver installed (apt-get install chromium chromium-driver)",
)
def test_slider_move_in_a_real_browser(view, tmp_path):
    webdriver = pytest.importorskip("selenium.webdriver")
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys

    opts = webdriver.ChromeOptions()
    opts.binary_location = _browser()
    for arg in (
        "--headless=new",
        "--no-sandbox",
        "--disable-gpu",
        "--window-size=1200,800",
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
    ):
        opts.add_argument(arg)
    driver = webdriver.Chrome(service=Service(shutil.which("chromedriver")), options=opts)
    try:
        driver.get(view.url)
        deadline = time.monotonic() + 30
        sliders = []
        while time.monotonic() < deadline and len(sliders) < 6:
            sliders = driver.find_elements(By.CSS_SELECTOR, "[role=slider]")
            time.sleep(0.1)
        assert len(sliders) == 6 + 3  # six tendons, three tip-force components
        assert sliders[0].get_attribute("aria-valuenow") == "4"
        time.sleep(1.0)  # first frame drawn
        before_png = driver.get_screenshot_as_png()
        n0, v0 = view.renders, view.last_vertices.copy()
        t_key = time.perf_counter()
        sliders[0].send_keys(Keys.END)  # T0 to the top of its range, through the page's DOM
        while view.renders == n0 and time.perf_counter() - t_key < 10:
            time.sleep(0.001)
        end_to_end = time.perf_counter() - t_key
        assert view.renders > n0, "the slider move did not reach the server"
        assert view._tensions[0] == pytest.approx(view.max_tension)
        assert np.abs(view.last_vertices - v0).max() > 0.01  # the tube moved (m)
        timing = view.timings[-1]
        assert timing.converged
        time.sleep(1.0)
        after_png = driver.get_screenshot_as_png()
        from io import BytesIO

        from PIL import Image, ImageChops

        a = Image.open(BytesIO(before_png)).convert("RGB")
        b = Image.open(BytesIO(after_png)).convert("RGB")
        diff = np.asarray(ImageChops.difference(a, b)).max(axis=2) > 30
        assert diff.mean() > 1e-3, "the page did not redraw"
        if os.environ.get("SOFTROD_LIVE_SCREENSHOT"):
            b.save(os.environ["SOFTROD_LIVE_SCREENSHOT"])
        print(
            f"\nlive view, NiTi robot: solve {timing.solve * 1e3:.2f} ms, render (solve end -> "
            f"scene sent) {timing.render * 1e3:.2f} ms, key press -> re-render done "
            f"{end_to_end * 1e3:.1f} ms, {diff.mean() * 100:.1f} % of pixels changed"
        )
    finally:
        driver.quit()


def test_the_view_command_takes_an_example_name_as_every_command(capsys):
    # (Port 0: any free port; the view stops after a fraction of a second.)
    from softrod.cli import main

    code = main(["view", "niti_two_segment", "--no-browser", "--port", "0", "--seconds", "0.1"])
    err = capsys.readouterr().err
    assert code == 0, err
    assert "softrod view: niti" in err
    assert main(["view", "no_such_robot", "--no-browser", "--seconds", "0.1"]) != 0
    assert "no_such_robot" in capsys.readouterr().err
