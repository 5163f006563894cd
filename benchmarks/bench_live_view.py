"""Benchmark of the live view's re-render on the two-segment NiTi robot: medians of the
warm-started solve and of the render (end of the solve until the scene updates are sent),
for alternating slider positions of the first tendon, with no browser attached.

Run: ``python benchmarks/bench_live_view.py`` (after ``pip install '.[view]'`` or ``.[test]``).
"""

from __future__ import annotations

import argparse
import statistics

import numpy as np

import softrod
from softrod.plot.live import serve


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--moves", type=int, default=60)
    a = ap.parse_args()
    robot = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    view = serve(robot, port=0, open_browser=False)
    try:
        base = np.asarray(view._tensions, dtype=float)
        for k in range(a.moves):
            t = base.copy()
            t[0] = base[0] * (1.25 if k % 2 else 0.75)
            view.set_actuation(tensions=t)
        timings = [t for t in view.timings[1:] if t.converged]
    finally:
        view.stop()
    solve = statistics.median(t.solve for t in timings) * 1e3
    render = statistics.median(t.render for t in timings) * 1e3
    print(f"live view, NiTi robot, {len(timings)} slider moves (medians)")
    print("solve (ms)  render (ms)  solve + render (ms)")
    print(f"{solve:10.2f}  {render:11.2f}  {solve + render:19.2f}")


if __name__ == "__main__":
    main()
