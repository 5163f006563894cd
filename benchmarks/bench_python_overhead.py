"""The Python overhead of a forward solve: ``Robot.solve`` and ``solve_statics`` against the core.

The two-segment NiTi robot of ``softrod.examples`` (RK4, 50 steps), tensions [4, 0, 0, 0, 2, 0]
N. Each case is the median of many individually timed calls; the core row is the same solve
timed inside Rust (``softrod._core._time_solve_statics``), so ``case - core`` is what the
Python call adds.

Run: ``python benchmarks/bench_python_overhead.py`` (after ``pip install .``). To compare with
another build, give the directory holding its ``softrod`` package (e.g. a copy of
``python/softrod`` with its compiled ``_core``): ``--baseline DIR`` runs the two builds
alternately in subprocesses, ``--rounds`` times, and prints the medians over the rounds side
by side. ``--loop N`` only makes N calls of ``robot.solve`` (``--loop-case objects``: of
``solve_statics`` with the objects), for instruction counts that do not depend on the machine's
load: ``valgrind --tool=callgrind python benchmarks/bench_python_overhead.py --loop 1000``
against ``--loop 1`` (with ``OPENBLAS_NUM_THREADS=1 PYTHONHASHSEED=0``, so that start-up is the
same in both), the difference divided by 999.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys

import numpy as np
from _timing import median_time

import softrod
from softrod import _core

TENSIONS = (4.0, 0.0, 0.0, 0.0, 2.0, 0.0)
CASES = (
    ("robot.solve(tensions)", "tensions as a NumPy array"),
    ("robot.solve(list)", "tensions as a list of floats"),
    ("robot.solve()", "the robot's own tensions"),
    ("solve_statics(objects)", "rod, tendons (with_tension), loads, steps=50"),
    ("core solve", "the same solve inside Rust"),
)


def robot() -> softrod.Robot:
    return softrod.load_robot(softrod.examples.path("niti_two_segment"))


def measure(calls: int, repeats: int) -> dict[str, float]:
    """Median wall time (us) of every case."""
    r = robot()
    t = np.array(TENSIONS)
    listed = list(TENSIONS)
    tendons = [x.with_tension(v) for x, v in zip(r.tendons, TENSIONS, strict=True)]
    rod, loads, solver = r.rod, r.loads, r.solver
    out = {
        "robot.solve(tensions)": median_time(lambda: r.solve(t), calls=calls, repeats=repeats),
        "robot.solve(list)": median_time(lambda: r.solve(listed), calls=calls, repeats=repeats),
        "robot.solve()": median_time(r.solve, calls=calls, repeats=repeats),
        "solve_statics(objects)": median_time(
            lambda: softrod.solve_statics(rod, tendons, loads, **solver),
            calls=calls,
            repeats=repeats,
        ),
    }
    core = _core._time_solve_statics(rod, tendons, loads, repeats=calls * repeats, **solver)
    out["core solve"] = statistics.median(core)
    return {k: v * 1e6 for k, v in out.items()}


def table(columns: dict[str, dict[str, float]]) -> None:
    """Prints the cases (rows) of each build (columns), with each case's overhead."""
    names = list(columns)
    width = max(len(c) for c, _ in CASES)
    head = "".join(f"  {n + ' (us)':>12}  {'overhead':>8}" for n in names)
    print(f"{'case':<{width}}{head}")
    print("-" * (width + 24 * len(names)))
    for case, _ in CASES:
        cells = ""
        for n in names:
            value, core = columns[n][case], columns[n]["core solve"]
            over = "" if case == "core solve" else f"{value - core:8.1f}"
            cells += f"  {value:12.1f}  {over:>8}"
        print(f"{case:<{width}}{cells}")


def compare(baseline: str, rounds: int, calls: int, repeats: int) -> None:
    """Both builds alternately in subprocesses; the medians over the rounds."""
    here = os.path.abspath(__file__)
    runs: dict[str, list[dict[str, float]]] = {"old": [], "new": []}
    for k in range(rounds):
        for which in ("old", "new"):
            env = dict(os.environ)
            if which == "old":
                env["PYTHONPATH"] = os.pathsep.join(
                    p for p in (os.path.abspath(baseline), env.get("PYTHONPATH")) if p
                )
            args = [sys.executable, here, "--json", "--calls", str(calls)]
            args += ["--repeats", str(repeats)]
            out = subprocess.run(args, env=env, check=True, capture_output=True, text=True)
            runs[which].append(json.loads(out.stdout))
            print(f"round {k + 1} {which}: {out.stdout.strip()}", file=sys.stderr)
    columns = {
        which: {c: statistics.median(r[c] for r in rs) for c, _ in CASES}
        for which, rs in runs.items()
    }
    print(f"medians of {rounds} alternating rounds x {calls * repeats} calls each")
    table(columns)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--calls", type=int, default=500)
    p.add_argument("--repeats", type=int, default=6)
    p.add_argument("--baseline", help="directory holding the softrod package to compare with")
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--loop", type=int, help="only make this many calls (of --loop-case)")
    p.add_argument(
        "--loop-case",
        choices=("robot", "objects"),
        default="robot",
        help="robot.solve(tensions) or solve_statics(rod, tendons, loads)",
    )
    p.add_argument("--json", action="store_true", help="print the medians as JSON")
    args = p.parse_args()
    if args.loop is not None:
        r, t = robot(), np.array(TENSIONS)
        if args.loop_case == "robot":
            for _ in range(args.loop):
                r.solve(t)
        else:
            tendons = [x.with_tension(v) for x, v in zip(r.tendons, TENSIONS, strict=True)]
            rod, loads, solver = r.rod, r.loads, r.solver
            for _ in range(args.loop):
                softrod.solve_statics(rod, tendons, loads, **solver)
        return
    if args.baseline:
        compare(args.baseline, args.rounds, args.calls, args.repeats)
        return
    medians = measure(args.calls, args.repeats)
    if args.json:
        print(json.dumps(medians))
        return
    print(f"softrod {softrod.__version__}: two-segment NiTi robot, RK4 50 steps (medians)")
    table({"this build": medians})


if __name__ == "__main__":
    main()
