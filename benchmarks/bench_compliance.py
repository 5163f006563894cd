"""Benchmark of the compliance API from Python; prints a table of medians.

Run: ``python benchmarks/bench_compliance.py`` (after ``pip install .``). Cases on the
two-segment NiTi robot (2 x 0.2 m, E 54 GPa, radius 0.7 mm, six tendons at 10 mm, tensions
[4, 0, 0, 0, 2, 0] N; RK4, 50 steps): the statics solve alone, the integrated compliance along
the arm, both together (ratio to the solve), the exact tangent tip compliance, eigenscrews, and a
10 000-configuration workspace map. The Rust-side numbers come from
``cargo bench -p softrod --bench compliance``.

``--arcs``: the tip compliance of stress-free arcs (``tests/harness/arcs.py``, precurved and
under a tip moment, pi/2 ... 2 pi, RK4 at the default steps): time and Castigliano error of
``compliance(sol)`` (on a finer nested mesh where the estimated truncation error of the
rotations exceeds 1e-7), of the tangent compliance, and of ``compliance(sol, s_out=[L])``
(marched under step-size control). Run it with another build's interpreter for a side-by-side
table (a build without ``s_out`` prints ``-`` there).
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from _timing import median_time

import softrod


def arcs_table(calls: int, reps: int) -> None:
    """Time and Castigliano error of the compliance of stress-free arcs (RK4 defaults)."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from harness import arcs
    from harness.oracles import block_relative_error

    def med(fn):
        return median_time(fn, calls=calls, repeats=reps) * 1e6

    print("tip compliance of stress-free arcs, RK4 default steps; medians in microseconds")
    print(
        "| arc | solve | compliance() | error | tangent | error "
        "| compliance(s_out=[L]) marched | error |"
    )
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")

    def row(case: str, theta: float) -> list[str]:
        sol = arcs.solve(case, theta)
        exact = arcs.exact(theta)
        cells = [f"{case} {theta / math.pi:g} pi", f"{med(lambda: arcs.solve(case, theta)):.1f}"]
        cells.append(f"{med(lambda: softrod.compliance(sol)):.1f}")
        cells.append(f"{block_relative_error(softrod.compliance(sol).tip_world, exact):.1e}")
        if case == "precurved":
            cells.append(f"{med(lambda: softrod.tangent_compliance(sol)):.1f}")
            tangent = softrod.tangent_compliance(sol).world
            cells.append(f"{block_relative_error(tangent, exact):.1e}")
        else:
            cells += ["-", "-"]
        try:
            marched = softrod.compliance(sol, s_out=[arcs.LENGTH]).world[0]
        except TypeError:
            return [*cells, "-", "-"]
        cells.append(f"{med(lambda: softrod.compliance(sol, s_out=[arcs.LENGTH])):.1f}")
        cells.append(f"{block_relative_error(marched, exact):.1e}")
        return cells

    for case in ("precurved", "moment"):
        for theta in arcs.ANGLES:
            print("| " + " | ".join(row(case, theta)) + " |")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--repeats", type=int, default=15)
    p.add_argument("--quick", action="store_true", help="fewer repeats (smoke run)")
    p.add_argument("--arcs", action="store_true", help="only the stress-free arcs table")
    args = p.parse_args()
    reps = 3 if args.quick else args.repeats
    calls = 30 if args.quick else 200
    if args.arcs:
        arcs_table(calls // 4, reps)
        return

    robot = softrod.examples.load("niti_two_segment")
    rows = []

    def med(fn):
        return median_time(fn, calls=calls, repeats=reps) * 1e6

    def case(name, loads):
        rod, tendons = robot.rod, robot.tendons
        sol = softrod.solve_statics(rod, tendons, loads)
        k = softrod.compliance(sol).tip_stiffness_world
        solve = med(lambda: softrod.solve_statics(rod, tendons, loads))
        both = med(lambda: softrod.compliance(softrod.solve_statics(rod, tendons, loads)))
        rows.append(
            (
                name,
                solve,
                med(lambda: softrod.compliance(sol)),
                both,
                both / solve,
                med(lambda: softrod.compliance(sol).stiffness_world),
                med(lambda: softrod.tangent_compliance(sol)),
                med(lambda: softrod.tangent_compliance(sol, "length")),
                med(lambda: softrod.eigenscrews(k)),
            )
        )

    case("tendons only", None)
    case("+ 0.05 N tip force", softrod.Loads(tip_force=(0.05, 0.0, 0.0)))
    print("medians in microseconds (NiTi robot, RK4 50 steps)")
    print(
        "| loads | solve | compliance along arm | solve + compliance | ratio "
        "| + stiffness at every node | tangent (tension) | tangent (length) | eigenscrews |"
    )
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for r in rows:
        cells = " | ".join(f"{v:.2f}" if i == 3 else f"{v:.1f}" for i, v in enumerate(r[1:]))
        print(f"| {r[0]} | {cells} |")
    grid = softrod.tension_grid(6, {0: np.linspace(0, 4, 100), 1: np.linspace(0, 4, 100)})
    times = []
    for _ in range(3 if args.quick else 7):
        t0 = time.perf_counter()
        softrod.workspace_map(robot.rod, robot.tendons, grid)
        times.append(time.perf_counter() - t0)
    med_map = statistics.median(times)
    print(f"\nworkspace map, 10 000 configurations (median of {len(times)}): {med_map:.3f} s")
    # The compliance at many arc lengths: each is a stop of one step-size-controlled march.
    sol = robot.solve([4.0, 0.0, 0.0, 0.0, 2.0, 0.0])
    print("\ncompliance(sol, s_out) at n arc lengths (median of 3)")
    print("| n | total (s) | per arc length (us) |")
    print("| ---: | ---: | ---: |")
    for n in (1_000, 10_000) if args.quick else (1_000, 10_000, 100_000, 200_000):
        s = np.linspace(0.0, robot.rod.length, n)
        t = median_time(lambda s=s: softrod.compliance(sol, s_out=s), calls=1, repeats=3)
        print(f"| {n} | {t:.3f} | {t / n * 1e6:.2f} |")


if __name__ == "__main__":
    main()
