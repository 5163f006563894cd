"""Benchmark of the planar cable-arm paper's arm from Python; prints a table of medians.

Run: ``python benchmarks/bench_planar.py`` (after ``pip install .``). The Rust-side numbers
come from ``cargo bench -p softrod --bench planar``.
"""

from __future__ import annotations

import argparse

import numpy as np
from _timing import median_time

import softrod


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--repeats", type=int, default=15)
    p.add_argument("--quick", action="store_true", help="fewer repeats (smoke run)")
    args = p.parse_args()
    reps = 3 if args.quick else args.repeats

    arm = softrod.PlanarCableArm.published_arm()
    tensions = np.linspace(0.0, 5.0, 10_000)
    rows: list[tuple[str, float, str]] = []

    t = median_time(lambda: arm.solve(1.0), calls=2000, repeats=reps)
    rows.append(("solve, closed form, 201 samples", t * 1e6, "us/solve"))
    t = median_time(lambda: arm.solve(1.0, 2), calls=2000, repeats=reps)
    rows.append(("solve, closed form, 2 samples", t * 1e6, "us/solve"))
    t = median_time(lambda: arm.solve(1.0, method="ode"), calls=200, repeats=reps)
    rows.append(("solve, ODE rtol 1e-8, 201 samples", t * 1e6, "us/solve"))
    t = median_time(
        lambda: arm.solve(1.0, method="ode", rtol=1e-10, atol=1e-12), calls=50, repeats=reps
    )
    rows.append(("solve, ODE rtol 1e-10, 201 samples", t * 1e6, "us/solve"))
    t = median_time(lambda: arm.solve_many(tensions), calls=1, repeats=reps)
    rows.append(("solve_many, 10 000 x 201, closed form", t * 1e3, "ms/batch"))
    rows.append(("  = sample-points per second", tensions.size * 201 / t / 1e6, "million/s"))
    t = median_time(lambda: arm.solve_many(tensions[:1000], method="ode"), calls=1, repeats=reps)
    rows.append(("solve_many, 1 000 x 201, ODE rtol 1e-8", t * 1e3, "ms/batch"))

    width = max(len(r[0]) for r in rows)
    print(f"softrod {softrod.__version__} planar benchmark (median of {reps} repeats)")
    print(f"{'case':<{width}}  {'median':>10}  unit")
    print("-" * (width + 24))
    for name, value, unit in rows:
        print(f"{name:<{width}}  {value:10.3f}  {unit}")


if __name__ == "__main__":
    main()
