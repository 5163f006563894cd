"""Benchmark of the Cosserat statics engine from Python; prints a table of medians.

Run: ``python benchmarks/bench_statics.py`` (after ``pip install .``). Each case is timed twice:
as a Python call of ``softrod.solve_statics`` and, for the same problem, inside Rust
(``softrod._core._time_solve_statics``); the difference is the Python overhead. The Rust-side
criterion numbers come from ``cargo bench -p softrod --bench statics``.
"""

from __future__ import annotations

import argparse
import statistics

import numpy as np
from _timing import median_time

import softrod
from softrod import _core


def two_segment_robot(tensions=(4, 0, 0, 0, 2, 0)):
    """2 x 0.2 m NiTi rod (E 54 GPa, nu 0.3, radius 0.7 mm), six tendons at 10 mm."""
    rod = softrod.Rod(0.4, softrod.CircularSection(0.7e-3), softrod.LinearElastic(54e9, 0.3))
    tendons = []
    for k, (end, ang) in enumerate(
        [(0.2, 90), (0.2, -30), (0.2, 210), (0.4, 90), (0.4, -30), (0.4, 210)]
    ):
        a = np.radians(ang)
        tendons.append(softrod.Tendon((0.01 * np.cos(a), 0.01 * np.sin(a)), tensions[k], end))
    return rod, tendons


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--repeats", type=int, default=15)
    p.add_argument("--quick", action="store_true", help="fewer repeats (smoke run)")
    args = p.parse_args()
    reps = 3 if args.quick else args.repeats
    calls = 50 if args.quick else 300

    rows = []

    def case(name, rod, tendons=(), loads=None, **kw):
        py = median_time(
            lambda: softrod.solve_statics(rod, tendons, loads, **kw), calls=calls, repeats=reps
        )
        rust = statistics.median(
            _core._time_solve_statics(rod, tendons, loads, repeats=calls * reps, **kw)
        )
        rows.append((name, rust * 1e6, py * 1e6, (py - rust) * 1e6))

    rod, tendons = two_segment_robot()
    cold = softrod.solve_statics(rod, tendons)
    case("two-segment NiTi, cold (RK4, 40 steps)", rod, tendons)
    nudged = [t.with_tension(t.tension * 1.02) for t in tendons]
    case("two-segment NiTi, warm after +2 % tension", rod, nudged, warm_start=cold)
    loads = softrod.Loads(tip_force=(0.05, 0.0, 0.0))
    cold_l = softrod.solve_statics(rod, tendons, loads)
    case("two-segment NiTi + 0.05 N tip force, cold", rod, tendons, loads)
    loads2 = softrod.Loads(tip_force=(0.051, 0.0, 0.0))
    case("  ... warm after +2 % force", rod, tendons, loads2, warm_start=cold_l)
    soft = softrod.Rod(0.27, softrod.CircularSection(0.01), softrod.LinearElastic(110e3, 0.5))
    case("soft cantilever, 0.02 N tip force", soft, (), softrod.Loads(tip_force=(0.02, 0, 0)))

    # Accuracy of the default solve against a tight adaptive run.
    ref = softrod.solve_statics(rod, tendons, integrator="adaptive", rtol=1e-12, atol=1e-14)
    err = np.linalg.norm(cold.tip_position - ref.tip_position)

    width = max(len(r[0]) for r in rows)
    print(f"softrod {softrod.__version__} statics benchmark (medians, {reps} repeats)")
    print(f"{'case':<{width}}  {'Rust (us)':>10}  {'Python (us)':>11}  {'overhead (us)':>13}")
    print("-" * (width + 42))
    for name, rust, py, over in rows:
        print(f"{name:<{width}}  {rust:10.1f}  {py:11.1f}  {over:13.1f}")
    print(f"two-segment tip error, RK4 40 steps vs adaptive rtol 1e-12: {err:.2e} m")


if __name__ == "__main__":
    main()
